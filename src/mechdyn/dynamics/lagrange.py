"""Equations of motion, Lagrange's equations of the second kind, for inspection:

    A(q) q'' + c(q, q') = Q(t, q, q')

in the generalized coordinates q of a model in one mode (its initial one by
default), with the body poses x re-solved from q at every evaluation (Newton from
the last solution, so the assembly branch is kept by continuity).
:class:`EquationsOfMotion` is a view of the equations that every run integrates,
:class:`~mechdyn.dynamics.mode_equations.ModeEquations` of the mode:

``"exact"`` (default)
    With the exact velocity analogs B = dx/dq and the acceleration bias b
    (``xddot = B q'' + b``), and the frame mass matrix M_x(x) and centripetal
    term h(x, xdot) of :mod:`mechdyn.model.inertia` (the body-frame origins
    need not be the centres of mass), A = B^T M_x B, c = B^T (M_x b + h),
    Q = B^T F + Q_drive, plus the rotor and gear inertia of the drives on their
    coordinates; through bifurcation positions on the branch the motion is on.

``"analogs"``
    The source paper's finite-difference analogs of the partial systems
    (:meth:`~mechdyn.dynamics.mode_equations.ModeEquations.analogs_terms`).

A mass matrix that is not positive definite raises
:class:`~mechdyn.errors.IntegrationError`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..kernels.inertia import reduced_force, reduced_mass
from ..kinematics.assembly import assemble
from ..model import Model
from ..model.forces import com_arms, force_model
from ..model.inertia import drive_inertia, frame_mass_matrix
from ..model.switchable import switched_model
from .mode_equations import FORMULATIONS, PIVOT_CHECK, ModeEquations
from .mode_system import ModeSystem

__all__ = ["EquationsOfMotion", "BranchEquations", "Terms", "FORMULATIONS", "PIVOT_CHECK",
           "equations_of_motion", "drive_inertia", "kinetic_energy", "potential_energy",
           "mass_matrix"]


@dataclass(frozen=True)
class Terms:
    """The terms of A q'' + c = Q at one state.

    Attributes
    ----------
    t : float
        Time, s.
    q, qdot, qddot : ndarray, shape (n_q,)
    x, xdot : ndarray, shape (n_x,)
        Body poses and their rates.
    B : ndarray, shape (n_x, n_q)
        Velocity analogs of the body frames, dx/dq.
    A : ndarray, shape (n_q, n_q)
        Generalized mass matrix (kg m^2 for angles, kg for travels, mixed kg m).
    c : ndarray, shape (n_q,)
        Velocity-dependent (Coriolis and centripetal) terms, N m or N.
    Q : ndarray, shape (n_q,)
        Generalized forces, N m or N (drives included).
    Q_drive : ndarray, shape (n_q,)
        The drives' part of Q.
    power_nc : float
        Power of the non-conservative forces (everything but gravity and spring
        stiffness), W.
    """

    t: float
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    B: np.ndarray
    A: np.ndarray
    c: np.ndarray
    Q: np.ndarray
    Q_drive: np.ndarray
    power_nc: float


def mass_matrix(model: Model, x, B) -> np.ndarray:
    """Generalized mass matrix A = B^T M_x B (M_x the frame mass matrix of
    :mod:`mechdyn.model.inertia`), shape (..., n_q, n_q)."""
    return reduced_mass(frame_mass_matrix(model, x), B)


def kinetic_energy(model: Model, x, xdot) -> np.ndarray:
    """T = 1/2 sum (m v_c^2 + J_c omega^2) of the bodies, J, shape (...)."""
    xdot = np.asarray(xdot, float)
    arm = com_arms(model, x)
    w = xdot[..., 2::3]
    vx = xdot[..., 0::3] - w * arm[..., 1]
    vy = xdot[..., 1::3] + w * arm[..., 0]
    return 0.5 * np.sum(model.mass * (vx * vx + vy * vy) + model.inertia * w * w, axis=-1)


def potential_energy(model: Model, x) -> np.ndarray:
    """Potential energy of gravity and springs, J, shape (...) (batched over poses)."""
    return force_model(model).potential_energy(x)


class EquationsOfMotion(ModeEquations):
    """A(q) q'' + c(q, q') = Q(t, q, q') of a model in one mode, evaluated on demand.

    Parameters
    ----------
    model : Model
    formulation : {"exact", "analogs"}
        See the module docstring.
    d : float or array_like, shape (n_q,), optional
        Virtual displacement of the ``"analogs"`` formulation (rad for angles, m
        for travels); default 0.1 deg for angles.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    x0 : array_like, shape (n_x,), optional
        A solved pose to start the Newton continuation from (default: the
        assembled sketch).
    backend : {"auto", "numpy", "numba"}
        ``"auto"`` uses the compiled kernel when numba is installed and every load
        is supported there (exact formulation only); ``"numba"`` insists on it.

    Attributes
    ----------
    equations : ModeEquations
        The equations of the mode, as the integrators see them (the view itself).
    backend, backend_note : str
        ``"numba"`` or ``"numpy"``; why the compiled path is not used.

    Raises
    ------
    ModelError
        An unknown formulation or backend, or a mode in which some declared
        coordinate is dependent.

    Examples
    --------
    A parallelogram four-bar of 1 m bars (1 kg, uniform) under gravity, its crank at
    1e-7 rad from the flat position (a bifurcation): (5/3) phi'' = -2 g cos(phi).

    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("parallelogram", gravity=(0.0, -9.81))
    >>> _ = m.add_ground({"O": (0.0, 0.0), "C": (1.0, 0.0)})
    >>> for name, pose in (("crank", (0, 0, 0.5)), ("coupler", (np.cos(0.5), np.sin(0.5), 0)),
    ...                    ("rocker", (1, 0, 0.5))):
    ...     _ = m.add_body(name, mass=1.0, inertia=1 / 12, com=(0.5, 0.0),
    ...                    points={"E": (1.0, 0.0)}, pose=pose)
    >>> _ = m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    >>> _ = m.add_revolute("A", "crank", "coupler", "E", (0.0, 0.0))
    >>> _ = m.add_revolute("B", "coupler", "rocker", "E", "E")
    >>> _ = m.add_revolute("C", "ground", "rocker", "C", (0.0, 0.0))
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> eom = EquationsOfMotion(m.compile(), backend="numpy")
    >>> _ = eom.qddot(0.0, [0.5], [-1.0])          # approaching: the chart is built
    >>> a = eom.qddot(0.0, [1e-7], [-1.0])[0]
    >>> bool(abs(a - (-2 * 9.81 * np.cos(1e-7) / (5 / 3))) < 1e-11)
    True
    """

    def __init__(self, model: Model, formulation: str = "exact", *, d=None, mode=None,
                 x0=None, backend: str = "auto"):
        self.model = model
        self.layout = model.layout(mode)
        if x0 is None:
            x0 = getattr(model, "x0", None)
            if x0 is None:
                x0 = assemble(model, layout=self.layout)
        sm = switched_model(model)
        locks = sm.initial_locks() if mode is None else frozenset(mode)
        targets: dict = {}
        for n in locks:
            sm.capture_target(n, x0, targets)
        ms = ModeSystem(sm, locks, targets, np.asarray(x0, float))
        if ms.n_i != model.n_q:
            raise ModelError(f"in mode {sorted(locks)} the coordinates "
                             f"{', '.join(model.coordinate_names)} are not all independent")
        super().__init__(sm, ms, backend, formulation, d)
        self.extra_inertia = sm.drive_inertia

    @property
    def equations(self) -> ModeEquations:
        return self

    @property
    def backend_note(self) -> str:
        return self.note

    @property
    def x(self) -> np.ndarray:
        """The last solved pose."""
        k = self.kernel
        return k.x.copy() if k is not None else self.ms.ws.x.copy()

    def positions(self, q, t: float | None = None, *, check_singular: bool = False):
        """Body poses x (n_x,) at coordinates ``q``, by Newton from the last solution.

        Raises
        ------
        AssemblyError, SingularPositionError
            (the latter only with ``check_singular``).
        """
        ev = self.evaluate(t or 0.0, np.asarray(q, float), np.zeros(self.model.n_q))
        if check_singular:
            self.check_position(t or 0.0, ev.x, ev.q)
        return ev.x.copy()

    def rhs(self, t: float, q, qdot):
        """q'' and the non-conservative power at (t, q, q'): ``(qddot (n_q,), p (1,))``."""
        return super().rhs(t, np.asarray(q, float), np.asarray(qdot, float))

    def qddot(self, t: float, q, qdot) -> np.ndarray:
        """Generalized accelerations q'' (n_q,) at (t, q, q')."""
        return self.rhs(t, q, qdot)[0]

    __call__ = qddot

    def terms(self, t: float, q, qdot) -> Terms:
        """All terms of the equations at one state (NumPy path, for inspection)."""
        q, qdot = np.asarray(q, float), np.asarray(qdot, float)
        if self.formulation == "analogs":
            return Terms(t, q, qdot, **self.analogs_terms(t, q, qdot))
        ev = self.evaluate(t, q, qdot)
        tm = self.ms.terms(t, ev.x, ev.xdot)
        B, M = tm["B"], tm["M"]
        Qd = self.sm.fm.applied(t, ev.x, ev.xdot, q, qdot)[1]
        return Terms(t, q, qdot, ev.qddot, ev.x, ev.xdot, B, tm["A"],
                     reduced_force(B, M @ tm["b"] + tm["h"]), reduced_force(B, tm["F"]), Qd,
                     self._power(ev))

    def energy(self, t: float, q, qdot) -> dict:
        """Kinetic and potential energy (J) and the non-conservative power (W) at one state."""
        tm = self.terms(t, q, qdot)
        T = 0.5 * float(qdot @ tm.A @ qdot)
        return {"kinetic": T, "potential": float(potential_energy(self.model, tm.x)),
                "power_nc": tm.power_nc}


#: the equations go through bifurcation positions on the branch (kept as a name)
BranchEquations = EquationsOfMotion


def equations_of_motion(model_or_mechanism, formulation: str = "exact", **kwargs
                        ) -> EquationsOfMotion:
    """:class:`EquationsOfMotion` of a model (a mechanism is compiled first)."""
    model = model_or_mechanism
    if not isinstance(model, Model):
        model = model.compile()
    return EquationsOfMotion(model, formulation, **kwargs)
