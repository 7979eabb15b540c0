"""Kinetostatics (inverse dynamics for a given motion): driving torques, joint
reactions, and the loads the frame and foundation receive.

The generalized coordinates follow a prescribed motion (a constant speed, a law
of time, or a trajectory from forward dynamics).  Driving constraints
``g_d(x) - q_d(t) = 0`` are appended to the joint constraints ``Phi(x) = 0``;
with the body poses ``x`` and their rates known, the Lagrange multipliers follow
from one linear solve per position (batched over all positions at once)::

    -Phi_x^T lambda + g_d,x^T tau = I(x, xdot, xddot) - F(t, x, xdot)

* ``I`` are the inertia forces conjugate to the body-frame poses: for each body
  ``m a_c`` and ``J_c alpha + a x m a_c`` (``a``: the centre of mass relative to
  the frame origin) -- i.e. ``M_x xddot`` plus the centripetal terms of a
  non-diagonal frame mass matrix ``M_x`` (:func:`frame_mass_matrix`).
* ``F`` are the applied forces (gravity, springs, forces, torques, process
  loads; force and moment about the body-frame origin).
* ``-Phi_x^T lambda`` are the constraint forces on the bodies; a joint's rows
  give its reaction.
* ``tau`` is the torque (N m) or force (N) the drive must APPLY to each driven
  coordinate -- positive when it acts in the positive sense of the coordinate.

Sign conventions (also in ``docs/kinetostatics.md``, section "Reactions and
driving torques"):

* The reaction of a joint is the force ON THE CHILD body FROM THE PARENT, at the
  joint point (revolute: the child point; prismatic: the child point; lock: the
  child frame origin), in the ground frame; the parent receives the opposite.
  Prismatic joints and locks also carry a moment on the child about that point.
* ``Drive`` elements on a driven coordinate are REPLACED by the prescribed
  motion (``model_drives="replace"``, default): ``driving`` is then the whole
  torque the motor must deliver.  With ``model_drives="load"`` they act as
  known loads and ``driving`` is the extra torque needed on top of them.
  Drives on coordinates that are not driven always act as known loads.
* The frame loads are what the FRAME RECEIVES from the mechanism: minus the
  reaction of every joint to the ground, the reaction torque of the drives on
  their stator (a drive of an absolute crank angle puts ``-tau`` on the frame),
  and the ground ends of springs, rotary springs and torques attached to it.
  Their sum is the shaking force and the shaking moment about ``point``.
  ``Force`` loads (e.g. a punch force) are external: their reaction is not
  carried by the frame unless named in ``reacting_loads``.
"""

from __future__ import annotations

import time
import warnings as _warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import AssemblyError, ModelError, SingularPositionError, did_you_mean
from ..kinematics.assembly import SINGULAR_RCOND, joint_residuals
from ..kinematics.constraints import (
    coordinates,
    coordinates_gamma,
    coordinates_jacobian,
    extend,
    gamma,
    jacobian,
    point_position,
    point_velocity,
    residual,
)
from ..mechanism.drive import TorqueSpeedCurve
from ..mechanism.load import Table
from ..model import COORD_TRAVEL, ConstraintLayout, Model, as_model
from .forces import LoadContext, evaluate, force_model

__all__ = ["Kinetostatics", "kinetostatics", "inertia_forces", "frame_mass_matrix",
           "applied_forces", "dead_centres", "KinetostaticsWarning"]

#: relative singular value below which constraint equations count as dependent
REDUNDANT_RCOND = 1e-9
#: rcond of the scaled inverse-dynamics matrix below which a position is reported
#: as close to singular (a warning; the solve is still exact)
NEAR_SINGULAR_RCOND = 1e-6


class KinetostaticsWarning(UserWarning):
    """Redundant constraints or singular positions in a kinetostatic analysis."""


# ====================================================================== helpers
def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _rotb(th, s):
    """A(th) s: th shape (...,), s shape (2,) -> (..., 2)."""
    c, sn = np.cos(th), np.sin(th)
    return np.stack([c * s[0] - sn * s[1], sn * s[0] + c * s[1]], axis=-1)


def _col_scale(model: Model) -> np.ndarray:
    s = np.ones(model.n_x)
    s[2::3] = model.length_scale
    return s




# ================================================================ inertia
def frame_mass_matrix(model: Model, x) -> np.ndarray:
    """Mass matrix M_x of the body-frame coordinates, shape (..., n_x, n_x).

    With the centre of mass at ``a = A(theta) com`` from the frame origin, the
    kinetic energy ``1/2 m |v + omega perp(a)|^2 + 1/2 J_c omega^2`` gives, per
    body, the block ``[[m, 0, -m a_y], [0, m, m a_x], [-m a_y, m a_x, J_c + m |a|^2]]``
    (kg, kg m, kg m^2).  The inertia forces are ``M_x xddot`` plus the
    centripetal force ``-m omega^2 a`` (see :func:`inertia_forces`).
    """
    x = np.asarray(x, dtype=float)
    nb = model.n_bodies
    th = x[..., 2::3]
    a = np.stack([np.cos(th) * model.com[:, 0] - np.sin(th) * model.com[:, 1],
                  np.sin(th) * model.com[:, 0] + np.cos(th) * model.com[:, 1]], axis=-1)
    m = model.mass
    M = np.zeros(x.shape[:-1] + (model.n_x, model.n_x))
    for b in range(nb):
        k = 3 * b
        M[..., k, k] = m[b]
        M[..., k + 1, k + 1] = m[b]
        M[..., k, k + 2] = M[..., k + 2, k] = -m[b] * a[..., b, 1]
        M[..., k + 1, k + 2] = M[..., k + 2, k + 1] = m[b] * a[..., b, 0]
        M[..., k + 2, k + 2] = model.inertia[b] + m[b] * (a[..., b, 0] ** 2 + a[..., b, 1] ** 2)
    return M


def inertia_forces(model: Model, x, xdot, xddot) -> np.ndarray:
    """Inertia forces conjugate to the body-frame poses, shape (..., n_x).

    Per body: ``m a_c`` (N) and ``J_c alpha + a x (m a_c)`` (N m, about the
    frame origin), with ``a_c = rddot + alpha perp(a) - omega^2 a`` the
    acceleration of the centre of mass.  Equals ``M_x xddot - m omega^2 a``.

    Parameters
    ----------
    x, xdot, xddot : array_like, shape (..., n_x)
        Poses (m, rad), their rates and accelerations.
    """
    x = np.asarray(x, dtype=float)
    nb = model.n_bodies
    batch = x.shape[:-1]
    X = x.reshape(batch + (nb, 3))
    V = np.asarray(xdot, dtype=float).reshape(batch + (nb, 3))
    W = np.asarray(xddot, dtype=float).reshape(batch + (nb, 3))
    th = X[..., 2]
    c, s = np.cos(th), np.sin(th)
    a = np.stack([c * model.com[:, 0] - s * model.com[:, 1],
                  s * model.com[:, 0] + c * model.com[:, 1]], axis=-1)
    ac = W[..., :2] + W[..., 2, None] * _perp(a) - (V[..., 2] ** 2)[..., None] * a
    f = model.mass[:, None] * ac
    mom = model.inertia * W[..., 2] + _cross(a, f)
    return np.concatenate([f, mom[..., None]], axis=-1).reshape(batch + (model.n_x,))


# ================================================================ applied forces
class _BatchContext:
    """A LoadContext whose attributes are arrays over positions (first axis)."""

    def __init__(self, model, t, q, qdot, x, xdot):
        self.model, self.t, self.q, self.qdot, self.x, self.xdot = model, t, q, qdot, x, xdot

    def coord(self, name):
        return self.q[:, self.model.coordinate_index(name)]

    def rate(self, name):
        return self.qdot[:, self.model.coordinate_index(name)]

    def point(self, body, point):
        return point_position(self.model, self.x, body, point)

    def velocity(self, body, point):
        return point_velocity(self.model, self.x, self.xdot, body, point)

    def variable(self, name):
        if name == "t":
            return self.t
        if name in self.model.coordinate_names:
            return self.coord(name)
        if name.endswith("_dot") and name[:-4] in self.model.coordinate_names:
            return self.rate(name[:-4])
        parts = name.split(".")
        if len(parts) == 3 and parts[2] in ("x", "y"):
            p = self.point(parts[0], parts[1])
            return p[:, 0] if parts[2] == "x" else p[:, 1]
        raise ModelError(f"unknown table variable {name!r}; use 't', a coordinate "
                         f"({', '.join(self.model.coordinate_names)}), '<coordinate>_dot' or "
                         f"'body.point.x' / 'body.point.y'")


def _table_batch(tab: Table, s) -> np.ndarray:
    s = np.asarray(s, dtype=float)
    y = np.interp(s, tab.x, tab.y)
    if tab.outside is not None:
        y = np.where((s < tab.x[0]) | (s > tab.x[-1]), tab.outside, y)
    return y


