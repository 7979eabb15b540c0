"""The reduction method for 1-DOF machines (lecture notes, docs/references.md [2]).

A machine with one degree of freedom is replaced by one *link of reduction*
turning with the generalized coordinate ``phi`` (or with a chosen link) that
carries the reduced moment of inertia ``J_red(phi) = 2 T / omega^2`` (kg m^2),
its exact derivative ``dJ_red/dphi`` and the reduced torque ``M_red = B^T F +
M_drive`` of all applied forces and drives by equal power (N m); its equation of
motion (eq. 7.12) is ``J(phi) domega/dt + 1/2 omega^2 dJ/dphi = M_red(phi, omega, t)``
with ``J = J_red + J_extra``.  The formulas and their use are in
``docs/reduction-and-drives.md``.

Public names
------------
Reduction, reduce_model, mode_mechanism
    The reduced quantities of a model tabulated over a cycle, and a
    variable-structure mechanism in one mode as a 1-DOF mechanism (this module).
reduced_kinematics
    :mod:`mechdyn.reduction.kinematics`.
ReducedMachine, Member, MemberLoad
    :mod:`mechdyn.reduction.machine`.
SteadyCycle, steady_state, FlywheelSizing, size_flywheel
    :mod:`mechdyn.reduction.flywheel`.
ReducedRun, run_reduced, energy_speed, StartupResult, startup
    :mod:`mechdyn.reduction.run`.

All of them are importable from this module.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..brief import brief, span, status_text
from ..errors import ModelError, Status, did_you_mean
from ..mechanism.joint import Lock
from ..model import Model, as_model
from ..results.records import ReductionStats
from .flywheel import FlywheelSizing, SteadyCycle, size_flywheel, steady_state
from .kinematics import _inertia, _ModelEvaluator, reduced_kinematics
from .machine import (
    TWO_PI,
    Member,
    MemberLoad,
    ReducedMachine,
    _extra_inertia,
    _Record,
)
from .run import ReducedRun, StartupResult, energy_speed, run_reduced, startup

__all__ = ["Reduction", "reduce_model", "ReducedMachine", "Member", "MemberLoad",
           "ReducedRun", "run_reduced", "energy_speed", "SteadyCycle", "steady_state",
           "FlywheelSizing", "size_flywheel", "StartupResult", "startup",
           "reduced_kinematics", "mode_mechanism"]


# ============================================================================ the table
@dataclass(frozen=True, repr=False)
class Reduction(_Record):
    """Reduced quantities of a 1-DOF mechanism over a range of positions.

    All arrays have shape (n,) over the positions.  With a link of reduction the
    quantities refer to that link: ``J_red = 2T / omega_link^2``,
    ``dJ_red_dphi`` is taken with respect to the link's angle, ``M_red`` is the
    torque on the link by equal power.

    Attributes
    ----------
    coordinate : str
        The generalized coordinate.
    link : str or None
        The link of reduction (None: the coordinate itself).
    is_angle : bool
        Whether the coordinate is an angle (else a travel: kg and N instead of
        kg m^2 and N m).
    phi : ndarray
        Values of the coordinate, rad (m for a travel).
    link_angle : ndarray or None
        Absolute angle of the link of reduction, rad.
    ratio : ndarray
        Transmission function d(link angle)/dphi (ones without a link).
    J_red, dJ_red_dphi : ndarray
        Reduced moment of inertia of the mechanism (kg m^2) and its derivative
        (kg m^2/rad).
    J_extra : ndarray
        Inertia added by the drives and the flywheel, reduced to the link
        (``J_extra_coordinate / ratio^2``), kg m^2.
    M_red, M_drive, M_forces : ndarray
        Reduced torque of all forces and drives, of the drives alone and of the
        applied forces (gravity, springs, loads) alone, N m.
    omega : ndarray
        Speed of the link of reduction at which M_red was evaluated, rad/s.
    t : float
        Time at which M_red was evaluated, s.
    point : (str, str) or None
        (body, point) of the reduced mass.
    m_red, v_ratio : ndarray or None
        Reduced mass at the point, ``2 T / v_P^2`` (kg, whole machine including
        J_extra), and ``|v_P| / omega`` (m/rad).
    status, message, events, stats
        As every result record.
    """

    coordinate: str
    link: str | None
    is_angle: bool
    phi: np.ndarray
    link_angle: np.ndarray | None
    ratio: np.ndarray
    J_red: np.ndarray
    dJ_red_dphi: np.ndarray
    J_extra: np.ndarray
    M_red: np.ndarray
    M_drive: np.ndarray
    M_forces: np.ndarray
    omega: np.ndarray
    t: float = 0.0
    point: tuple | None = None
    m_red: np.ndarray | None = None
    v_ratio: np.ndarray | None = None

    def __repr__(self) -> str:
        link = f"link {self.link!r}" if self.link is not None else ""
        return brief(self, f"{self.phi.size} positions of {self.coordinate!r}", link,
                     status_text(self), f"J_red = {span(self.J_red, 'kg m^2')}",
                     f"M_red = {span(self.M_red, 'N m' if self.is_angle else 'N')}")

    @property
    def J_total(self) -> np.ndarray:
        """J_red + J_extra, kg m^2."""
        return self.J_red + self.J_extra

    @property
    def position(self) -> np.ndarray:
        """The position variable of the link of reduction: the link angle, or phi."""
        return self.phi if self.link_angle is None else self.link_angle

    def work(self) -> np.ndarray:
        """Work of M_red from the first position, integral M_red d(position), J (trapezoid)."""
        from scipy.integrate import cumulative_trapezoid

        return cumulative_trapezoid(self.M_red, self.position, initial=0.0)

    def to_dataframe(self):
        """The table with unit-suffixed columns (``phi_deg``, ``J_red_kgm2``, ``M_red_Nm`` ...)."""
        import pandas as pd

        ang = self.is_angle or self.link is not None
        iu, tu, du = ("kgm2", "Nm", "kgm2") if ang else ("kg", "N", "kg")
        cols = ({"phi_deg": np.degrees(self.phi), "phi_rad": self.phi} if self.is_angle
                else {"s_m": self.phi})
        if self.link is not None:
            cols[f"theta_{self.link}_deg"] = np.degrees(self.link_angle)
            cols["ratio"] = self.ratio
        cols.update({f"J_red_{iu}": self.J_red,
                     f"dJ_red_dphi_{du}" + ("" if ang else "_per_m"): self.dJ_red_dphi,
                     f"J_extra_{iu}": self.J_extra, f"J_total_{iu}": self.J_total,
                     f"M_red_{tu}": self.M_red, f"M_drive_{tu}": self.M_drive,
                     f"M_forces_{tu}": self.M_forces,
                     "omega_rad_s" if ang else "v_m_s": self.omega})
        if self.m_red is not None:
            cols.update({"m_red_kg": self.m_red, "v_ratio_m_rad": self.v_ratio})
        return pd.DataFrame(cols)

    def machine(self, model: Model | None = None, **kwargs) -> ReducedMachine:
        """A fast :class:`ReducedMachine` interpolating this table (see
        :meth:`~mechdyn.reduction.machine.ReducedMachine.from_reduction`)."""
        return ReducedMachine.from_reduction(self, model, **kwargs)


def reduce_model(model: Model, *, coordinate: str | None = None, link: str | None = None,
                 point: tuple[str, object] | None = None, steps: int = 361,
                 phi=None, start: float = 0.0, period: float | None = None,
                 omega: float = 1.0, t: float = 0.0, extra_inertia: float | None = None,
                 mode=None, x0=None) -> Reduction:
    """Tabulate the reduced quantities of a 1-DOF model over a cycle.

    Parameters
    ----------
    model : Model
        A compiled model with one generalized coordinate (in ``mode``).
    coordinate : str, optional
        Its name (checked; default the model's only coordinate).
    link : str, optional
        A body taken as the link of reduction: quantities are divided by its
        angular-velocity analog (``J_link = J_red / (dtheta_link/dphi)^2``,
        ``M_link = M_red / (dtheta_link/dphi)``).  Where that analog vanishes
        (a rocker at its dead positions) they are infinite.
    point : (body, point), optional
        Also give the reduced mass at this point, ``2 T / v_P^2``, kg.
    steps : int
        Number of positions (default 361: every degree of a turn, ends included).
    phi : array_like, shape (n,), optional
        Explicit positions (rad or m), followed in order; overrides
        ``steps``/``start``/``period``.
    start, period : float
        The cycle ``start ... start + period`` (rad; default period 2 pi; required
        for a travel coordinate unless ``phi`` is given).
    omega : float
        Speed of the link of reduction at which forces and drives are evaluated
        (rad/s, or m/s); matters for velocity-dependent loads and motors only.
    t : float
        Time at which loads are evaluated, s.
    extra_inertia : float, optional
        Inertia added on the coordinate, kg m^2; default the drives' rotor and
        gear inertia (``extra_inertia()`` of their torque objects).
    mode : iterable of str, optional
        Engaged locks (default the model's initial mode).
    x0 : array_like, shape (n_x,), optional
        A pose on the wanted assembly branch (default the sketch).

    Returns
    -------
    Reduction
        ``stats.friction_ignored``: the joints with friction, which the reduction
        leaves out (a :class:`~mechdyn.friction.ignored.FrictionIgnoredWarning`
        names them).
    """
    model = as_model(model)  # a Mechanism is compiled (and validated) here
    ev = _ModelEvaluator(model, coordinate, mode=mode, x0=x0)
    if phi is None:
        if steps is None or int(steps) < 2:
            raise ModelError(f"steps must be an integer >= 2, got {steps!r}")
        if period is None:
            if not ev.is_angle:
                raise ModelError(f"coordinate {ev.coordinate!r} is a travel: give the "
                                 f"positions (phi=...) or the period (m) of the cycle")
            period = TWO_PI
        phis = float(start) + np.linspace(0.0, float(period), int(steps))
    else:
        phis = np.asarray(phi, dtype=float).reshape(-1)
        if phis.size < 1 or not np.all(np.isfinite(phis)):
            raise ModelError("phi must be a non-empty sequence of finite positions")
    j_extra = _extra_inertia(extra_inertia, model)
    sw = ev.sweep(phis)
    xs, B = sw.x, sw.B[..., 0]
    J, dJ = _inertia(model, xs, B, sw.xddot)
    n = phis.size
    if link is None:
        ratio, dratio, link_angle = np.ones(n), np.zeros(n), None
    elif model.body_index(link) >= model.n_bodies:
        raise ModelError(f"link of reduction: the ground cannot be the link; choose one of "
                         f"{', '.join(model.body_names)}")
    else:
        link_angle, ratio, dratio = sw.angular(link)
    with np.errstate(divide="ignore", invalid="ignore"):
        qdot = float(omega) / ratio
        mf, md = ev.generalized_forces(float(t), phis, np.where(np.isfinite(qdot), qdot, 0.0),
                                       xs, B)
        J_link = J / ratio**2
        dJ_link = (dJ / ratio**2 - 2.0 * J * dratio / ratio**3) / ratio
        J_extra = j_extra / ratio**2
        M_f, M_d = mf / ratio, md / ratio
    m_red = v_ratio = None
    if point is not None:
        point = tuple(point)
        v_ratio = np.linalg.norm(sw.point_analogs(*point)[..., 0], axis=-1)
        with np.errstate(divide="ignore"):
            m_red = (J + j_extra) / v_ratio**2
    bad = ~np.isfinite(J_link) | (np.abs(ratio) <= 1e-9 * np.max(np.abs(ratio), initial=0.0))
    status, message = "success", ""
    if np.any(bad):
        status = Status.SINGULAR_POSITION
        message = (f"the angular-velocity analog of link {link!r} vanishes at "
                   f"{int(bad.sum())} position(s) (e.g. phi = "
                   f"{np.degrees(phis[np.argmax(bad)]):.4g} deg): the reduced quantities are "
                   f"infinite there; choose a link that turns continuously")
    return Reduction(
        coordinate=ev.coordinate, link=link, is_angle=ev.is_angle, phi=phis,
        link_angle=link_angle, ratio=ratio, J_red=J_link, dJ_red_dphi=dJ_link, J_extra=J_extra,
        M_red=M_f + M_d, M_drive=M_d, M_forces=M_f, omega=np.full(n, float(omega)), t=float(t),
        point=point, m_red=m_red, v_ratio=v_ratio, status=status, message=message,
        stats=ReductionStats(positions=n, extra_inertia_coordinate=j_extra,
                             friction_ignored=ev.friction))


def mode_mechanism(mechanism, *, engage: Sequence[str] = (), offsets: dict | None = None,
                   drop: Sequence[str] = ()):
    """A copy of a mechanism with locks engaged and the coordinates they freeze removed.

    The reduction method needs one degree of freedom; a variable-structure
    machine has it in some modes only (the clutchless press in its working mode:
    rocker locked onto the slider).  This builds that mode as a mechanism of its
    own.

    Parameters
    ----------
    mechanism : Mechanism
    engage : sequence of str
        Locks to engage.
    offsets : dict, optional
        Lock name -> pose (x m, y m, theta rad) of the child frame in the parent
        frame held by the lock; default the lock's own offset (or the sketch).
    drop : sequence of str
        Coordinates to remove (those the engaged locks freeze).

    Returns
    -------
    Mechanism
        The original is not changed; initial values of dropped coordinates are
        removed from ``extras["initial"]``.
    """
    offsets = dict(offsets or {})
    joints = dict(mechanism.joints)
    probs = []
    for name in engage:
        j = joints.get(name)
        if not isinstance(j, Lock):
            locks = [n for n, jj in joints.items() if isinstance(jj, Lock)]
            probs.append(did_you_mean(name, locks, "lock"))
            continue
        off = offsets.pop(name, j.offset)
        joints[name] = dataclasses.replace(j, engaged=True,
                                           offset=None if off is None else tuple(map(float, off)))
    probs += [f"offsets: lock {name!r} is not in engage" for name in offsets]
    probs += [did_you_mean(name, mechanism.coordinates, "coordinate") for name in drop
              if name not in mechanism.coordinates]
    coords = {k: v for k, v in mechanism.coordinates.items() if k not in set(drop)}
    if probs:
        raise ModelError(probs)
    extras = dict(mechanism.extras)
    init = extras.get("initial")
    if isinstance(init, dict):
        extras["initial"] = {k: {c: v for c, v in dict(d or {}).items() if c in coords}
                             for k, d in init.items()}
    return dataclasses.replace(mechanism, joints=joints, coordinates=coords,
                               loads=list(mechanism.loads), drives=list(mechanism.drives),
                               extras=extras)
