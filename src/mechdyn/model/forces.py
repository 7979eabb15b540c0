"""Applied forces in absolute coordinates, their generalized forces and potentials.

``ForceModel.loads`` returns the force vector F (..., n_x) conjugate to the body
poses x: for each body the force (N) and the moment about the body-frame origin
(N m).  It works on one pose (x of shape (n_x,)) or on a batch (leading
dimensions, as in :mod:`mechdyn.model.constraints`), so forward dynamics
(one state per call) and kinetostatics (a whole cycle per call) evaluate the
loads with the same code.  The generalized forces are then Q = B^T F + Q_drive
by virtual work, exact.  Drives act on their coordinate directly (Q_drive).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kernels import rows_numpy
from ..kernels.planar import cross, rotate
from ..mechanism.drive import Drive
from ..mechanism.load import Bushing, Force, RotarySpring, Spring, Table, Torque
from . import Model
from .constraints import (
    coordinates_jacobian,
    extend,
    point_position,
    point_velocity,
)
from .pair_loads import BushingSet, SpringSet
from .variable import lower, parse

__all__ = ["LoadContext", "ForceModel", "force_model", "evaluate", "applied_forces",
           "com_arms"]


# ====================================================================== geometry
def com_arms(model: Model, x) -> np.ndarray:
    """A_k c_k: centres of mass relative to the frame origins in the ground frame,
    shape (..., n_bodies, 2), m."""
    th = np.asarray(x)[..., 2::3]
    c, s = np.cos(th), np.sin(th)
    cx, cy = model.com[:, 0], model.com[:, 1]
    out = np.empty(th.shape + (2,))
    out[..., 0] = c * cx - s * cy
    out[..., 1] = s * cx + c * cy
    return out


# ====================================================================== values
def _scalar_or_array(v):
    return float(v) if np.ndim(v) == 0 else v


class LoadContext:
    """What a load's value may depend on, handed to callables and tables.

    One position (``t`` a float, ``q`` of shape (n_q,) ...) or a batch of
    positions (leading dimensions ``(...)`` on every attribute); the methods
    return floats for one position and arrays of shape ``(...)`` for a batch.

    Attributes
    ----------
    t : float or ndarray, shape (...)
        Time, s.
    q, qdot : ndarray, shape (..., n_q)
    x, xdot : ndarray, shape (..., n_x)
        Body poses and their rates.
    """

    __slots__ = ("model", "t", "q", "qdot", "x", "xdot", "_read")

    def __init__(self, model: Model, t, q, qdot, x, xdot):
        self.model, self.t, self.q, self.qdot, self.x, self.xdot = model, t, q, qdot, x, xdot
        self._read = {}  # the variables read so far (several tables read the same one)

    @property
    def shape(self) -> tuple:
        """The batch shape, ``()`` for one position."""
        return np.shape(self.t)

    def at(self, k: tuple) -> LoadContext:
        """The context of one position ``k`` (an index into :attr:`shape`) of a batch."""
        if not k:
            return self
        return LoadContext(self.model, float(self.t[k]), self.q[k], self.qdot[k], self.x[k],
                           self.xdot[k])

    def coord(self, name: str):
        """Value of a generalized coordinate (rad or m)."""
        return _scalar_or_array(self.q[..., self.model.coordinate_index(name)])

    def rate(self, name: str):
        """Rate of a generalized coordinate (rad/s or m/s)."""
        return _scalar_or_array(self.qdot[..., self.model.coordinate_index(name)])

    def point(self, body: str, point) -> np.ndarray:
        """Position (..., 2) of a body point, m."""
        return point_position(self.model, self.x, body, point)

    def velocity(self, body: str, point) -> np.ndarray:
        """Velocity (..., 2) of a body point, m/s."""
        return point_velocity(self.model, self.x, self.xdot, body, point)

    def variable(self, name: str):
        """A named variable (:mod:`mechdyn.model.variable`): ``'t'``, a coordinate,
        ``'<coordinate>_dot'``, ``'joint:NAME'``, ``'angle:BODY'``, ``'body.point.x|y'``
        or ``'dist(body.point, body.point)'``; s, rad, m or their rates."""
        v = self._read.get(name)
        if v is None:
            fm = self.model.forces
            fn = fm.readers.get(name) if fm is not None else None
            if fn is None:  # a variable of no table (read by a callable load)
                fn = _variable_reader(self.model, name)
            v = self._read[name] = _scalar_or_array(fn(self))
        return v


def _variable_reader(model: Model, name: str):
    """A function of a :class:`LoadContext` giving variable ``name`` (array or float);
    those of the load tables are resolved once, by :func:`force_model`.

    Raises
    ------
    ModelError
        Unknown variable, coordinate, joint, body or point; the message lists the
        valid forms or names.
    """
    var = parse(name, model.coordinate_names)
    if var.kind == "time":
        def fn(ctx):
            return ctx.t
    elif var.kind == "coordinate":
        k = model.coordinate_index(var.name)

        def fn(ctx, k=k, rate=var.rate):
            return np.asarray(ctx.qdot if rate else ctx.q)[..., k]
    else:
        rows = lower(model, var)
        if var.kind == "point" and rows.b1[0] < model.n_bodies:
            b, s, comp = int(rows.b1[0]), rows.s1[0], var.comp

            def fn(ctx, b=b, s=s, comp=comp):  # a body point: its position, the short way
                x = np.asarray(ctx.x)
                return x[..., 3 * b + comp] + rotate(x[..., 3 * b + 2], s)[..., comp]
        elif var.kind == "distance":
            def fn(ctx, rows=rows):
                d = rows_numpy.values(rows, ctx.x)
                return np.hypot(d[..., 0], d[..., 1])
        else:
            def fn(ctx, rows=rows):
                return rows_numpy.values(rows, ctx.x)[..., 0]
    return fn


def _each(fn, shape: tuple):
    """fn(k) for every position k of a batch shape: a float for (), else an array."""
    if not shape:
        return fn(())
    out = np.empty(shape)
    for k in np.ndindex(shape):
        out[k] = fn(k)
    return out


def evaluate(value, ctx: LoadContext, where: str = "load"):
    """Evaluate a load value (constant, Table or callable of a LoadContext).

    Returns a float for one position, an array of shape ``ctx.shape`` for a
    batch.  Callables marked ``vectorized`` get the batch context whole; others
    are called once per position.
    """
    if isinstance(value, Table):
        return value(ctx.variable(value.variable))
    shape = ctx.shape
    if not callable(value):
        out = float(value)
        if shape:
            return np.full(shape, out)
    elif getattr(value, "vectorized", False) and shape:
        out = np.broadcast_to(np.asarray(value(ctx), dtype=float), shape).copy()
    else:
        out = _each(lambda k: float(value(ctx.at(k))), shape)
    if math.isfinite(out) if not shape else np.isfinite(out).all():
        return out
    k = int(np.argmax(~np.isfinite(np.ravel(out))))
    raise ModelError(f"{where}: value is not finite ({float(np.ravel(out)[k])!r}) at "
                         f"t = {np.ravel(np.broadcast_to(ctx.t, shape))[k]:.6g} s")


# ====================================================================== the loads
def _apply(F, b, arm, f):
    """Add force f (..., 2) at arm (..., 2) from the origin of body slot b to F (..., nb+1, 3)."""
    F[..., b, :2] += f
    F[..., b, 2] += cross(arm, f)


@dataclass
class ForceModel:
    """The loads and drives of a model, resolved to indices (build with :func:`force_model`)."""

    model: Model
    springs: list
    rotary: list
    forces: list
    torques: list
    drives: list
    bushings: list = field(default_factory=list)
    #: {variable name: its reader, a function of a LoadContext} of the load tables
    readers: dict = field(default_factory=dict)

    def __post_init__(self):
        m = self.model
        has = bool(np.any(m.gravity)) and bool(np.any(m.mass))
        #: the weights (n_bodies, 2), N, or None without gravity
        self._weights = m.mass[:, None] * m.gravity if has else None
        self._springs = SpringSet(self.springs, m.n_bodies) if self.springs else None
        self._bushings = BushingSet(self.bushings, m.n_bodies) if self.bushings else None
        self._damped = any(r[5] != 0.0 for r in self.rotary) or any(
            p is not None and p.damped for p in (self._springs, self._bushings))

    # ----------------------------------------------------------------- forces
    def loads(self, t, x, xdot, q, qdot, *, skip_drives: Sequence[int] = (),
              reacting_loads: Sequence[str] = (), conservative: bool = False):
        """Applied loads at one pose or a batch of poses.

        Parameters
        ----------
        t : float or array_like, shape (...)
        x, xdot : array_like, shape (..., n_x)
        q, qdot : array_like, shape (..., n_q)
        skip_drives : sequence of int
            Coordinates whose ``Drive`` elements are left out.
        reacting_loads : sequence of str
            Names of ``Force`` loads whose reaction the frame carries.
        conservative : bool
            Gravity and spring stiffness/preload alone (``t``, ``xdot``, ``q``
            and ``qdot`` are then not used).

        Returns
        -------
        F : ndarray, shape (..., n_x)
            Forces (N) and moments about the body-frame origins (N m) on the
            moving bodies; drives are not included (see ``Qd``).
        ground : ndarray, shape (..., 3)
            Force (N) and moment about the ground origin (N m) that the load
            elements attached to the frame put on it (spring ends, torque
            reactions, reacting forces).
        Qd : ndarray, shape (..., n_q)
            The drive torques/forces on the coordinates.
        """
        return self._loads(t, x, xdot, q, qdot, skip_drives, reacting_loads, conservative)[:3]

    def _loads(self, t, x, xdot, q, qdot, skip_drives=(), reacting_loads=(),
               conservative=False, keep_conservative=False):
        """:meth:`loads`, plus (with ``keep_conservative``, and no dampers) the
        conservative forces of the same pose as a fourth item (else None)."""
        m = self.model
        x = np.asarray(x, dtype=float)
        batch = x.shape[:-1]
        nb = m.n_bodies
        X = extend(m, x)
        F = np.zeros(batch + (nb + 1, 3))
        if self._weights is not None:  # at the centres of mass
            F[..., :nb, :2] += self._weights
            F[..., :nb, 2] += cross(com_arms(m, x), self._weights)
        V = None if conservative else extend(m, xdot)
        for pairs in (self._springs, self._bushings):
            if pairs is not None:
                pairs.apply(F, X, V)
        for (_name, i, j, k, a0, c, pre) in self.rotary:
            tq = k * (X[..., j, 2] - X[..., i, 2] - a0)
            if V is not None and c != 0.0:
                tq = tq + c * (V[..., j, 2] - V[..., i, 2])
            tq = -(tq + pre)
            F[..., j, 2] += tq
            F[..., i, 2] -= tq
        Fc = None
        if keep_conservative and not self._damped:
            Fc = F[..., :nb, :].reshape(batch + (m.n_x,)).copy()
        Qd = np.zeros(batch + (m.n_q,))
        if not conservative and (self.forces or self.torques or self.drives):
            if batch and np.shape(t) != batch:  # one time for a batch of poses
                t = np.broadcast_to(np.asarray(t, dtype=float), batch)
            ctx = LoadContext(m, t, q, qdot, x, xdot)
            reacting = set(reacting_loads)
            for (ld, b, s) in self.forces:
                mag = evaluate(ld.magnitude, ctx, f"force {ld.name!r}")
                d = np.asarray(ld.direction, dtype=float)
                arm = rotate(X[..., b, 2], s)
                if ld.frame == "body":
                    d = rotate(X[..., b, 2], d)
                f = np.asarray(mag)[..., None] * d
                _apply(F, b, arm, f)
                if ld.name in reacting:
                    # the frame takes the reaction along the same line of action
                    _apply(F, nb, X[..., b, :2] + arm, -f)
            for (ld, b, r) in self.torques:
                tq = evaluate(ld.magnitude, ctx, f"torque {ld.name!r}")
                F[..., b, 2] += tq
                if r is not None:
                    F[..., r, 2] -= tq
            skip = set(int(k) for k in skip_drives)
            for (dr, k) in self.drives:
                if k not in skip:
                    Qd[..., k] += self.drive_torque(dr, ctx, k)
        return F[..., :nb, :].reshape(batch + (m.n_x,)), F[..., nb, :], Qd, Fc

    def applied_and_conservative(self, t, x, xdot, q, qdot):
        """(F, Q_drive, F_c): :meth:`applied` and :meth:`conservative` at one state,
        the loads evaluated once when no spring has a damper (same values)."""
        F, _, Qd, Fc = self._loads(t, x, xdot, q, qdot, keep_conservative=True)
        return F, Qd, (self.conservative(x) if Fc is None else Fc)

    def applied(self, t, x, xdot, q, qdot) -> tuple[np.ndarray, np.ndarray]:
        """Applied forces F (..., n_x) on the body poses and drive forces Q_drive (..., n_q)."""
        F, _, Qd = self.loads(t, x, xdot, q, qdot)
        return F, Qd

    def drive_torque(self, dr: Drive, ctx: LoadContext, k: int):
        """Torque (N m) or force (N) of one drive on its coordinate (float, or an array
        of shape ``ctx.shape`` for a batch)."""
        tq = dr.torque
        w = np.asarray(ctx.qdot)[..., k]
        if hasattr(tq, "torque_at"):  # motor characteristics of mechanism.drive extensions
            return _each(lambda i: float(tq.torque_at(w[i])), ctx.shape)
        if hasattr(tq, "omega"):  # TorqueSpeedCurve
            return tq(w[()])
        return evaluate(tq, ctx, f"drive {dr.name!r}")

    # ----------------------------------------------------------------- energy
    def potential_energy(self, x):
        """Potential energy of gravity and springs (J), shape (...); zero at the origin
        / free length."""
        m = self.model
        x = np.asarray(x, dtype=float)
        X = extend(m, x)
        rc = X[..., :-1, :2] + com_arms(m, x)
        U = -np.sum(m.mass * (rc @ m.gravity), axis=-1)
        for pairs in (self._springs, self._bushings):
            if pairs is not None:
                U = U + pairs.energy(X)
        for (_, i, j, k, a0, _c, pre) in self.rotary:
            rel = X[..., j, 2] - X[..., i, 2]
            U = U + 0.5 * k * (rel - a0) ** 2 + pre * rel
        return U

    def nonconservative_power(self, t, x, xdot, q, qdot, *, applied=None):
        """Power (W) of every force that is not gravity or spring stiffness:
        dampers, applied forces and torques, and drives; shape (...).

        ``applied`` = (F, Q_drive) from :meth:`applied` at the same state
        saves evaluating the loads again."""
        F, Qd = self.applied(t, x, xdot, q, qdot) if applied is None else applied
        P = np.sum((F - self.conservative(x)) * xdot, axis=-1)
        return _scalar_or_array(P + np.sum(Qd * np.asarray(qdot), axis=-1))

    def conservative(self, x) -> np.ndarray:
        """Forces of gravity and spring stiffness/preload alone, (..., n_x)."""
        return self.loads(None, x, None, None, None, conservative=True)[0]


def applied_forces(model: Model, t, x, xdot, q, qdot, *, skip_drives: Sequence[int] = (),
                   reacting_loads: Sequence[str] = ()):
    """Applied forces for a batch of positions, drives included on the body poses.

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
    F, ground, Qd = fm.loads(t, x, np.asarray(xdot, dtype=float), np.asarray(q, dtype=float),
                             np.asarray(qdot, dtype=float), skip_drives=skip_drives,
                             reacting_loads=reacting_loads)
    if np.any(Qd):
        F = F + np.einsum("nq,nqx->nx", Qd, coordinates_jacobian(model, x))
    return F, ground, Qd