def _value_batch(value, bctx: _BatchContext, where: str) -> np.ndarray:
    """A load value for every position: vectorized where possible, else a loop."""
    n = bctx.t.shape[0]
    if isinstance(value, Table):
        return _table_batch(value, bctx.variable(value.variable))
    if callable(value):
        if getattr(value, "vectorized", False):
            out = np.broadcast_to(np.asarray(value(bctx), dtype=float), (n,)).copy()
        else:
            out = np.empty(n)
            for k in range(n):
                ctx = LoadContext(bctx.model, float(bctx.t[k]), bctx.q[k], bctx.qdot[k],
                                  bctx.x[k], bctx.xdot[k])
                out[k] = evaluate(value, ctx, where)
        if not np.all(np.isfinite(out)):
            k = int(np.argmax(~np.isfinite(out)))
            raise ModelError(f"{where}: value is not finite ({out[k]!r}) at "
                             f"t = {bctx.t[k]:.6g} s")
        return out
    return np.full(n, float(value))


def _drive_batch(fm, dr, k: int, bctx: _BatchContext) -> np.ndarray:
    tq = dr.torque
    n = bctx.t.shape[0]
    if isinstance(tq, TorqueSpeedCurve):
        return np.interp(bctx.qdot[:, k], tq.omega, tq.torque)
    if isinstance(tq, Table):
        return _table_batch(tq, bctx.variable(tq.variable))
    if not callable(tq) and not hasattr(tq, "torque_at"):
        return np.full(n, float(tq))
    out = np.empty(n)
    for i in range(n):
        ctx = LoadContext(bctx.model, float(bctx.t[i]), bctx.q[i], bctx.qdot[i], bctx.x[i],
                          bctx.xdot[i])
        out[i] = fm.drive_torque(dr, ctx, k)
    return out


def _apply(F, b, arm, f):
    """Add force f (n,2) at arm (n,2) from the origin of body slot b to F (n, nb+1, 3)."""
    F[:, b, 0] += f[:, 0]
    F[:, b, 1] += f[:, 1]
    F[:, b, 2] += _cross(arm, f)


def applied_forces(model: Model, t, x, xdot, q, qdot, *, skip_drives: Sequence[int] = (),
                   reacting_loads: Sequence[str] = ()):
    """Applied forces for a batch of positions (vectorized version of ``ForceModel.applied``).

    Parameters
    ----------
    t : array_like, shape (n,)
    x, xdot : array_like, shape (n, n_x)
    q, qdot : array_like, shape (n, n_q)
    skip_drives : sequence of int
        Coordinates whose ``Drive`` elements are left out (replaced by a prescribed motion).
    reacting_loads : sequence of str
        Names of ``Force`` loads whose reaction the frame carries.

    Returns
    -------
    F : ndarray, shape (n, n_x)
        Forces (N) and moments about the body-frame origins (N m) on the moving
        bodies, drives on coordinates included (as ``g_x^T Q_drive``).
    ground : ndarray, shape (n, 3)
        Force (N) and moment about the ground origin (N m) that the load
        elements attached to the frame put on it (spring ends, torque
        reactions, reacting forces); drives are not included here.
    Qd : ndarray, shape (n, n_q)
        The drive torques/forces that were applied, per coordinate.
    """
    fm = force_model(model)
    t = np.asarray(t, dtype=float).reshape(-1)
    x = np.asarray(x, dtype=float)
    xdot = np.asarray(xdot, dtype=float)
    n = t.shape[0]
    nb = model.n_bodies
    X = extend(model, x)
    V = extend(model, xdot)
    bctx = _BatchContext(model, t, np.asarray(q, float), np.asarray(qdot, float), x, xdot)
    F = np.zeros((n, nb + 1, 3))
    # gravity
    if np.any(model.gravity) and np.any(model.mass):
        th = X[:, :nb, 2]
        c, s = np.cos(th), np.sin(th)
        a = np.stack([c * model.com[:, 0] - s * model.com[:, 1],
                      s * model.com[:, 0] + c * model.com[:, 1]], axis=-1)
        w = model.mass[:, None] * model.gravity  # (nb, 2)
        F[:, :nb, :2] += w
        F[:, :nb, 2] += _cross(a, np.broadcast_to(w, a.shape))
    for (name, i, si, j, sj, k, L0, cdamp, pre) in fm.springs:
        ai, aj = _rotb(X[:, i, 2], si), _rotb(X[:, j, 2], sj)
        d = X[:, j, :2] + aj - X[:, i, :2] - ai
        L = np.hypot(d[:, 0], d[:, 1])
        if np.any(L < 1e-300):
            raise ModelError(f"spring {name!r}: its two points coincide; direction undefined")
        e = d / L[:, None]
        vd = (V[:, j, :2] + V[:, j, 2, None] * _perp(aj)
              - V[:, i, :2] - V[:, i, 2, None] * _perp(ai))
        f = k * (L - L0) + cdamp * np.sum(e * vd, axis=-1) + pre
        _apply(F, i, ai, f[:, None] * e)
        _apply(F, j, aj, -f[:, None] * e)
    for (_name, i, j, k, a0, cdamp, pre) in fm.rotary:
        tq = -(k * (X[:, j, 2] - X[:, i, 2] - a0) + cdamp * (V[:, j, 2] - V[:, i, 2]) + pre)
        F[:, j, 2] += tq
        F[:, i, 2] -= tq
    reacting = set(reacting_loads)
    for (ld, b, s) in fm.forces:
        mag = _value_batch(ld.magnitude, bctx, f"force {ld.name!r}")
        d = np.asarray(ld.direction, dtype=float)
        arm = _rotb(X[:, b, 2], s)
        dirs = _rotb(X[:, b, 2], d) if ld.frame == "body" else np.broadcast_to(d, (n, 2))
        f = mag[:, None] * dirs
        if b < nb:
            _apply(F, b, arm, f)
        if ld.name in reacting:
            # the frame takes the reaction along the same line of action
            _apply(F, nb, X[:, b, :2] + arm, -f)
    for (ld, b, r) in fm.torques:
        tq = _value_batch(ld.magnitude, bctx, f"torque {ld.name!r}")
        F[:, b, 2] += tq
        if r is not None:
            F[:, r, 2] -= tq
    Qd = np.zeros((n, model.n_q))
    skip = set(int(k) for k in skip_drives)
    for (dr, k) in fm.drives:
        if k in skip:
            continue
        Qd[:, k] += _drive_batch(fm, dr, k, bctx)
    Fx = F[:, :nb, :].reshape(n, model.n_x)
    if np.any(Qd):
        Fx = Fx + np.einsum("nq,nqx->nx", Qd, coordinates_jacobian(model, x))
    return Fx, F[:, nb, :].copy(), Qd


def _net_on_ground(model: Model, x, D) -> np.ndarray:
    """Minus the net force and moment about the ground origin of body forces D (n, n_x).

    For a force element between the frame and the moving bodies, this is what
    the frame receives (action and reaction).
    """
    n = D.shape[0]
    Db = D.reshape(n, model.n_bodies, 3)
    r = np.asarray(x, float).reshape(n, model.n_bodies, 3)[..., :2]
    f = Db[..., :2].sum(axis=1)
    m = (Db[..., 2] + _cross(r, Db[..., :2])).sum(axis=1)
    return -np.concatenate([f, m[:, None]], axis=-1)


# ================================================================ the result
_ROW_LABELS = {"revolute": ("x", "y"), "prismatic": ("normal", "angle"),
               "lock": ("x", "y", "angle")}


