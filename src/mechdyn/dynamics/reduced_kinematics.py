"""Exact reduced kinematics of a one-degree-of-freedom model (METHOD.md §2).

The velocity analogs of the body frames and centres of mass, ``B = dx/dphi``,
and their derivatives ``b = d2x/dphi2`` (the acceleration bias at unit speed)
give the reduced moment of inertia ``J_red = sum_k (m_k |v_ck/omega|^2 +
J_ck (omega_k/omega)^2)`` and its exact derivative ``dJ_red/dphi``.

Public names
------------
reduced_kinematics
    The transmission functions and J_red, dJ_red/dphi of solved poses (batched).

The evaluator ``_ModelEvaluator`` (positions continued along the assembly
branch, the generalized force of loads and drives) serves
:func:`~mechdyn.dynamics.reduction.reduce_model` and
:meth:`~mechdyn.dynamics.reduced_machine.ReducedMachine.from_model`.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kinematics.assembly import assemble, solve_position
from ..kinematics.constraints import (
    coordinates,
    coordinates_gamma,
    coordinates_jacobian,
    gamma,
    jacobian,
    residual,
)
from ..mechanism.motors import extra_inertia_by_coordinate
from ..model import Model, as_model
from .forces import force_model

__all__ = ["reduced_kinematics"]


def _rot(th, s):
    """A(theta) s for th (..., nb) and s (nb, 2) -> (..., nb, 2)."""
    c, sn = np.cos(th), np.sin(th)
    return np.stack([c * s[:, 0] - sn * s[:, 1], sn * s[:, 0] + c * s[:, 1]], axis=-1)


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _lin_solve(J, rhs):
    """Solve [Phi_x; g_x] y = rhs (least squares for redundant constraint sets)."""
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(J, rhs)
    return np.linalg.pinv(J) @ rhs


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
    Jf = np.concatenate([jacobian(model, x, lay), coordinates_jacobian(model, x)], axis=-2)
    rhs = np.zeros(Jf.shape[:-1] + (1,))
    rhs[..., lay.n_rows:, 0] = 1.0
    B = _lin_solve(Jf, rhs)[..., 0]
    g = np.concatenate([gamma(model, x, B, lay), coordinates_gamma(model, x, B)], axis=-1)
    b = _lin_solve(Jf, g[..., None])[..., 0]
    th = x[..., 2::3]
    arm = _rot(th, model.com)
    w, al = B[..., 2::3], b[..., 2::3]
    vr = np.stack([B[..., 0::3], B[..., 1::3]], axis=-1)
    ar = np.stack([b[..., 0::3], b[..., 1::3]], axis=-1)
    vc = vr + w[..., None] * _perp(arm)
    ac = ar + al[..., None] * _perp(arm) - (w**2)[..., None] * arm
    m, jc = model.mass, model.inertia
    J = np.sum(m * np.sum(vc * vc, axis=-1) + jc * w * w, axis=-1)
    dJ = 2.0 * np.sum(m * np.sum(vc * ac, axis=-1) + jc * w * al, axis=-1)
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
        self.model = model
        self.coordinate = model.coordinate_names[0]
        self.is_angle = bool(model.coord_is_angle[0])
        self.layout = model.layout(mode)
        self.forces = force_model(model)
        if x0 is None:
            x0 = getattr(model, "x0", None)
            if x0 is None:
                x0 = assemble(model, layout=self.layout)
        self.x_last = np.array(x0, dtype=float)
        self.q_last = float(coordinates(model, self.x_last)[0])
        self.max_step = math.radians(5.0) if self.is_angle else 0.05 * model.length_scale
        self._cache_q = None
        self._cache = None
        self._pred = None  # (q, x, B, b) of the last full evaluation

    def pose(self, phi: float) -> np.ndarray:
        """Solved pose at ``phi``, continued from the last pose (keeps the branch).

        Near the last evaluated position the Newton solve starts from the
        second-order predictor ``x + B dphi + b dphi^2 / 2``.
        """
        phi = float(phi)
        pred = self._pred
        if pred is not None and abs(phi - pred[0]) <= 3.0 * self.max_step:
            d = phi - pred[0]
            guess = pred[1] + pred[2] * d + 0.5 * pred[3] * d * d
            x = self._chord(phi, guess, pred[4])
            if x is None:
                x = solve_position(self.model, np.array([phi]), guess, layout=self.layout,
                                   check_singular=False)
        else:
            n = max(1, int(math.ceil(abs(phi - self.q_last) / self.max_step)))
            x = self.x_last
            for q in np.linspace(self.q_last, phi, n + 1)[1:]:
                x = solve_position(self.model, np.array([q]), x, layout=self.layout,
                                   check_singular=False)
        self.x_last, self.q_last = x, phi
        return x

    def _chord(self, phi, x, Jf, max_iter: int = 8):
        """Chord Newton from a close predictor with the last Jacobian; None if it stalls."""
        tol = 1e-13 * max(self.model.length_scale, 1e-3)
        if Jf.shape[0] != Jf.shape[1]:
            return None
        prev = np.inf
        for _ in range(max_iter):
            F = np.concatenate([residual(self.model, x, self.layout),
                                coordinates(self.model, x) - phi])
            err = float(np.max(np.abs(F)))
            if err <= tol:
                return x
            if err > 0.5 * prev:
                return x if err <= 1e3 * tol else None
            prev = err
            x = x - np.linalg.solve(Jf, F)
        return None

    def poses(self, phis) -> np.ndarray:
        """Poses along a sequence of positions (continuation in the given order), (n, n_x).

        Positions are solved one by one only at a coarse stride (at most
        ``max_step`` apart); every other position starts from a second-order
        Taylor predictor of its coarse neighbour, ``x_c + B dphi + b dphi^2/2``,
        and all are polished by one batched Newton solve.
        """
        phis = np.asarray(phis, float).reshape(-1)
        n = phis.size
        if n <= 4:
            return np.array([self.pose(p) for p in phis])
        coarse = [0]
        for i in range(1, n):
            if abs(phis[i] - phis[coarse[-1]]) > self.max_step:
                coarse.append(i - 1 if i - 1 != coarse[-1] else i)
        xc = np.array([self.pose(phis[i]) for i in coarse])
        kin = reduced_kinematics(self.model, xc, self.layout)
        owner = np.searchsorted(np.asarray(coarse), np.arange(n), side="right") - 1
        d = (phis - phis[np.asarray(coarse)][owner])[:, None]
        guess = xc[owner] + kin["B"][owner] * d + 0.5 * kin["b"][owner] * d * d
        xs = solve_position(self.model, phis[:, None], guess, layout=self.layout,
                            check_singular=False)
        self.x_last, self.q_last = xs[-1], float(phis[-1])
        self._cache_q = None
        return xs

    def state(self, phi: float):
        """(x, kinematics dict) at one position (cached for the last position)."""
        if self._cache_q != phi:
            x = self.pose(phi)
            kin = reduced_kinematics(self.model, x, self.layout)
            self._cache = (x, kin)
            self._cache_q = phi
            self._pred = (phi, x, kin["B"], kin["b"], kin["Jf"])
        return self._cache

    def drive_inertia(self) -> float:
        """Rotor and gear inertia of the drives on the coordinate, kg m^2."""
        return extra_inertia_by_coordinate(self.model.mechanism).get(self.coordinate, 0.0)

    def inertia(self, phi):
        _, kin = self.state(float(phi))
        return float(kin["J"]), float(kin["dJ"])

    def generalized_forces(self, t, phi, omega, x, B) -> tuple[float, float]:
        """(M_forces, M_drive): B^T F of the applied forces and the drive torque, N m."""
        F, Qd = self.forces.applied(float(t), x, B * omega, np.array([phi]), np.array([omega]))
        return float(B @ F), float(Qd[0])

    def torque(self, t, phi, omega):
        x, kin = self.state(float(phi))
        mf, md = self.generalized_forces(t, phi, omega, x, kin["B"])
        return mf + md