def force_model(model: Model) -> ForceModel:
    """Resolve the loads and drives of ``model.mechanism`` to indices; all problems at once
    (the compiler builds it once: :attr:`Model.forces <mechdyn.model.Model>`).

    Raises
    ------
    ModelError
        Every problem found: unknown bodies, points, joints and coordinates (with the
        valid names), negative or non-finite parameters, unknown table variables.
    """
    if model.forces is not None:  # built when the model was compiled
        return model.forces
    r = _Resolver(model)
    for ld in model.mechanism.loads:
        r.load(ld)
    r.tables()
    r.drives()
    if r.probs:
        raise ModelError(r.probs)
    return ForceModel(model, r.springs, r.rotary, r.forces, r.torques, r.drives_, r.bushings,
                      r.readers)


class _Resolver:
    """The loads and drives of a model resolved one by one, their problems collected."""

    def __init__(self, model: Model):
        self.model, self.mech = model, model.mechanism
        self.probs: list[str] = []
        self.springs, self.rotary, self.forces, self.torques = [], [], [], []
        self.drives_, self.bushings = [], []
        self.readers: dict = {}  # the table variables, each resolved once

    def body(self, name, where):
        """The body index, or None with the problem noted."""
        model = self.model
        try:
            return model.body_index(name)
        except ModelError:
            self.probs.append(f"{where}: " + did_you_mean(name, [*model.body_names, "ground"],
                                                         "body"))
            return None

    def anchor(self, b, p, where):
        """(body index, point in the body frame), or None with the problem noted."""
        i = self.body(b, where)
        try:
            return None if i is None else (i, self.model.point_local(b, p))
        except ModelError as exc:
            self.probs.append(f"{where}: {exc}")

    def load(self, ld) -> None:
        """Resolve one load by its type."""
        where = f"{type(ld).__name__.lower()} {getattr(ld, 'name', '?')!r}"
        for kind, resolve in ((Spring, self.spring), (Bushing, self.bushing),
                              (RotarySpring, self.rotary_spring), (Force, self.force),
                              (Torque, self.torque)):
            if isinstance(ld, kind):
                resolve(ld, where)
                return
        if not hasattr(ld, "generalized"):  # extension loads (process loads, contacts ...)
            self.probs.append(f"{where}: not a load mechdyn knows (Spring, Bushing, "
                              "RotarySpring, Force, Torque)")

    def spring(self, ld, where) -> None:
        a1, a2 = self.anchor(ld.body1, ld.point1, where), self.anchor(ld.body2, ld.point2, where)
        for fld in ("stiffness", "free_length", "damping"):
            if getattr(ld, fld) < 0:
                self.probs.append(f"{where}: {fld} must be >= 0, got {getattr(ld, fld)!r}")
        if a1 and a2:
            self.springs.append((ld.name, *a1, *a2, float(ld.stiffness),
                                 float(ld.free_length), float(ld.damping), float(ld.preload)))

    def bushing(self, ld, where) -> None:
        a1, a2 = self.anchor(ld.body1, ld.point1, where), self.anchor(ld.body2, ld.point2, where)
        for fld in ("kx", "ky", "cx", "cy"):
            v = getattr(ld, fld)
            if not (isinstance(v, int | float | np.integer | np.floating)
                    and math.isfinite(v) and v >= 0):
                self.probs.append(f"{where}: {fld} must be a finite number >= 0, got {v!r}")
        if a1 and a2 and a1[0] == a2[0]:
            self.probs.append(f"{where}: body1 and body2 are the same body {ld.body1!r}")
        elif a1 and a2:
            self.bushings.append((ld.name, *a1, *a2, *(float(getattr(ld, f))
                                                       for f in ("kx", "ky", "cx", "cy"))))

    def rotary_spring(self, ld, where) -> None:
        model = self.model
        if ld.joint not in self.mech.joints or model.joint_kind(ld.joint) != "revolute":
            self.probs.append(f"{where}: joint: " + did_you_mean(ld.joint, model.rev.names,
                                                                  "revolute joint"))
            return
        jj = model.rev.names.index(ld.joint)
        self.rotary.append((ld.name, int(model.rev.i[jj]), int(model.rev.j[jj]),
                            float(ld.stiffness), float(ld.free_angle), float(ld.damping),
                            float(ld.preload)))

    def force(self, ld, where) -> None:
        a = self.anchor(ld.body, ld.point, where)
        if a:
            self.forces.append((ld, *a))

    def torque(self, ld, where) -> None:
        b = self.body(ld.body, where)
        r = self.body(ld.reaction_body, where) if ld.reaction_body is not None else None
        if b is not None:
            self.torques.append((ld, b, r))

    def tables(self) -> None:
        """The variables of the load and drive tables, each resolved once."""
        for ld in [*self.mech.loads, *self.mech.drives]:
            for fld in ("magnitude", "torque"):
                tab = getattr(ld, fld, None)
                if isinstance(tab, Table):
                    try:
                        self.readers[tab.variable] = _variable_reader(self.model, tab.variable)
                    except ModelError as exc:
                        self.probs.append(f"{type(ld).__name__.lower()} "
                                          f"{getattr(ld, 'name', '?')!r}: {fld}: table "
                                          f"variable: {exc}")

    def drives(self) -> None:
        """Each drive's coordinate index."""
        model = self.model
        for dr in self.mech.drives:
            if dr.coordinate not in model.coordinate_names:
                self.probs.append(f"drive {dr.name!r}: coordinate: "
                                  + did_you_mean(dr.coordinate, model.coordinate_names,
                                                 "coordinate"))
                continue
            self.drives_.append((dr, model.coordinate_index(dr.coordinate)))