@dataclass(frozen=True, repr=False)
class Kinetostatics:
    """Result of a kinetostatic (inverse-dynamics) analysis over ``n`` positions.

    Attributes
    ----------
    over : str
        The coordinate that labels the positions (the crank angle, usually).
    t : ndarray, shape (n,)
        Time, s (zeros for a static analysis).
    values : ndarray, shape (n,)
        Values of ``over`` (rad or m).
    q, qdot, qddot : ndarray, shape (n, n_q)
        All generalized coordinates and their rates, measured on the poses.
    x, xdot, xddot : ndarray, shape (n, n_x)
        Body-frame poses, velocities and accelerations.
    driven : tuple of str
        Coordinates whose motion is prescribed (each has a driving torque/force).
    reactions : dict str -> ndarray, shape (n, 2)
        Per joint, the force ON THE CHILD FROM THE PARENT at the joint point, in
        the ground frame, N.
    moments : dict str -> ndarray, shape (n,)
        Per joint, the moment on the child about the joint point, N m (zero for
        revolutes).
    joint_frame : dict str -> ndarray, shape (n, 2)
        The reaction in the joint frame: prismatic (tangential along the axis,
        normal = axis turned +90 deg); revolute and lock: components along the
        parent body's x and y axes.
    joint_points : dict str -> ndarray, shape (n, 2)
        Where each reaction acts (ground frame), m.
    driving : dict str -> ndarray, shape (n,)
        Torque (N m) or force (N) the drive must apply to each driven coordinate.
    power : dict str -> ndarray, shape (n,)
        Driving power ``driving * qdot`` per driven coordinate, W.
    frame_force : ndarray, shape (n, 2)
        Sum of all forces the frame receives (shaking force), N.
    frame_moment : ndarray, shape (n,)
        Sum of the moments the frame receives about ``frame_point`` (shaking
        moment), N m.
    frame_point : ndarray, shape (2,)
        The point of the frame moments, m.
    frame_loads : dict str -> ndarray, shape (n, 3)
        Per contributor (every joint to the ground by name, ``"drives"`` for
        the stator reactions, ``"loads"`` for spring/torque ends): force x, y
        (N) and moment about ``frame_point`` (N m) that the frame receives.
    multipliers : ndarray, shape (n, n_rows)
        Lagrange multipliers of the joint equations (layout row order).
    joint_kinds : dict str -> str
        "revolute", "prismatic" or "lock" for each reported joint.
    mode : frozenset of str
        Engaged locks.
    redundant_joints : tuple of str
        Joints whose equations are linearly dependent (their reactions are not
        unique; the minimum-norm solution is reported).
    status : str
        "ok", "redundant" (non-unique reactions) or "singular" (positions where
        the driven coordinates lose control of the mechanism).
    message : str
    warnings : tuple of str
    stats : dict
        Run figures: positions, seconds, Newton iterations, power-balance
        residual (relative), smallest rcond, ...
    """

    over: str
    t: np.ndarray
    values: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    coordinate_names: tuple
    driven: tuple
    reactions: dict
    moments: dict
    joint_frame: dict
    joint_points: dict
    driving: dict
    power: dict
    frame_force: np.ndarray
    frame_moment: np.ndarray
    frame_point: np.ndarray
    frame_loads: dict
    multipliers: np.ndarray
    joint_kinds: dict
    mode: frozenset
    redundant_joints: tuple
    status: str
    message: str
    warnings: tuple
    stats: dict
    model: Model | None = field(default=None, compare=False)

    def __repr__(self) -> str:
        return (f"Kinetostatics(status={self.status!r}, {len(self.t)} positions over "
                f"{self.over!r}, driven={list(self.driven)}, joints={list(self.reactions)})")

    # ------------------------------------------------------------ helpers
    @property
    def n(self) -> int:
        """Number of positions."""
        return int(self.t.shape[0])

    @property
    def over_is_angle(self) -> bool:
        """True when ``over`` is an angle coordinate."""
        k = self.coordinate_names.index(self.over)
        return self._is_angle(k)

    def _is_angle(self, k: int) -> bool:
        if self.model is not None:
            return bool(self.model.coord_is_angle[k])
        return True

    def _label(self, name: str) -> tuple[str, float]:
        """Column of a coordinate value and the factor from SI."""
        k = self.coordinate_names.index(name)
        return (f"{name}_deg", np.rad2deg(1.0)) if self._is_angle(k) else (f"{name}_m", 1.0)

    def _drive_unit(self, name: str) -> tuple[str, str]:
        k = self.coordinate_names.index(name)
        return ("M", "Nm") if self._is_angle(k) else ("F", "N")

    def force_magnitude(self, joint: str) -> np.ndarray:
        """Resultant |R| of a joint reaction, N, shape (n,)."""
        R = self._reaction(joint)
        return np.hypot(R[:, 0], R[:, 1])

    def force_angle(self, joint: str) -> np.ndarray:
        """Direction angle of a joint reaction in the ground frame, rad (-pi, pi], shape (n,)."""
        R = self._reaction(joint)
        return np.arctan2(R[:, 1], R[:, 0])

    def _reaction(self, joint: str) -> np.ndarray:
        try:
            return self.reactions[joint]
        except KeyError:
            raise ModelError(did_you_mean(joint, self.reactions, "joint")) from None

    @property
    def driving_total_power(self) -> np.ndarray:
        """Sum of the driving powers, W, shape (n,)."""
        out = np.zeros(self.n)
        for p in self.power.values():
            out = out + p
        return out

    # ------------------------------------------------------------ tables
    def to_dataframe(self):
        """One row per position, unit-suffixed columns.

        Columns: ``t_s``; per coordinate ``<c>_deg`` (or ``<c>_m``),
        ``<c>_dot_rad_s``, ``<c>_ddot_rad_s2`` (or m/s, m/s^2); per driven
        coordinate ``M_drive_<c>_Nm`` (``F_drive_<c>_N`` for a travel) and
        ``P_drive_<c>_W``; per joint ``Fx_<J>_N``, ``Fy_<J>_N``, ``F_<J>_N``,
        ``angle_F_<J>_deg``, for prismatic joints ``Ft_<J>_N``, ``Fn_<J>_N`` and
        ``M_<J>_Nm``, for locks ``M_<J>_Nm``; per joint to the ground
        ``Fx_frame_<J>_N``, ``Fy_frame_<J>_N``, ``M_frame_<J>_Nm``; and the
        totals ``Fx_frame_N``, ``Fy_frame_N``, ``F_frame_N``, ``M_frame_Nm``.
        """
        import pandas as pd

        cols: dict[str, np.ndarray] = {"t_s": self.t}
        for k, c in enumerate(self.coordinate_names):
            if self._is_angle(k):
                cols[f"{c}_deg"] = np.rad2deg(self.q[:, k])
                cols[f"{c}_dot_rad_s"] = self.qdot[:, k]
                cols[f"{c}_ddot_rad_s2"] = self.qddot[:, k]
            else:
                cols[f"{c}_m"] = self.q[:, k]
                cols[f"{c}_dot_m_s"] = self.qdot[:, k]
                cols[f"{c}_ddot_m_s2"] = self.qddot[:, k]
        for c in self.driven:
            sym, unit = self._drive_unit(c)
            cols[f"{sym}_drive_{c}_{unit}"] = self.driving[c]
            cols[f"P_drive_{c}_W"] = self.power[c]
        for j, R in self.reactions.items():
            cols[f"Fx_{j}_N"] = R[:, 0]
            cols[f"Fy_{j}_N"] = R[:, 1]
            cols[f"F_{j}_N"] = np.hypot(R[:, 0], R[:, 1])
            cols[f"angle_F_{j}_deg"] = np.rad2deg(np.arctan2(R[:, 1], R[:, 0]))
            kind = self.joint_kinds[j]
            if kind == "prismatic":
                cols[f"Ft_{j}_N"] = self.joint_frame[j][:, 0]
                cols[f"Fn_{j}_N"] = self.joint_frame[j][:, 1]
            if kind in ("prismatic", "lock"):
                cols[f"M_{j}_Nm"] = self.moments[j]
        for j, L in self.frame_loads.items():
            if j in self.reactions:
                cols[f"Fx_frame_{j}_N"] = L[:, 0]
                cols[f"Fy_frame_{j}_N"] = L[:, 1]
                cols[f"M_frame_{j}_Nm"] = L[:, 2]
        cols["Fx_frame_N"] = self.frame_force[:, 0]
        cols["Fy_frame_N"] = self.frame_force[:, 1]
        cols["F_frame_N"] = np.hypot(self.frame_force[:, 0], self.frame_force[:, 1])
        cols["M_frame_Nm"] = self.frame_moment
        return pd.DataFrame(cols)

    # ------------------------------------------------------------ summaries
    def _where(self, k: int) -> str:
        lab, f = self._label(self.over)
        unit = "deg" if lab.endswith("_deg") else "m"
        return f"{self.over} = {self.values[k] * f:.4g} {unit}"

    def rms(self, series) -> float:
        """RMS of a series over the positions, weighted by time when time advances
        (trapezoidal rule), else by position count."""
        y = np.asarray(series, dtype=float)
        t = self.t
        if y.size < 2:
            return float(np.sqrt(np.mean(y**2)))
        if np.all(np.diff(t) > 0):
            return float(np.sqrt(np.trapezoid(y**2, t) / (t[-1] - t[0])))
        v = self.values
        if np.all(np.diff(v) > 0) or np.all(np.diff(v) < 0):
            return float(np.sqrt(np.trapezoid(y**2, v) / (v[-1] - v[0])))
        return float(np.sqrt(np.mean(y**2)))

    def peaks(self) -> dict:
        """The figures of :meth:`summary` as a dict (SI units; positions in ``over``'s unit)."""
        out: dict = {"driving": {}, "joints": {}, "frame": {}}
        for c in self.driven:
            m = self.driving[c]
            ka, kmx, kmn = int(np.argmax(np.abs(m))), int(np.argmax(m)), int(np.argmin(m))
            out["driving"][c] = {
                "peak_abs": float(m[ka]), "peak_abs_at": float(self.values[ka]),
                "max": float(m[kmx]), "max_at": float(self.values[kmx]),
                "min": float(m[kmn]), "min_at": float(self.values[kmn]),
                "rms": self.rms(m), "mean": float(np.mean(m)),
                "peak_power": float(np.max(np.abs(self.power[c]))),
            }
        for j in self.reactions:
            F = self.force_magnitude(j)
            k = int(np.argmax(F))
            out["joints"][j] = {"peak": float(F[k]), "peak_at": float(self.values[k]),
                                "rms": self.rms(F)}
            if self.joint_kinds[j] != "revolute":
                M = self.moments[j]
                km = int(np.argmax(np.abs(M)))
                out["joints"][j].update(peak_moment=float(M[km]),
                                        peak_moment_at=float(self.values[km]))
        Ff = np.hypot(self.frame_force[:, 0], self.frame_force[:, 1])
        k, km = int(np.argmax(Ff)), int(np.argmax(np.abs(self.frame_moment)))
        out["frame"] = {
            "force_peak": float(Ff[k]), "force_peak_at": float(self.values[k]),
            "Fx_min": float(self.frame_force[:, 0].min()),
            "Fx_max": float(self.frame_force[:, 0].max()),
            "Fy_min": float(self.frame_force[:, 1].min()),
            "Fy_max": float(self.frame_force[:, 1].max()),
            "moment_peak": float(self.frame_moment[km]),
            "moment_peak_at": float(self.values[km]),
            "M_min": float(self.frame_moment.min()), "M_max": float(self.frame_moment.max()),
        }
        return out

    def summary(self) -> str:
        """Peak and RMS driving torque (motor sizing), peak force per joint and where,
        shaking force and moment extremes; warnings last."""
        p = self.peaks()
        lab, f = self._label(self.over)
        unit = "deg" if lab.endswith("_deg") else "m"
        lines = [f"kinetostatics over {self.over}: {self.n} positions, "
                 f"{self.over} from {self.values[0] * f:.4g} to {self.values[-1] * f:.4g} "
                 f"{unit}; status {self.status}"]
        for c, d in p["driving"].items():
            sym, u = self._drive_unit(c)
            u = "N m" if u == "Nm" else u
            lines.append(
                f"  drive {c}: peak {d['peak_abs']:.6g} {u} at {self.over} = "
                f"{d['peak_abs_at'] * f:.4g} {unit}; max {d['max']:.6g} {u} at "
                f"{d['max_at'] * f:.4g} {unit}; min {d['min']:.6g} {u} at "
                f"{d['min_at'] * f:.4g} {unit}; RMS {d['rms']:.6g} {u}; mean "
                f"{d['mean']:.6g} {u}; peak power {d['peak_power']:.6g} W")
        for j, d in p["joints"].items():
            s = (f"  joint {j} ({self.joint_kinds[j]}): peak force {d['peak']:.6g} N at "
                 f"{self.over} = {d['peak_at'] * f:.4g} {unit}")
            if "peak_moment" in d:
                s += (f"; peak moment {d['peak_moment']:.6g} N m at "
                      f"{d['peak_moment_at'] * f:.4g} {unit}")
            lines.append(s)
        fr = p["frame"]
        lines.append(
            f"  frame: shaking force peak {fr['force_peak']:.6g} N at {self.over} = "
            f"{fr['force_peak_at'] * f:.4g} {unit} (Fx {fr['Fx_min']:.6g}..{fr['Fx_max']:.6g} N,"
            f" Fy {fr['Fy_min']:.6g}..{fr['Fy_max']:.6g} N); shaking moment about "
            f"({self.frame_point[0]:.4g}, {self.frame_point[1]:.4g}) m: "
            f"{fr['M_min']:.6g}..{fr['M_max']:.6g} N m")
        for w in self.warnings:
            lines.append(f"  warning: {w}")
        return "\n".join(lines)

    def harmonics(self, n_orders: int | None = None):
        """Harmonics of the shaking force and moment per order of the ``over`` cycle.

        The positions must sample one full turn of an angle coordinate
        uniformly (an end point equal to the start point modulo 2 pi is
        dropped); at constant speed this is the Fourier series in time, order k
        at ``k`` times the crank frequency.

        Parameters
        ----------
        n_orders : int, optional
            Highest order returned (default: all, up to the Nyquist order).

        Returns
        -------
        pandas.DataFrame
            Columns ``order``, ``f_Hz`` (k times the mean crank frequency; NaN
            for a static analysis), and amplitude and phase of ``Fx_frame_N``,
            ``Fy_frame_N``, ``M_frame_Nm`` (columns ``<name>`` for the
            amplitude, ``<name>_phase_deg``) in the cosine series
            ``y = sum_k A_k cos(k |phi - phi_0| + phase_k)`` (angle travelled
            from the first position); order 0 is the (signed) mean.

        Raises
        ------
        ValueError
            If the samples are not one uniformly sampled turn.
        """
        import pandas as pd

        v = np.asarray(self.values, dtype=float)
        if not self.over_is_angle:
            raise ValueError(f"harmonics need an angle coordinate; {self.over!r} is a travel")
        n = v.size
        if n >= 2 and np.isclose(abs(v[-1] - v[0]), 2 * np.pi, rtol=1e-9, atol=1e-12):
            n -= 1  # the end point repeats the start point
        step = 2 * np.pi / n if n else np.nan
        if n < 4 or not np.allclose(np.abs(np.diff(v)), step, rtol=1e-6, atol=1e-12):
            raise ValueError(
                f"harmonics need one full turn of {self.over!r} sampled uniformly "
                f"(e.g. values = linspace(0, 2 pi, 361)); got {v.size} positions from "
                f"{np.rad2deg(v[0]):.6g} to {np.rad2deg(v[-1]):.6g} deg")
        series = {"Fx_frame_N": self.frame_force[:n, 0], "Fy_frame_N": self.frame_force[:n, 1],
                  "M_frame_Nm": self.frame_moment[:n]}
        kmax = n // 2 if n_orders is None else min(int(n_orders), n // 2)
        orders = np.arange(kmax + 1)
        tt = self.t
        period = (tt[n] - tt[0]) if n < tt.size else (tt[n - 1] - tt[0]) * n / (n - 1)
        freq = orders / period if period > 0 else orders * np.nan
        cols: dict = {"order": orders, "f_Hz": freq}
        for name, y in series.items():
            Y = np.fft.rfft(y)[: kmax + 1] / n
            amp = 2 * np.abs(Y)
            ph = np.angle(Y)
            amp[0], ph[0] = Y[0].real, 0.0
            if n % 2 == 0 and kmax == n // 2:
                amp[-1] = np.abs(Y[-1])
            cols[name] = amp
            cols[f"{name}_phase_deg"] = np.rad2deg(ph)
        return pd.DataFrame(cols)


