"""Applied forces in absolute coordinates, their generalized forces and potentials.

``applied_forces`` returns the force vector F (n_x,) conjugate to the body
poses x: for each body the force (N) and the moment about the body-frame origin
(N m).  The generalized forces are then Q = B^T F + Q_drive by virtual work,
exact.  Drives act on their coordinate directly (Q_drive).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kinematics.constraints import extend
from ..mechanism.drive import Drive
from ..mechanism.load import Force, RotarySpring, Spring, Table, Torque
from ..model import Model

__all__ = ["LoadContext", "ForceModel", "force_model"]


class LoadContext:
    """What a load's value may depend on, handed to callables and tables.

    Attributes
    ----------
    t : float
        Time, s.
    q, qdot : ndarray, shape (n_q,)
    x, xdot : ndarray, shape (n_x,)
        Body poses and their rates.
    """

    __slots__ = ("model", "t", "q", "qdot", "x", "xdot")

    def __init__(self, model: Model, t, q, qdot, x, xdot):
        self.model, self.t, self.q, self.qdot, self.x, self.xdot = model, t, q, qdot, x, xdot

    def coord(self, name: str) -> float:
        """Value of a generalized coordinate (rad or m)."""
        return float(self.q[self.model.coordinate_index(name)])

    def rate(self, name: str) -> float:
        """Rate of a generalized coordinate (rad/s or m/s)."""
        return float(self.qdot[self.model.coordinate_index(name)])

    def point(self, body: str, point) -> np.ndarray:
        """Position (2,) of a body point, m."""
        from ..kinematics.constraints import point_position

        return point_position(self.model, self.x, body, point)

    def velocity(self, body: str, point) -> np.ndarray:
        """Velocity (2,) of a body point, m/s."""
        from ..kinematics.constraints import point_velocity

        return point_velocity(self.model, self.x, self.xdot, body, point)

    def variable(self, name: str) -> float:
        """A named variable: 't', a coordinate, '<coordinate>_dot', 'body.point.x|y'."""
        if name == "t":
            return float(self.t)
        if name in self.model.coordinate_names:
            return self.coord(name)
        if name.endswith("_dot") and name[:-4] in self.model.coordinate_names:
            return self.rate(name[:-4])
        parts = name.split(".")
        if len(parts) == 3 and parts[2] in ("x", "y"):
            p = self.point(parts[0], parts[1])
            return float(p[0] if parts[2] == "x" else p[1])
        raise ModelError(f"unknown table variable {name!r}; use 't', a coordinate "
                         f"({', '.join(self.model.coordinate_names)}), '<coordinate>_dot' or "
                         f"'body.point.x' / 'body.point.y'")


def evaluate(value, ctx: LoadContext, where: str = "load") -> float:
    """Evaluate a load value (constant, Table or callable of a LoadContext)."""
    if isinstance(value, Table):
        return value(ctx.variable(value.variable))
    if callable(value):
        out = float(value(ctx))
    else:
        out = float(value)
    if not np.isfinite(out):
        raise ModelError(f"{where}: value is not finite ({out!r}) at t = {ctx.t:.6g} s")
    return out


def _rot(th, s):
    c, sn = np.cos(th), np.sin(th)
    return np.array([c * s[0] - sn * s[1], sn * s[0] + c * s[1]])


@dataclass
class ForceModel:
    """The loads and drives of a model, resolved to indices (build with :func:`force_model`)."""

    model: Model
    gravity_F: np.ndarray  # (n_x,) forces of gravity at theta = 0 (moments added per pose)
    springs: list
    rotary: list
    forces: list
    torques: list
    drives: list

    # ----------------------------------------------------------------- forces
    def applied(self, t, x, xdot, q, qdot) -> tuple[np.ndarray, np.ndarray]:
        """Applied forces F (n_x,) on the body poses and drive forces Q_drive (n_q,)."""
        m = self.model
        F = np.zeros(m.n_x)
        self.add_gravity(F, x)
        ctx = None
        if self.springs or self.rotary or self.forces or self.torques or self.drives:
            ctx = LoadContext(m, t, q, qdot, x, xdot)
        X = extend(m, x)
        V = extend(m, xdot)
        nb = m.n_bodies
        for (name, i, si, j, sj, k, L0, c, pre) in self.springs:
            ai, aj = _rot(X[i, 2], si), _rot(X[j, 2], sj)
            d = X[j, :2] + aj - X[i, :2] - ai
            L = np.hypot(d[0], d[1])
            if L < 1e-300:
                raise ModelError(f"spring {name!r}: its two points coincide; direction undefined")
            e = d / L
            vd = (V[j, :2] + V[j, 2] * np.array([-aj[1], aj[0]])
                  - V[i, :2] - V[i, 2] * np.array([-ai[1], ai[0]]))
            f = k * (L - L0) + c * (e @ vd) + pre
            self._apply(F, i, ai, f * e, nb)
            self._apply(F, j, aj, -f * e, nb)
        for (_name, i, j, k, a0, c, pre) in self.rotary:
            rel = X[j, 2] - X[i, 2]
            w = V[j, 2] - V[i, 2]
            tq = -(k * (rel - a0) + c * w + pre)
            if j < nb:
                F[3 * j + 2] += tq
            if i < nb:
                F[3 * i + 2] -= tq
        for (ld, b, s) in self.forces:
            mag = evaluate(ld.magnitude, ctx, f"force {ld.name!r}")
            d = np.asarray(ld.direction)
            if ld.frame == "body":
                d = _rot(X[b, 2], d)
            self._apply(F, b, _rot(X[b, 2], s), mag * d, nb)
        for (ld, b, r) in self.torques:
            tq = evaluate(ld.magnitude, ctx, f"torque {ld.name!r}")
            if b < nb:
                F[3 * b + 2] += tq
            if r is not None and r < nb:
                F[3 * r + 2] -= tq
        Qd = np.zeros(m.n_q)
        for (dr, k) in self.drives:
            Qd[k] += self.drive_torque(dr, ctx, k)
        return F, Qd

    def drive_torque(self, dr: Drive, ctx: LoadContext, k: int) -> float:
        """Torque (N m) or force (N) of one drive on its coordinate."""
        tq = dr.torque
        if hasattr(tq, "torque_at"):  # motor characteristics of mechanism.drive extensions
            return float(tq.torque_at(ctx.qdot[k]))
        if not isinstance(tq, Table) and not callable(tq):
            return float(tq)
        if hasattr(tq, "omega"):  # TorqueSpeedCurve
            return tq(ctx.qdot[k])
        return evaluate(tq, ctx, f"drive {dr.name!r}")

    @staticmethod
    def _apply(F, b, arm, f, nb):
        if b < nb:
            F[3 * b] += f[0]
            F[3 * b + 1] += f[1]
            F[3 * b + 2] += arm[0] * f[1] - arm[1] * f[0]

    def add_gravity(self, F, x):
        """Add the weight of every body at its centre of mass to F (in place)."""
        m = self.model
        if not np.any(m.gravity) or not np.any(m.mass):
            return F
        th = x[2::3]
        c, s = np.cos(th), np.sin(th)
        ax = c * m.com[:, 0] - s * m.com[:, 1]
        ay = s * m.com[:, 0] + c * m.com[:, 1]
        fx, fy = m.mass * m.gravity[0], m.mass * m.gravity[1]
        F[0::3] += fx
        F[1::3] += fy
        F[2::3] += ax * fy - ay * fx
        return F

    # ----------------------------------------------------------------- energy
    def potential_energy(self, x) -> float:
        """Potential energy of gravity and springs (J); zero at the origin / free length."""
        m = self.model
        X = extend(m, x)
        th = X[:-1, 2]
        c, s = np.cos(th), np.sin(th)
        rc = X[:-1, :2] + np.stack([c * m.com[:, 0] - s * m.com[:, 1],
                                    s * m.com[:, 0] + c * m.com[:, 1]], axis=-1)
        U = -float(np.sum(m.mass * (rc @ m.gravity)))
        for (_, i, si, j, sj, k, L0, _c, pre) in self.springs:
            d = X[j, :2] + _rot(X[j, 2], sj) - X[i, :2] - _rot(X[i, 2], si)
            L = np.hypot(d[0], d[1])
            U += 0.5 * k * (L - L0) ** 2 + pre * L
        for (_, i, j, k, a0, _c, pre) in self.rotary:
            rel = X[j, 2] - X[i, 2]
            U += 0.5 * k * (rel - a0) ** 2 + pre * rel
        return U

    def nonconservative_power(self, t, x, xdot, q, qdot) -> float:
        """Power (W) of every force that is not gravity or spring stiffness:
        dampers, applied forces and torques, and drives."""
        F, Qd = self.applied(t, x, xdot, q, qdot)
        Fc = self.conservative(x)
        return float((F - Fc) @ xdot + Qd @ qdot)

    def conservative(self, x) -> np.ndarray:
        """Forces of gravity and spring stiffness/preload alone, (n_x,)."""
        m = self.model
        F = np.zeros(m.n_x)
        self.add_gravity(F, x)
        X = extend(m, x)
        nb = m.n_bodies
        for (_, i, si, j, sj, k, L0, _c, pre) in self.springs:
            ai, aj = _rot(X[i, 2], si), _rot(X[j, 2], sj)
            d = X[j, :2] + aj - X[i, :2] - ai
            L = np.hypot(d[0], d[1])
            f = k * (L - L0) + pre
            self._apply(F, i, ai, f * d / L, nb)
            self._apply(F, j, aj, -f * d / L, nb)
        for (_, i, j, k, a0, _c, pre) in self.rotary:
            tq = -(k * (X[j, 2] - X[i, 2] - a0) + pre)
            if j < nb:
                F[3 * j + 2] += tq
            if i < nb:
                F[3 * i + 2] -= tq
        return F


def force_model(model: Model) -> ForceModel:
    """Resolve the loads and drives of ``model.mechanism`` to indices; all problems at once."""
    mech = model.mechanism
    cached = getattr(model, "_force_model", None)
    if cached is not None:
        return cached
    probs: list[str] = []
    springs, rotary, forces, torques, drives = [], [], [], [], []

    def body(name, where):
        try:
            return model.body_index(name)
        except ModelError:
            probs.append(f"{where}: " + did_you_mean(name, [*model.body_names, "ground"], "body"))
            return None

    def point(b, p, where):
        try:
            return model.point_local(b, p)
        except ModelError as exc:
            probs.append(f"{where}: {exc}")
            return None

    for ld in mech.loads:
        where = f"{type(ld).__name__.lower()} {getattr(ld, 'name', '?')!r}"
        if isinstance(ld, Spring):
            i, j = body(ld.body1, where), body(ld.body2, where)
            si = point(ld.body1, ld.point1, where) if i is not None else None
            sj = point(ld.body2, ld.point2, where) if j is not None else None
            for fld in ("stiffness", "free_length", "damping"):
                if getattr(ld, fld) < 0:
                    probs.append(f"{where}: {fld} must be >= 0, got {getattr(ld, fld)!r}")
            if None not in (i, j) and si is not None and sj is not None:
                springs.append((ld.name, i, si, j, sj, float(ld.stiffness),
                                float(ld.free_length), float(ld.damping), float(ld.preload)))
        elif isinstance(ld, RotarySpring):
            if ld.joint not in mech.joints or model.joint_kind(ld.joint) != "revolute":
                probs.append(f"{where}: joint: " + did_you_mean(ld.joint, model.rev.names,
                                                                 "revolute joint"))
                continue
            jj = model.rev.names.index(ld.joint)
            rotary.append((ld.name, int(model.rev.i[jj]), int(model.rev.j[jj]),
                           float(ld.stiffness), float(ld.free_angle), float(ld.damping),
                           float(ld.preload)))
        elif isinstance(ld, Force):
            b = body(ld.body, where)
            s = point(ld.body, ld.point, where) if b is not None else None
            if b is not None and s is not None:
                forces.append((ld, b, s))
        elif isinstance(ld, Torque):
            b = body(ld.body, where)
            r = body(ld.reaction_body, where) if ld.reaction_body is not None else None
            if b is not None:
                torques.append((ld, b, r))
        elif hasattr(ld, "generalized"):  # extension loads (process loads, contacts ...)
            continue
        else:
            probs.append(f"{where}: not a load mechdyn knows (Spring, RotarySpring, Force, "
                         f"Torque)")
    for dr in mech.drives:
        if dr.coordinate not in model.coordinate_names:
            probs.append(f"drive {dr.name!r}: coordinate: "
                         + did_you_mean(dr.coordinate, model.coordinate_names, "coordinate"))
            continue
        drives.append((dr, model.coordinate_index(dr.coordinate)))
    if probs:
        raise ModelError(probs)
    fm = ForceModel(model, np.zeros(model.n_x), springs, rotary, forces, torques, drives)
    model._force_model = fm
    return fm
