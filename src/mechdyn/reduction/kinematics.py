"""Exact reduced kinematics of a one-degree-of-freedom model (reference [2], docs/references.md).

The velocity analogs ``B = dx/dphi`` and their derivatives ``b = d2x/dphi2`` (the
acceleration bias at unit speed) give ``J_red = B^T M_x B`` (the generalized mass
matrix of the 1-DOF model) and ``dJ_red/dphi = 2 B^T (M_x b + h)``.

Public name: :func:`reduced_kinematics`.  The private ``_ModelEvaluator`` (positions
continued along the assembly branch, generalized forces of loads and drives) serves
:func:`~mechdyn.reduction.reduce.reduce_model` and ``ReducedMachine.from_model``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError, did_you_mean
from ..friction.ignored import warn_friction_ignored
from ..kernels.inertia import reduced_mass
from ..kernels.planar import perp
from ..kinematics.analogs import acceleration_bias, velocity_analogs
from ..kinematics.sweep import analyze, sweep
from ..model import Model, as_model
from ..model.constraints import full_jacobian
from ..model.forces import com_arms, force_model
from ..model.inertia import frame_mass_matrix, inertia_forces

__all__ = ["reduced_kinematics"]


def _inertia(model: Model, x, B, b):
    """J_red = B^T M_x B and dJ_red/dphi = 2 B^T (M_x b + h) of the analogs B, b (..., n_x)."""
    J = reduced_mass(frame_mass_matrix(model, x), np.asarray(B, float)[..., None])[..., 0, 0]
    return J, 2.0 * np.sum(B * inertia_forces(model, x, B, b), axis=-1)


def reduced_kinematics(model: Model, x, layout=None) -> dict:
    """Exact first and second transmission functions of a 1-DOF model (batched).

    Parameters
    ----------
    model : Model
        A model with ``n_q == 1``.
    x : array_like, shape (..., n_x)
        Solved body poses.
    layout : ConstraintLayout, optional

    Returns
    -------
    dict of ndarray
        ``B`` (..., n_x): dx/dphi of the body frames; ``b`` (..., n_x): d2x/dphi2
        (the acceleration bias at unit speed); ``vc``, ``ac`` (..., n_bodies, 2):
        centre-of-mass analogs dr_c/dphi (m/rad) and their derivatives
        (m/rad^2); ``w``, ``al`` (..., n_bodies): angular analogs dtheta/dphi and
        d2theta/dphi2; ``J`` (...): J_red, kg m^2; ``dJ`` (...): dJ_red/dphi,
        kg m^2/rad; ``Jf`` (..., n_x, n_x): the Jacobian [Phi_x; g_x].
    """
    lay = layout or model.layout()
    x = np.asarray(x, dtype=float)
    Jf = full_jacobian(model, x, lay)
    B = velocity_analogs(model, x, lay, J=Jf)[..., 0]
    b = acceleration_bias(model, x, B, lay, J=Jf)
    arm = com_arms(model, x)
    V = B.reshape(B.shape[:-1] + (-1, 3))
    A = b.reshape(V.shape)
    w, al = V[..., 2], A[..., 2]
    vc = V[..., :2] + w[..., None] * perp(arm)
    ac = A[..., :2] + al[..., None] * perp(arm) - (w**2)[..., None] * arm
    J, dJ = _inertia(model, x, B, b)
    return {"B": B, "b": b, "vc": vc, "ac": ac, "w": w, "al": al, "J": J, "dJ": dJ, "Jf": Jf}


class _ModelEvaluator:
    """Exact reduced quantities of a 1-DOF model at any position, with branch continuation."""

    def __init__(self, model: Model, coordinate: str | None = None, *, mode=None, x0=None):
        model = as_model(model)  # a Mechanism is compiled (and validated) here
        if model.n_q != 1:
            raise ModelError(
                f"the reduction method needs one degree of freedom, but the model has "
                f"{model.n_q} coordinates ({', '.join(model.coordinate_names)}); reduce a "
                f"1-DOF model (for a variable-structure machine: the model of one mode)")
        if coordinate is not None and coordinate not in model.coordinate_names:
            raise ModelError(did_you_mean(coordinate, model.coordinate_names, "coordinate"))
        self.friction = warn_friction_ignored(
            model, "the reduction method (reduce_model, ReducedMachine, steady_state, "
            "size_flywheel, startup)", "the reduced torque leaves out the friction moments "
            "and forces of these pairs (they depend on the reactions, hence on the speed and "
            "the acceleration), so the steady speed, the speed fluctuation and the flywheel "
            "are those of the frictionless machine; mechdyn.kinetostatics gives the losses "
            "and the driving torque with friction", stacklevel=3)
        self.model = model
        self.mode = mode
        self.coordinate = model.coordinate_names[0]
        self.is_angle = bool(model.coord_is_angle[0])
        self.forces = force_model(model)
        self.x_last = None if x0 is None else np.array(x0, dtype=float)  # None: the sketch
        self.max_step = math.radians(5.0) if self.is_angle else 0.05 * model.length_scale
        self._last = None  # (phi, x, B, b, J, dJ) of the last position

    def sweep(self, phis):
        """The kinematic sweep along the positions, continued from the last pose."""
        sw = sweep(self.model, values=phis, x_start=self.x_last, mode=self.mode)
        self.x_last = sw.raise_for_status().x[-1]
        return sw

    def state(self, phi: float):
        """(phi, x, B, b, J, dJ) at one position, continued from the last one (cached).

        Near the last position the solve starts from the second-order predictor
        ``x + B dphi + b dphi^2 / 2``; farther away the sweep continues to it.
        """
        phi = float(phi)
        last = self._last
        if last is None or last[0] != phi:
            if last is not None and abs(phi - last[0]) <= 3.0 * self.max_step:
                d = phi - last[0]
                guess = last[1] + last[2] * d + 0.5 * last[3] * d * d
            else:
                guess = self.sweep([phi]).x[-1]
            pt = analyze(self.model, [phi], [1.0], x_guess=guess, mode=self.mode)
            B, b = pt.B[:, 0], pt.xddot
            self._last = last = (phi, pt.x, B, b, *map(float, _inertia(self.model, pt.x, B, b)))
            self.x_last = pt.x
        return last

    def inertia(self, phi):
        return self.state(phi)[4:]

    def generalized_forces(self, t, phi, omega, x, B):
        """(M_forces, M_drive): B^T F of the applied forces and the drive torque, N m.

        Batched over positions: ``phi``, ``omega`` (n,) with ``x``, ``B`` (n, n_x).
        """
        omega = np.asarray(omega, dtype=float)
        F, Qd = self.forces.applied(t, x, B * omega[..., None], np.asarray(phi)[..., None],
                                    omega[..., None])
        return np.sum(B * F, axis=-1), Qd[..., 0]

    def torque(self, t, phi, omega):
        _, x, B, *_ = self.state(phi)
        mf, md = self.generalized_forces(float(t), phi, omega, x, B)
        return float(mf + md)