# ================================================================ positions
def _kin_system(model, lay, didx, x, qd):
    Phi = residual(model, x, lay)
    g = coordinates(model, x)[..., didx]
    F = np.concatenate([Phi, g - qd], axis=-1)
    J = np.concatenate([jacobian(model, x, lay), coordinates_jacobian(model, x)[..., didx, :]],
                       axis=-2)
    return F, J


def _lin_solve(J, F):
    """Solve J dx = F (batched), least squares / minimum norm when not square or singular."""
    if J.shape[-1] == J.shape[-2]:
        try:
            dx = np.linalg.solve(J, F[..., None])[..., 0]
            if np.all(np.isfinite(dx)):
                return dx
        except np.linalg.LinAlgError:
            pass
    return (np.linalg.pinv(J, rcond=1e-12) @ F[..., None])[..., 0]


class _Positions:
    """Position, velocity and acceleration analysis with a subset of driven coordinates."""

    def __init__(self, model: Model, lay: ConstraintLayout, didx: np.ndarray):
        self.model, self.lay, self.didx = model, lay, didx
        self.tol = 1e-12 * max(model.length_scale, 1e-3)
        self.scale = _col_scale(model)
        self.iterations = 0
        self.branch_changes: list = []

    def jac(self, x):
        """[Phi_x; g_d,x] at x, shape (..., n_rows + n_d, n_x)."""
        return _kin_system(self.model, self.lay, self.didx, x,
                           np.zeros(np.shape(x)[:-1] + (len(self.didx),)))[1]

    def newton(self, qd, x, max_iter=30):
        """Newton iterations (batched); returns x, converged flags, and J at x."""
        x = np.array(x, dtype=float, copy=True)
        for _ in range(max_iter):
            F, J = _kin_system(self.model, self.lay, self.didx, x, qd)
            err = np.max(np.abs(F), axis=-1) if F.shape[-1] else np.zeros(F.shape[:-1])
            done = err <= self.tol
            if np.all(done):
                return x, done, J
            self.iterations += 1
            dx = _lin_solve(J, F)
            if not np.all(np.isfinite(dx)):
                break
            x = x - np.where(done[..., None], 0.0, dx)
        F, J = _kin_system(self.model, self.lay, self.didx, x, qd)
        err = np.max(np.abs(F), axis=-1)
        return x, err <= 1e3 * self.tol, J

    def analogs(self, J):
        """dx/dq_d from the Jacobian J, shape (..., n_x, n_d)."""
        rhs = np.zeros(J.shape[:-2] + (J.shape[-2], len(self.didx)))
        rhs[..., self.lay.n_rows:, :] = np.eye(len(self.didx))
        if J.shape[-1] == J.shape[-2]:
            try:
                return np.linalg.solve(J, rhs)
            except np.linalg.LinAlgError:
                pass
        return np.linalg.pinv(J, rcond=1e-12) @ rhs

    def det_sign(self, J):
        """Sign of det of the scaled J (ones when J is not square)."""
        if J.shape[-1] != J.shape[-2]:
            return np.ones(J.shape[:-2])
        return np.sign(np.linalg.det(J * self.scale))

    def first(self, qd, x_start):
        """The first pose: continuation from the assembled start pose keeps its branch."""
        q_s = coordinates(self.model, x_start)[self.didx]
        F, _ = _kin_system(self.model, self.lay, self.didx, x_start, q_s)
        if np.max(np.abs(F), initial=0.0) <= 1e3 * self.tol:
            try:
                return self.step(q_s, x_start, qd)[0]
            except (AssemblyError, SingularPositionError):
                pass
        x, ok, _ = self.newton(qd, x_start, max_iter=60)
        if ok:
            return x
        from scipy.optimize import least_squares

        def fun(xx):
            return _kin_system(self.model, self.lay, self.didx, xx, qd)[0]

        def jac(xx):
            return _kin_system(self.model, self.lay, self.didx, xx, qd)[1]

        sol = least_squares(fun, x_start, jac=jac, method="trf", xtol=1e-15, ftol=1e-15,
                            gtol=1e-15, x_scale=self.scale / self.model.length_scale,
                            max_nfev=2000)
        x, ok, _ = self.newton(qd, sol.x)
        if not ok:
            raise self._error(qd, x)
        return x

    def _error(self, qd, x, t=None):
        res = joint_residuals(self.model, x, self.lay)
        names = [self.model.coordinate_names[k] for k in self.didx]
        if max(res.values(), default=0.0) < 1e-6 * self.model.length_scale:
            return SingularPositionError(
                "the position solve stalls near a dead, toggle or change point: the driven "
                "coordinate(s) " + ", ".join(names) + " lose control of the mechanism there "
                "(largest joint residual " + f"{max(res.values()):.3g}); analyse up to that "
                "position or choose another driven coordinate", t=t, q=qd,
                coordinates=names, joints=list(res))
        open_ = {n: v for n, v in res.items() if v > 1e-9 * max(self.model.length_scale, 1e-3)}
        qs = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, np.atleast_1d(qd), strict=True))
        parts = ", ".join(f"{n!r}: {v:.3g}" for n, v in open_.items()) or "none"
        return AssemblyError(f"the mechanism cannot be assembled at {qs}; joints that stay "
                             f"open (residual, m or rad): {parts}", t=t, q=qd,
                             residuals=open_)

    def step(self, qd_from, x_from, qd_to, J_from=None, depth=0):
        """Solve at qd_to continuing from a solved pose, halving the step on failure.

        Returns the pose and the Jacobian there."""
        L = self.model.length_scale
        if J_from is None:
            J_from = self.jac(x_from)
        dx = self.analogs(J_from) @ (qd_to - qd_from)
        # near a singular position the analogs blow up: then start from x_from itself
        pred = x_from + dx if np.max(np.abs(dx * self.scale)) <= 0.5 * L else x_from
        x, ok, J = self.newton(qd_to, pred)
        if ok:
            # a link turning by more than ~1 rad in one step means the solve jumped
            jump = np.max(np.abs((x - x_from) * self.scale)) > L
            same = self.det_sign(J) == self.det_sign(J_from)
            if (same and not jump) or depth > 10:
                if not same or jump:
                    self.branch_changes.append(np.array(qd_to, dtype=float))
                return x, J
        if depth > 14:
            raise self._error(qd_to, x)
        mid = 0.5 * (qd_from + qd_to)
        xm, Jm = self.step(qd_from, x_from, mid, J_from, depth + 1)
        return self.step(mid, xm, qd_to, Jm, depth + 1)

    def solve(self, qd, x_start, x_guess=None):
        """Poses for all rows of qd (n, n_d), by continuation from x_start.

        Sequential continuation on about 100 anchor positions, then one batched
        Newton solve for all the others from the anchors' first-order predictions
        (with a branch check, falling back to continuation where it fails)."""
        n = qd.shape[0]
        if x_guess is not None:
            x, ok, _ = self.newton(qd, x_guess)
            if np.all(ok):
                return x
        x = np.empty((n, self.model.n_x))
        x[0] = self.first(qd[0], x_start if x_guess is None else x_guess[0])
        if n == 1:
            return x
        stride = max(1, n // 100)
        anchors = list(range(0, n, stride))
        if anchors[-1] != n - 1:
            anchors.append(n - 1)
        Ja = np.empty((len(anchors),) + self.jac(x[0]).shape)
        Ja[0] = self.jac(x[0])
        for i, (a0, a1) in enumerate(zip(anchors[:-1], anchors[1:], strict=True)):
            x[a1], Ja[i + 1] = self.step(qd[a0], x[a0], qd[a1], Ja[i])
        rest = np.setdiff1d(np.arange(n), anchors)
        if rest.size:
            base = np.searchsorted(anchors, rest, side="right") - 1
            a = np.asarray(anchors)[base]
            B = self.analogs(Ja[base])
            pred = x[a] + (B @ (qd[rest] - qd[a])[..., None])[..., 0]
            xr, ok, Jr = self.newton(qd[rest], pred)
            ok &= self.det_sign(Jr) == self.det_sign(Ja[base])
            x[rest] = xr
            for k in rest[~ok]:
                x[k] = self.step(qd[k - 1], x[k - 1], qd[k])[0]
        return x

    def motion(self, x, qd_dot, qd_ddot):
        """Velocities and accelerations of the poses for driven rates (batched)."""
        m, lay = self.model, self.lay
        _, J = _kin_system(m, lay, self.didx, x, np.zeros(x.shape[:-1] + (len(self.didx),)))
        rhs = np.zeros(x.shape[:-1] + (J.shape[-2],))
        rhs[..., lay.n_rows:] = qd_dot
        xdot = _lin_solve(J, rhs)
        gam = np.concatenate([gamma(m, x, xdot, lay),
                              coordinates_gamma(m, x, xdot)[..., self.didx] + qd_ddot], axis=-1)
        xddot = _lin_solve(J, gam)
        return xdot, xddot


# ================================================================ motion specs
def _derivs(law: Callable, t: np.ndarray, n_d: int):
    """Values and two derivatives of a law of time (5-point central differences)."""
    def ev(tt):
        try:
            out = np.asarray(law(tt), dtype=float)
            if out.shape[:1] != tt.shape:
                raise ValueError
        except (ValueError, TypeError):
            out = np.array([np.asarray(law(float(s)), dtype=float) for s in tt])
        return out.reshape(tt.size, n_d)

    first = law(float(t[0])) if t.size else None
    if isinstance(first, tuple) and len(first) == 3:
        parts = [np.array([np.asarray(law(float(s))[i], dtype=float).reshape(n_d) for s in t])
                 for i in range(3)]
        return parts[0], parts[1], parts[2]
    span = float(np.ptp(t)) if t.size > 1 else 1.0
    h = 1e-3 * (span if span > 0 else 1.0)
    y0 = ev(t)
    yp1, ym1, yp2, ym2 = ev(t + h), ev(t - h), ev(t + 2 * h), ev(t - 2 * h)
    yd = (8 * (yp1 - ym1) - (yp2 - ym2)) / (12 * h)
    ydd = (16 * (yp1 + ym1) - (yp2 + ym2) - 30 * y0) / (12 * h * h)
    return y0, yd, ydd


def _integrate_speed(omega: Callable, t: np.ndarray, start: np.ndarray, n_d: int):
    """q(t) = start + integral of omega, by 5-point Gauss-Legendre per interval."""
    def ev(tt):
        tt = np.asarray(tt, dtype=float)
        try:
            out = np.asarray(omega(tt), dtype=float)
            if out.shape[:1] != tt.shape:
                raise ValueError
        except (ValueError, TypeError):
            out = np.array([np.asarray(omega(float(s)), dtype=float) for s in tt.ravel()])
        return out.reshape(tt.size, n_d)

    xg, wg = np.polynomial.legendre.leggauss(5)
    q = np.empty((t.size, n_d))
    q[0] = start
    if t.size > 1:
        a, b = t[:-1], t[1:]
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        nodes = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
        w = ev(nodes).reshape(a.size, xg.size, n_d)
        inc = np.einsum("k,nkd->nd", wg, w) * half[:, None]
        q[1:] = start + np.cumsum(inc, axis=0)
    _, wd, wdd = _derivs(lambda s: ev(np.atleast_1d(s)), t, n_d)
    return q, ev(t), wd


# ================================================================ the analysis
def _independent_subset(model, lay, x0, first: list[int]) -> list[int]:
    """Extend ``first`` with coordinates that add rank, up to the DOF of the layout."""
    sc = _col_scale(model)
    P = jacobian(model, x0, lay) * sc
    G = coordinates_jacobian(model, x0) * sc

    def rank(A):
        if A.size == 0:
            return 0
        s = np.linalg.svd(A, compute_uv=False)
        return int(np.sum(s > REDUNDANT_RCOND * s[0])) if s[0] > 0 else 0

    r_phi = rank(P)
    dof = model.n_x - r_phi
    chosen: list[int] = []
    for k in first:
        if rank(np.concatenate([P, G[chosen + [k]]])) == r_phi + len(chosen) + 1:
            chosen.append(k)
        else:
            raise ModelError(
                f"coordinate {model.coordinate_names[k]!r} cannot be driven in mode "
                f"{sorted(lay.mode)}: it is fixed by the other driven coordinates and the "
                f"constraints ({dof} degree(s) of freedom)")
    for k in range(model.n_q):
        if len(chosen) >= dof:
            break
        if k in chosen:
            continue
        if rank(np.concatenate([P, G[chosen + [k]]])) == r_phi + len(chosen) + 1:
            chosen.append(k)
    if len(chosen) < dof:
        raise ModelError(f"the mechanism has {dof} degrees of freedom in mode "
                         f"{sorted(lay.mode)}, but only {len(chosen)} coordinates can be driven")
    return chosen


def _redundancy(model, lay, x) -> tuple[int, list[str], list[str]]:
    """Number of dependent joint equations, the joints involved and row labels."""
    if lay.n_rows == 0:
        return 0, [], []
    sc = _col_scale(model)
    x = np.asarray(x, dtype=float).reshape(-1, model.n_x)
    if x.shape[0] > 64:  # redundancy is structural: a sample of the positions suffices
        x = x[np.unique(np.linspace(0, x.shape[0] - 1, 64).astype(int))]
    P = jacobian(model, x, lay) * sc
    s = np.linalg.svd(P, compute_uv=False)
    r = np.sum(s > REDUNDANT_RCOND * s[..., :1], axis=-1)
    if s.shape[-1] < lay.n_rows:  # more equations than unknowns
        r = np.minimum(r, s.shape[-1])
    n_red = int(lay.n_rows - r.min())
    if n_red == 0:
        return 0, [], []
    k = int(np.argmin(r))
    u = np.linalg.svd(P[k])[0]
    null = u[:, int(r[k]):]
    weight = np.sum(null**2, axis=1)
    rows = [i for i in range(lay.n_rows) if weight[i] > 1e-6]
    joints = sorted({str(lay.row_joint[i]) for i in rows})
    labels = []
    for i in rows:
        j = str(lay.row_joint[i])
        pos = int(np.flatnonzero(lay.rows[j] == i)[0])
        labels.append(f"{j} ({_ROW_LABELS[model.joint_kind(j)][pos]})")
    return n_red, joints, labels


def _joint_geometry(model: Model, lay: ConstraintLayout):
    """Per active joint: kind, parent index, child index, child-frame point, parent axis."""
    out = {}
    for k, nme in enumerate(model.rev.names):
        out[nme] = ("revolute", int(model.rev.i[k]), int(model.rev.j[k]), model.rev.sj[k], None)
    for k, nme in enumerate(model.pri.names):
        out[nme] = ("prismatic", int(model.pri.i[k]), int(model.pri.j[k]), model.pri.sj[k],
                    model.pri.ui[k])
    for k, nme in enumerate(model.lock.names):
        if lay.lock_active[k]:
            out[nme] = ("lock", int(model.lock.i[k]), int(model.lock.j[k]), np.zeros(2), None)
    return {n: out[n] for n in model.joint_names if n in out}


def _to_array(v, n_d: int, what: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.ndim == 0:
        a = np.full(n_d, float(a))
    if a.shape != (n_d,):
        raise ValueError(f"{what}: expected {n_d} value(s), got shape {a.shape}")
    return a


def kinetostatics(mech_or_model, *, over: str | Sequence[str] | None = None,
                  speed=None, values=None, t=None, law: Callable | None = None,
                  start=None, trajectory=None, hold: Mapping[str, float] | None = None,
                  mode=None, point=(0.0, 0.0), model_drives: str = "replace",
                  reacting_loads: Sequence[str] = (), x_guess=None) -> Kinetostatics:
    """Driving torques, joint reactions and frame loads for a prescribed motion.

    Give the motion in one of three ways:

    * ``speed`` (constant, rad/s or m/s; 0 for statics) and ``values`` of the
      coordinate(s) ``over`` (default one full turn, ``linspace(0, 2 pi, 361)``);
      time is ``(values - values[0]) / speed``.
    * ``t`` with ``law`` (a callable q(t) giving the driven value(s), or a
      tuple (q, qdot, qddot) for exact derivatives; derivatives are otherwise
      taken by 5-point central differences), or ``t`` with a callable ``speed``
      omega(t), integrated from ``start`` (default the sketch value).
    * ``trajectory``: an object with ``t``, ``q``, ``qdot``, ``qddot`` (and
      optionally ``x``), e.g. a :class:`~mechdyn.results.trajectory.Trajectory`
      from forward dynamics; all independent coordinates are driven.

    When the mechanism has more degrees of freedom (in ``mode``) than driven
    coordinates, the remaining coordinates are HELD at ``hold[name]`` (default
    their value in the assembled sketch); they are driven coordinates with zero
    speed and get a holding torque.  Coordinates that are fixed by the others
    in ``mode`` (e.g. the rocker angle when the rocker is locked to the slider)
    follow from the constraints.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    over : str or sequence of str, optional
        Driven coordinate(s); default the first independent coordinate.
    speed : float, array_like or callable, optional
    values : array_like, shape (n,) or (n, k), optional
        Positions of the ``over`` coordinates, rad or m.
    t : array_like, shape (n,), optional
        Times for ``law`` or a callable ``speed``, s.
    law : callable, optional
    start : float or array_like, optional
        Start value for a callable ``speed``.
    trajectory : object, optional
    hold : mapping, optional
        Values (rad or m) at which non-driven independent coordinates are held.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    point : (float, float)
        Point of the frame moments (shaking moment), ground frame, m.
    model_drives : {"replace", "load"}
        What to do with ``Drive`` elements on driven coordinates (see module
        docstring).
    reacting_loads : sequence of str
        ``Force`` loads whose reaction the frame carries (e.g. the punch force
        of a press whose bed is part of the frame).
    x_guess : array_like, shape (n_x,) or (n, n_x), optional
        Start pose(s) of the position solve (default the assembled sketch).

    Returns
    -------
    Kinetostatics

    Raises
    ------
    ModelError
        Unknown coordinate or load names, or a motion that does not fit the
        mechanism's degrees of freedom.
    AssemblyError
        A position cannot be assembled.

    Examples
    --------
    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("crank", gravity=(0.0, -9.81))
    >>> _ = m.add_body("crank", mass=1.0, com=(0.1, 0.0))
    >>> _ = m.add_revolute("O", "ground", "crank")
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> res = kinetostatics(m, over="phi", speed=0.0, values=[0.0])
    >>> round(float(res.driving["phi"][0]), 4)   # holds the weight: 1 kg x 9.81 x 0.1 m
    0.981
    """
    t_start = time.perf_counter()
    model = as_model(mech_or_model)
    fm = force_model(model)
    if model_drives not in ("replace", "load"):
        raise ValueError(f"model_drives must be 'replace' or 'load', got {model_drives!r}")
    if mode is None and trajectory is not None and isinstance(
            getattr(trajectory, "mode", None), frozenset):
        mode = trajectory.mode
    lay = model.layout(mode)
    load_names = {getattr(ld, "name", None) for ld in model.mechanism.loads}
    for nm in reacting_loads:
        if nm not in load_names:
            raise ModelError(did_you_mean(nm, [n for n in load_names if n], "load"))
    warn: list[str] = []
    for ld in model.mechanism.loads:
        if hasattr(ld, "generalized"):
            warn.append(f"load {getattr(ld, 'name', '?')!r} ({type(ld).__name__}) is an "
                        f"extension load that kinetostatics does not evaluate; it is left out")
    x_start = getattr(model, "x0", None)
    if x_start is None:
        x_start = model.x_sketch
    if x_guess is not None:
        xg = np.asarray(x_guess, dtype=float)
        if xg.ndim == 1:
            x_start, x_guess = xg, None
        else:
            x_guess = xg

    # ---------------------------------------------------------- the motion
    if over is None:
        over_names: list[str] = []
    elif isinstance(over, str):
        over_names = [over]
    else:
        over_names = list(over)
    over_idx = [model.coordinate_index(c) for c in over_names]

    if trajectory is not None:
        if any(v is not None for v in (speed, values, t, law)):
            raise ValueError("give either trajectory= or speed/values/t/law, not both")
        tt = np.asarray(trajectory.t, dtype=float).reshape(-1)
        Q = np.asarray(trajectory.q, dtype=float).reshape(tt.size, model.n_q)
        Qd = np.asarray(trajectory.qdot, dtype=float).reshape(tt.size, model.n_q)
        Qdd = np.asarray(trajectory.qddot, dtype=float).reshape(tt.size, model.n_q)
        didx = _independent_subset(model, lay, x_start, over_idx)
        qd, qd_dot, qd_ddot = Q[:, didx], Qd[:, didx], Qdd[:, didx]
        tx = getattr(trajectory, "x", None)
        if x_guess is None and tx is not None and np.shape(tx) == (tt.size, model.n_x):
            x_guess = np.asarray(tx, dtype=float)
        if not over_names:
            over_names = [model.coordinate_names[didx[0]]]
    else:
        if not over_idx:
            over_idx = _independent_subset(model, lay, x_start, [])[:1]
            over_names = [model.coordinate_names[over_idx[0]]]
        n_o = len(over_idx)
        if law is not None:
            if t is None:
                raise ValueError("law= needs the times t=")
            if speed is not None or values is not None:
                raise ValueError("give law= or speed=/values=, not both")
            tt = np.asarray(t, dtype=float).reshape(-1)
            qo, qo_d, qo_dd = _derivs(law, tt, n_o)
        elif callable(speed):
            if t is None:
                raise ValueError("a speed law omega(t) needs the times t=")
            tt = np.asarray(t, dtype=float).reshape(-1)
            if start is None:
                start = coordinates(model, x_start)[over_idx]
            qo, qo_d, qo_dd = _integrate_speed(speed, tt, _to_array(start, n_o, "start"), n_o)
        else:
            if speed is None:
                raise ValueError("give the motion: speed= (a constant, 0 for statics, or a "
                                 "callable omega(t) with t=), law= with t=, or trajectory=")
            w = _to_array(speed, n_o, "speed")
            if values is None:
                if not all(model.coord_is_angle[k] for k in over_idx):
                    raise ValueError("values= is needed for a travel coordinate")
                sgn = np.where(w < 0, -1.0, 1.0)
                values = np.linspace(0.0, 2 * np.pi, 361)[:, None] * sgn
            qo = np.asarray(values, dtype=float).reshape(-1, n_o)
            qo_d = np.broadcast_to(w, qo.shape).copy()
            qo_dd = np.zeros_like(qo)
            k0 = int(np.argmax(np.abs(w)))
            tt = ((qo[:, k0] - qo[0, k0]) / w[k0]) if w[k0] != 0 else np.zeros(qo.shape[0])
            if t is not None:
                raise ValueError("t= is used with law= or a callable speed, not with a "
                                 "constant speed (time follows from values and speed)")
        didx = _independent_subset(model, lay, x_start, over_idx)
        n = tt.size
        extra = didx[n_o:]
        held = coordinates(model, x_start)[extra] if extra else np.zeros(0)
        hold = dict(hold or {})
        for nm in hold:
            model.coordinate_index(nm)
        for i, k in enumerate(extra):
            nm = model.coordinate_names[k]
            if nm in hold:
                held[i] = float(hold[nm])
        qd = np.concatenate([qo, np.broadcast_to(held, (n, len(extra)))], axis=1)
        qd_dot = np.concatenate([qo_d, np.zeros((n, len(extra)))], axis=1)
        qd_ddot = np.concatenate([qo_dd, np.zeros((n, len(extra)))], axis=1)
        if extra:
            warn.append("coordinate(s) " + ", ".join(
                f"{model.coordinate_names[k]!r} = {h:.6g}" for k, h in zip(extra, held,
                                                                           strict=True))
                + " are held fixed (not driven by the given motion); their driving entries "
                  "are holding torques/forces")
    didx = np.asarray(didx, dtype=int)
    n = tt.size
    if n == 0:
        raise ValueError("no positions to analyse")

    # ---------------------------------------------------------- kinematics
    pos = _Positions(model, lay, didx)
    x = pos.solve(qd, np.asarray(x_start, dtype=float), x_guess)
    xdot, xddot = pos.motion(x, qd_dot, qd_ddot)
    if pos.branch_changes:
        names = [model.coordinate_names[k] for k in didx]
        at = ", ".join(f"{nm} = {v:.6g}" for nm, v in zip(names, pos.branch_changes[0],
                                                          strict=True))
        warn.append(f"the assembly branch changes near {at} ({len(pos.branch_changes)} "
                    f"time(s)): the motion passes a singular (change or dead) position; "
                    f"results beyond it belong to another assembly mode")
    G = coordinates_jacobian(model, x)
    q = coordinates(model, x)
    qdot = np.einsum("nqx,nx->nq", G, xdot)
    qddot = np.einsum("nqx,nx->nq", G, xddot) - coordinates_gamma(model, x, xdot)
    # keep the prescribed values exactly (the poses satisfy them to round-off)
    q[:, didx], qdot[:, didx], qddot[:, didx] = qd, qd_dot, qd_ddot

    core = _inverse(model, lay, didx, tt, x, xdot, xddot, q, qdot,
                    skip=didx if model_drives == "replace" else (),
                    reacting=tuple(reacting_loads), point=np.asarray(point, dtype=float))
    warn.extend(core["warnings"])
    notes = []
    if model_drives == "replace":
        replaced = [dr.name for dr, k in fm.drives if k in set(didx.tolist())]
        if replaced:
            notes.append("drive(s) " + ", ".join(repr(r) for r in replaced)
                         + " on driven coordinates are replaced by the prescribed motion "
                           "(driving = the whole torque the drive must deliver)")
    over_values = q[:, model.coordinate_index(over_names[0])]
    stats = dict(core["stats"])
    stats.update(positions=n, newton_iterations=pos.iterations,
                 seconds=time.perf_counter() - t_start)
    status = core["status"]
    message = {"ok": "kinetostatic analysis completed",
               "redundant": "completed; reactions of redundant joints are not unique "
                            "(minimum-norm solution reported)",
               "singular": "completed with singular positions: the driven coordinates lose "
                           "control there and the reactions are unbounded"}[status]
    message = "; ".join([message, *notes])
    names = model.coordinate_names
    return Kinetostatics(
        over=over_names[0], t=tt, values=over_values, q=q, qdot=qdot, qddot=qddot, x=x,
        xdot=xdot, xddot=xddot, coordinate_names=tuple(names),
        driven=tuple(names[k] for k in didx), reactions=core["reactions"],
        moments=core["moments"], joint_frame=core["joint_frame"],
        joint_points=core["joint_points"],
        driving={names[k]: core["tau"][:, i] for i, k in enumerate(didx)},
        power={names[k]: core["tau"][:, i] * qdot[:, k] for i, k in enumerate(didx)},
        frame_force=core["frame_force"], frame_moment=core["frame_moment"],
        frame_point=np.asarray(point, dtype=float).copy(), frame_loads=core["frame_loads"],
        multipliers=core["lam"], joint_kinds=core["kinds"], mode=lay.mode,
        redundant_joints=tuple(core["redundant"]), status=status, message=message,
        warnings=tuple(warn), stats=stats, model=model)


def _inverse(model: Model, lay: ConstraintLayout, didx, t, x, xdot, xddot, q, qdot, *,
             skip, reacting, point) -> dict:
    """The batched inverse-dynamics solve and the reaction bookkeeping."""
    n = t.shape[0]
    nb = model.n_bodies
    L = model.length_scale
    n_d = len(didx)
    warn: list[str] = []
    F, F_ground, Qd_loads = applied_forces(model, t, x, xdot, q, qdot, skip_drives=skip,
                                           reacting_loads=reacting)
    Ix = inertia_forces(model, x, xdot, xddot)
    P = jacobian(model, x, lay)  # (n, rows, n_x)
    G = coordinates_jacobian(model, x)  # (n, n_q, n_x)
    Gd = G[:, didx, :]
    A = np.concatenate([-P, Gd], axis=1).transpose(0, 2, 1)  # (n, n_x, rows + n_d)
    rhs = Ix - F
    # balance units: moment equations / L; moment-like unknowns scaled by L
    rs = np.ones(model.n_x)
    rs[2::3] = 1.0 / L
    cs = np.ones(lay.n_rows + n_d)
    for j, rows in lay.rows.items():
        kind = model.joint_kind(j)
        if kind == "prismatic":
            cs[rows[1]] = L
        elif kind == "lock":
            cs[rows[2]] = L
    for i, k in enumerate(didx):
        if model.coord_kind[k] != COORD_TRAVEL:
            cs[lay.n_rows + i] = L
    As = A * rs[:, None] * cs[None, :]
    bs = rhs * rs
    n_red, red_joints, red_labels = _redundancy(model, lay, x)
    sv = np.linalg.svd(As, compute_uv=False)
    rank_need = lay.n_rows + n_d - n_red
    smax = sv[:, 0]
    s_need = sv[:, rank_need - 1] if rank_need > 0 else smax
    rcond = s_need / np.where(smax > 0, smax, 1.0)
    singular = rcond < SINGULAR_RCOND
    if n_red == 0 and As.shape[1] == As.shape[2] and not singular.any():
        z = np.linalg.solve(As, bs[..., None])[..., 0]
    else:
        z = (np.linalg.pinv(As, rcond=1e-10) @ bs[..., None])[..., 0]
    resid = np.einsum("nij,nj->ni", As, z) - bs
    scale_f = np.maximum(np.max(np.abs(bs), axis=-1), 1e-300)
    bad = np.max(np.abs(resid), axis=-1) > 1e-6 * np.maximum(
        scale_f, np.max(np.abs(As), axis=(1, 2)) * np.max(np.abs(z), axis=-1))
    singular |= bad
    z = z * cs
    lam = z[:, :lay.n_rows]
    tau = z[:, lay.n_rows:]
    status = "ok"
    redundant: list[str] = []
    if n_red:
        status = "redundant"
        redundant = red_joints
        warn.append(f"{n_red} redundant joint equation(s): the equations "
                    + ", ".join(red_labels) + " are linearly dependent, so the reactions of "
                    "joints " + ", ".join(repr(j) for j in red_joints) + " are not unique; "
                    "the minimum-norm solution is reported (forces in N, moments in N m "
                    f"divided by the length scale {L:.4g} m)")
    if singular.any():
        status = "singular"
        ks = np.flatnonzero(singular)
        warn.append(f"{ks.size} singular position(s) (first at index {ks[0]}, t = "
                    f"{t[ks[0]]:.6g} s): the driven coordinates do not control the "
                    f"mechanism there; reactions there are least-squares values")
    near = (rcond < NEAR_SINGULAR_RCOND) & ~singular
    if near.any():
        k = int(np.argmin(np.where(near, rcond, np.inf)))
        warn.append(f"{int(near.sum())} position(s) close to a singular position (smallest "
                    f"rcond {rcond[k]:.2e} at index {k}, t = {t[k]:.6g} s): reactions and "
                    f"driving torques there are large and sensitive to the geometry")
    for w in warn:
        _warnings.warn(w, KinetostaticsWarning, stacklevel=3)

    # ------------------------------------------------ joint reactions
    X = extend(model, x)
    C = -P * lam[:, :, None]  # row contributions to generalized forces (n, rows, n_x)
    geo = _joint_geometry(model, lay)
    reactions, moments, jframe, jpoints, kinds = {}, {}, {}, {}, {}
    frame_loads: dict[str, np.ndarray] = {}
    for name, (kind, i, j, sj, ui) in geo.items():
        rows = lay.rows[name]
        Cj = C[:, rows, :].sum(axis=1).reshape(n, nb, 3)
        Pt = X[:, j, :2] + _rotb(X[:, j, 2], sj)  # joint point (ground frame)
        if j < nb:
            f = Cj[:, j, :2]
            m_o = Cj[:, j, 2]
            mP = m_o - _cross(Pt - X[:, j, :2], f)
        else:  # child is the ground: use the parent's share (action = -reaction)
            fi = Cj[:, i, :2]
            mi = Cj[:, i, 2] - _cross(Pt - X[:, i, :2], fi)
            f, mP = -fi, -mi
        reactions[name] = f
        moments[name] = mP if kind != "revolute" else np.zeros(n)
        jpoints[name] = Pt
        kinds[name] = kind
        thi = X[:, i, 2]
        if kind == "prismatic":
            u = _rotb(thi, ui)
            nrm = _perp(u)
            jframe[name] = np.stack([np.sum(f * u, -1), np.sum(f * nrm, -1)], axis=-1)
        else:
            e1 = np.stack([np.cos(thi), np.sin(thi)], axis=-1)
            jframe[name] = np.stack([np.sum(f * e1, -1), np.sum(f * _perp(e1), -1)], axis=-1)
        if i == nb or j == nb:
            sgn = 1.0 if j == nb else -1.0  # what the frame receives
            ff, mm = sgn * f, sgn * mP
            frame_loads[name] = np.concatenate(
                [ff, (mm + _cross(Pt - point, ff))[:, None]], axis=-1)

    # ------------------------------------------------ drives' stator and ground-attached loads
    D = np.einsum("nd,ndx->nx", tau, Gd) + np.einsum("nq,nqx->nx", Qd_loads, G)
    dr = _net_on_ground(model, x, D)
    dr[:, 2] -= _cross(np.broadcast_to(point, (n, 2)), dr[:, :2])
    frame_loads["drives"] = dr
    lg = F_ground.copy()
    lg[:, 2] -= _cross(np.broadcast_to(point, (n, 2)), lg[:, :2])
    frame_loads["loads"] = lg
    tot = sum(frame_loads.values())
    # ------------------------------------------------ power balance (self-check)
    p_in = np.einsum("nd,nd->n", tau, qdot[:, didx]) + np.einsum("nx,nx->n", F, xdot)
    p_kin = np.einsum("nx,nx->n", Ix, xdot)
    p_scale = max(float(np.max(np.abs(p_kin))), float(np.max(np.abs(p_in))),
                  float(np.max(np.abs(F * xdot))), 1e-300)
    stats = {"power_balance_rel": float(np.max(np.abs(p_in - p_kin)) / p_scale),
             "rcond_min": float(np.min(rcond)), "redundant_equations": n_red,
             "singular_positions": int(singular.sum())}
    return {"reactions": reactions, "moments": moments, "joint_frame": jframe,
            "joint_points": jpoints, "kinds": kinds, "frame_loads": frame_loads,
            "frame_force": tot[:, :2].copy(), "frame_moment": tot[:, 2].copy(), "tau": tau,
            "lam": lam, "status": status, "warnings": warn, "redundant": redundant,
            "stats": stats}


# ================================================================ dead centres
def dead_centres(mech_or_model, body: str, point, *, coordinate: str = "y",
                 over: str | None = None, mode=None, n: int = 720) -> dict:
    """Extreme positions of a point over one turn of a crank coordinate.

    Parameters
    ----------
    body, point :
        The watched point (e.g. the slider's ``"F"``).
    coordinate : {"x", "y"}
        Which ground coordinate of the point.
    over : str, optional
        The crank coordinate (default the first independent coordinate).
    n : int
        Samples of the turn before refinement.

    Returns
    -------
    dict
        ``{"min": (angle_rad, value_m), "max": (angle_rad, value_m)}`` with the
        angle in [0, 2 pi) and the extreme refined to about 1e-10 rad.
    """
    from scipy.optimize import minimize_scalar

    model = as_model(mech_or_model)
    lay = model.layout(mode)
    x_start = getattr(model, "x0", model.x_sketch)
    over_idx = [model.coordinate_index(over)] if over else []
    didx = np.asarray(_independent_subset(model, lay, x_start, over_idx), dtype=int)
    held = coordinates(model, x_start)[didx[1:]]
    pos = _Positions(model, lay, didx)
    ang = np.linspace(0.0, 2 * np.pi, n + 1)
    qd = np.concatenate([ang[:, None], np.broadcast_to(held, (n + 1, held.size))], axis=1)
    xs = pos.solve(qd, np.asarray(x_start, float))
    k = 0 if coordinate == "x" else 1
    c = point_position(model, xs, body, point)[:, k]
    out = {}
    for key, sgn in (("min", 1.0), ("max", -1.0)):
        i = int(np.argmin(sgn * c[:-1]))
        xi = xs[i]

        def f(a, xi=xi, sgn=sgn):
            qq = np.concatenate([[a], held])
            xa, _, _ = pos.newton(qq, xi)
            return sgn * point_position(model, xa, body, point)[k]

        h = ang[1] - ang[0]
        res = minimize_scalar(f, bracket=(ang[i] - h, ang[i], ang[i] + h),
                              options={"xtol": 1e-12})
        a = float(np.mod(res.x, 2 * np.pi))
        out[key] = (a, float(sgn * res.fun))
    return out
