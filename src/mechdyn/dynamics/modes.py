"""Kinematics and dynamics of one *mode* of a variable-structure mechanism.

A mode is the set of active switchable constraints (``State.mode``): engaged
locks (welds :class:`~mechdyn.mechanism.joint.Lock` and
:class:`~mechdyn.mechanism.switch.CoordinateLock`), closed stops
(``"stop@lower"``), closed contacts (``"contact"``) and their friction state
(``"contact:stick"``, ``"contact:slip+"``, ``"contact:slip-"``).

In a mode the constraint rows are the mechanism's revolute and prismatic rows
(:mod:`mechdyn.kinematics.constraints`) plus one row per active element, each a
*measure* m(x) held at a target (all rows, with their exact Jacobian and
acceleration term, live here: the model's own tables are left untouched).  The
independent coordinates q_I are a subset of the declared coordinates, chosen by
the largest pivots of the declared coordinates' Jacobian restricted to the
mode's null space (coordinates that became dependent are dropped).

Dynamics in a mode (reduced, exact), with xddot = B qddot_I + b and the
x-space mass matrix M(x) of bodies whose frames need not sit at their centres
of mass (h(x, xdot) the centripetal terms of the offset centres of mass):

    M (B qddot_I + b) + h = F + Phi_x^T lambda + (friction of sliding contacts)

n_x equations for qddot_I and the multipliers lambda of every row: the
accelerations and all constraint forces (joint reactions, lock torques,
contact forces) come out of one solve.  Redundant rows (a weld over a pin,
statically indeterminate contacts) get the multipliers of least weighted norm,
the weights being the contact compliances (the limit of the compliance-
regularized problem of the cyclic-automata document).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from ..errors import AssemblyError, ModelError, did_you_mean
from ..kinematics.constraints import extend, jacobian, residual
from ..model import COORD_ANGLE, COORD_RELATIVE, Model
from .forces import force_model
from .inertia import drive_inertia

__all__ = ["Measure", "parse_variable", "SwitchedModel", "Row", "ModeSystem", "ModeEval",
           "mass_matrix_x", "mode_locks", "mode_unilateral", "mode_friction"]


# ============================================================================ measures
def _rot(th, s):
    c, sn = np.cos(th), np.sin(th)
    return np.array([c * s[0] - sn * s[1], sn * s[0] + c * s[1]])


def _perp(v):
    return np.array([-v[1], v[0]])


class Measure:
    """A scalar measured on a pose: value m(x), gradient m_x (n_x,), and the
    velocity-quadratic term of its second derivative, d2m/dt2 = m_x xddot + quad.

    ``is_angle`` says whether it is in rad (True) or m (False).
    """

    is_angle = False
    label = "?"
    needs_velocity = False

    def value(self, X, V=None) -> float:
        raise NotImplementedError

    def grad(self, X, nb) -> np.ndarray:
        raise NotImplementedError

    def quad(self, X, V) -> float:
        raise NotImplementedError

    def rate(self, X, V, nb) -> float:
        """dm/dt = m_x xdot."""
        return float(self.grad(X, nb) @ V[:-1].reshape(-1))


class AngleMeasure(Measure):
    """Absolute angle of body ``b`` (+ offset), rad."""

    is_angle = True

    def __init__(self, b, offset=0.0, label="angle"):
        self.b, self.offset, self.label = b, float(offset), label

    def value(self, X, V=None):
        return float(X[self.b, 2] + self.offset)

    def grad(self, X, nb):
        g = np.zeros(3 * nb)
        if self.b < nb:
            g[3 * self.b + 2] = 1.0
        return g

    def quad(self, X, V):
        return 0.0


class RelAngleMeasure(Measure):
    """theta_j - theta_i (+ offset), rad."""

    is_angle = True

    def __init__(self, i, j, offset=0.0, label="relative angle"):
        self.i, self.j, self.offset, self.label = i, j, float(offset), label

    def value(self, X, V=None):
        return float(X[self.j, 2] - X[self.i, 2] + self.offset)

    def grad(self, X, nb):
        g = np.zeros(3 * nb)
        if self.j < nb:
            g[3 * self.j + 2] += 1.0
        if self.i < nb:
            g[3 * self.i + 2] -= 1.0
        return g

    def quad(self, X, V):
        return 0.0


class PointMeasure(Measure):
    """x (comp 0) or y (comp 1) of a body point in the ground frame, m."""

    def __init__(self, b, s, comp, label="point"):
        self.b, self.s, self.comp, self.label = b, np.asarray(s, float), comp, label

    def value(self, X, V=None):
        return float((X[self.b, :2] + _rot(X[self.b, 2], self.s))[self.comp])

    def grad(self, X, nb):
        g = np.zeros(3 * nb)
        if self.b < nb:
            rho = _rot(X[self.b, 2], self.s)
            g[3 * self.b + self.comp] = 1.0
            g[3 * self.b + 2] = _perp(rho)[self.comp]
        return g

    def quad(self, X, V):
        rho = _rot(X[self.b, 2], self.s)
        return float(-V[self.b, 2] ** 2 * rho[self.comp])


class LineMeasure(Measure):
    """Position of point ``s1`` of body ``b1`` relative to a line of body ``b2``.

    ``normal=True``: n . (p - a) (a gap; n = direction turned +90 deg);
    ``normal=False``: t . (p - a) (a travel along the line).  Plus ``offset``.
    """

    def __init__(self, b1, s1, b2, s2, u, normal, offset=0.0, label="line"):
        self.b1, self.s1 = b1, np.asarray(s1, float)
        self.b2, self.s2 = b2, np.asarray(s2, float)
        self.u = np.asarray(u, float) / np.hypot(*u)
        self.normal, self.offset, self.label = bool(normal), float(offset), label

    def _parts(self, X):
        r1 = _rot(X[self.b1, 2], self.s1)
        r2 = _rot(X[self.b2, 2], self.s2)
        d = X[self.b1, :2] + r1 - X[self.b2, :2] - r2
        t = _rot(X[self.b2, 2], self.u)
        n = _perp(t)
        return r1, r2, d, t, n

    def value(self, X, V=None):
        _, _, d, t, n = self._parts(X)
        return float((n if self.normal else t) @ d + self.offset)

    def grad(self, X, nb):
        r1, r2, d, t, n = self._parts(X)
        e, e2 = (n, -t) if self.normal else (t, n)  # direction, its derivative / dtheta2
        g = np.zeros(3 * nb)
        if self.b1 < nb:
            g[3 * self.b1:3 * self.b1 + 2] += e
            g[3 * self.b1 + 2] += e @ _perp(r1)
        if self.b2 < nb:
            g[3 * self.b2:3 * self.b2 + 2] -= e
            g[3 * self.b2 + 2] += e2 @ d - e @ _perp(r2)
        return g

    def quad(self, X, V):
        r1, r2, d, t, n = self._parts(X)
        w1, w2 = V[self.b1, 2], V[self.b2, 2]
        dd = V[self.b1, :2] + w1 * _perp(r1) - V[self.b2, :2] - w2 * _perp(r2)
        acc = -w1 ** 2 * r1 + w2 ** 2 * r2  # velocity part of the second derivative of d
        if self.normal:
            return float(-w2 ** 2 * (n @ d) - 2 * w2 * (t @ dd) + n @ acc)
        return float(-w2 ** 2 * (t @ d) + 2 * w2 * (n @ dd) + t @ acc)


class RateMeasure(Measure):
    """The time derivative of another measure (switch conditions only)."""

    needs_velocity = True

    def __init__(self, base, nb, label):
        self.base, self.nb, self.label = base, nb, label
        self.is_angle = base.is_angle

    def value(self, X, V=None):
        return self.base.rate(X, V, self.nb)


class DistanceMeasure(Measure):
    """Distance between two body points, m (switch conditions only)."""

    def __init__(self, b1, s1, b2, s2, label):
        self.b1, self.s1, self.b2, self.s2 = b1, np.asarray(s1, float), b2, np.asarray(s2, float)
        self.label = label

    def value(self, X, V=None):
        p1 = X[self.b1, :2] + _rot(X[self.b1, 2], self.s1)
        p2 = X[self.b2, :2] + _rot(X[self.b2, 2], self.s2)
        return float(np.hypot(*(p1 - p2)))


class TimeMeasure(Measure):
    """Time, s (the value is supplied by the caller)."""

    label = "t"


def coordinate_measure(model: Model, k: int) -> Measure:
    """The measure of declared coordinate number ``k`` (same as ``coordinates``)."""
    kind = model.coord_kind[k]
    off = model.coord_offset[k]
    name = model.coordinate_names[k]
    if kind == COORD_ANGLE:
        return AngleMeasure(model.coord_body[k], off, name)
    if kind == COORD_RELATIVE:
        jj = model.coord_joint[k]
        return RelAngleMeasure(model.rev.i[jj], model.rev.j[jj], off, name)
    jj = model.coord_joint[k]
    p = model.pri
    return LineMeasure(p.j[jj], p.sj[jj], p.i[jj], p.si[jj], p.ui[jj], False, off, name)


def _joint_measure(model: Model, jname: str) -> Measure:
    if jname in model.rev.names:
        jj = model.rev.names.index(jname)
        return RelAngleMeasure(model.rev.i[jj], model.rev.j[jj], 0.0, f"joint:{jname}")
    if jname in model.pri.names:
        p = model.pri
        jj = p.names.index(jname)
        return LineMeasure(p.j[jj], p.sj[jj], p.i[jj], p.si[jj], p.ui[jj], False, 0.0,
                           f"joint:{jname}")
    raise ModelError(did_you_mean(jname, (*model.rev.names, *model.pri.names),
                                  "revolute or prismatic joint"))


_DIST = re.compile(r"^dist\(\s*([^,\s]+)\s*,\s*([^,\s)]+)\s*\)$")


def _body_point(model, ref: str):
    parts = ref.split(".")
    if len(parts) != 2:
        raise ModelError(f"point reference {ref!r} must be 'body.point'")
    b = model.body_index(parts[0])
    return b, model.point_local(parts[0], parts[1])


def parse_variable(model: Model, spec: str, *, allow_time=False, allow_rate=False,
                   allow_distance=False) -> Measure:
    """The :class:`Measure` named by a variable string (see :mod:`mechdyn.mechanism.switch`).

    Raises
    ------
    ModelError
        The string names nothing known; the message lists the valid forms/names.
    """
    s = str(spec).strip()
    if s == "t":
        if not allow_time:
            raise ModelError("variable 't' (time) is allowed only in switch conditions")
        return TimeMeasure()
    if s in model.coordinate_names:
        return coordinate_measure(model, model.coordinate_index(s))
    if s.endswith("_dot") and s[:-4] in model.coordinate_names:
        if not allow_rate:
            raise ModelError(f"rate variable {s!r} is allowed only in switch conditions")
        base = coordinate_measure(model, model.coordinate_index(s[:-4]))
        return RateMeasure(base, model.n_bodies, s)
    if s.startswith("joint:"):
        return _joint_measure(model, s[6:])
    if s.startswith("angle:"):
        return AngleMeasure(model.body_index(s[6:]), 0.0, s)
    m = _DIST.match(s)
    if m:
        if not allow_distance:
            raise ModelError(f"distance variable {s!r} is allowed only in switch conditions")
        b1, s1 = _body_point(model, m.group(1))
        b2, s2 = _body_point(model, m.group(2))
        return DistanceMeasure(b1, s1, b2, s2, s)
    parts = s.split(".")
    if len(parts) == 3 and parts[2] in ("x", "y"):
        b, p = _body_point(model, ".".join(parts[:2]))
        return PointMeasure(b, p, 0 if parts[2] == "x" else 1, s)
    raise ModelError(
        f"unknown variable {s!r}; use a coordinate ({', '.join(model.coordinate_names)}), "
        "'<coordinate>_dot', 'joint:NAME', 'angle:BODY', 'body.point.x', 'body.point.y', "
        "'dist(body.point, body.point)' or 't'")


# ============================================================================ mass
_MASS_INDEX: dict = {}  # flat indices of the nonzeros of M, per number of bodies


def mass_matrix_x(model: Model, x, xdot=None):
    """Mass matrix M(x) (n_x, n_x) of the body poses and the centripetal term h (n_x,).

    The kinetic energy is T = 1/2 sum (m |v_c|^2 + J_c omega^2) with the centre
    of mass at rho = A(theta) com from the body frame origin; M xddot + h is the
    inertia force conjugate to the poses (force, N; moment about the frame
    origin, N m).
    """
    nb = model.n_bodies
    n_x = 3 * nb
    M = np.zeros((n_x, n_x))
    h = np.zeros(n_x)
    th = np.asarray(x, float)[2::3]
    c, sn = np.cos(th), np.sin(th)
    cx, cy = model.com[:, 0], model.com[:, 1]
    rx = c * cx - sn * cy
    ry = sn * cx + c * cy
    m = model.mass
    i = 3 * np.arange(nb)
    flat = _MASS_INDEX.get(nb)
    if flat is None:
        flat = _MASS_INDEX[nb] = np.concatenate([
            i * n_x + i, (i + 1) * n_x + i + 1, i * n_x + i + 2, (i + 2) * n_x + i,
            (i + 1) * n_x + i + 2, (i + 2) * n_x + i + 1, (i + 2) * n_x + i + 2])
    mry, mrx = m * -ry, m * rx
    M.flat[flat] = np.concatenate([m, m, mry, mry, mrx, mrx,
                                   model.inertia + m * (rx * rx + ry * ry)])
    if xdot is not None:
        w = np.asarray(xdot, float)[2::3]
        f = -m * w * w
        h[i] = f * rx
        h[i + 1] = f * ry
    return M, h


# ============================================================================ elements
@dataclass(frozen=True)
class Row:
    """One constraint row of a mode: sign * (measure(x) - target) = 0.

    ``kind`` is 'lock', 'stop', 'contact' or 'stick'; unilateral rows ('stop',
    'contact') carry a force lambda >= 0 that opens the gap.  ``slip`` (+1/-1,
    0 for none) and ``mu`` describe sliding friction on a contact row, with
    ``tangent`` the slip measure.
    """

    element: str
    label: str
    kind: str
    measure: Measure
    target: float
    sign: float = 1.0
    mu: float = 0.0
    slip: int = 0
    tangent: Measure | None = None
    compliance: float = 0.0

    @property
    def unilateral(self) -> bool:
        return self.kind in ("stop", "contact")


def mode_locks(mode) -> frozenset:
    """The lock names of a mode (tokens without '@' or ':')."""
    return frozenset(t for t in mode if "@" not in t and ":" not in t)


def mode_unilateral(mode) -> frozenset:
    """Closed stop sides ('name@lower', 'name@upper') and contacts ('name@contact')."""
    return frozenset(t for t in mode if "@" in t)


def mode_friction(mode) -> dict:
    """{contact: 'stick' | 'slip+' | 'slip-'} of a mode."""
    out = {}
    for t in mode:
        if ":" in t:
            c, s = t.split(":", 1)
            out[c] = s
    return out


class SwitchedModel:
    """A model with its switchable elements compiled (locks, stops, contacts, switches).

    Parameters
    ----------
    model : Model
        The compiled mechanism; its ``mechanism.extras`` may hold
        ``coordinate_locks``, ``stops``, ``contacts`` and ``switches``.

    Raises
    ------
    ModelError
        Every problem of the switchable elements, at once.
    """

    def __init__(self, model: Model):
        self.model = model
        mech = model.mechanism
        ex = mech.extras or {}
        nb = model.n_bodies
        self.nb = nb
        self.coord_measures = [coordinate_measure(model, k) for k in range(model.n_q)]
        self.base_layout = model.layout(frozenset())
        # batched kernels of the coordinates and joint rows (None: generic path)
        cterms = [_measure_term(m_, nb) for m_ in self.coord_measures]
        self._coord_batch = (_MeasureBatch(cterms, nb) if model.n_q and None not in cterms
                             and not self.base_layout.lock_active.any() else None)
        self._base_terms = _base_terms(model)
        probs: list[str] = []
        # weld locks (model tables); coordinate locks
        self.welds = {}
        lk = model.lock
        for k, n in enumerate(lk.names):
            self.welds[n] = dict(i=int(lk.i[k]), j=int(lk.j[k]), c=lk.c[k].copy(),
                                 angle=float(lk.angle[k]), engaged=bool(lk.engaged[k]),
                                 declared=mech.joints[n].offset is not None)
        self.coord_locks = {}
        for cl in ex.get("coordinate_locks", []):
            try:
                meas = parse_variable(model, cl.variable)
            except ModelError as exc:
                probs.append(f"coordinate lock {cl.name!r}: variable: {exc}")
                continue
            for f in cl.frees:
                if f not in model.coordinate_names:
                    probs.append(f"coordinate lock {cl.name!r}: frees: "
                                 + did_you_mean(f, model.coordinate_names, "coordinate"))
            self.coord_locks[cl.name] = (cl, meas)
        self.stops = {}
        for st in ex.get("stops", []):
            try:
                self.stops[st.name] = (st, parse_variable(model, st.variable))
            except ModelError as exc:
                probs.append(f"stop {st.name!r}: variable: {exc}")
        self.contacts = {}
        for ct in ex.get("contacts", []):
            try:
                b1 = model.body_index(ct.body)
                s1 = model.point_local(ct.body, ct.point)
                b2 = model.body_index(ct.line_body)
                s2 = model.point_local(ct.line_body, ct.line_point)
            except ModelError as exc:
                probs.append(f"contact {ct.name!r}: {exc}")
                continue
            if b1 == b2:
                probs.append(f"contact {ct.name!r}: the point and the line are on the same "
                             f"body {ct.body!r}")
                continue
            u = np.asarray(ct.line_direction, float)
            self.contacts[ct.name] = (
                ct, LineMeasure(b1, s1, b2, s2, u, True, 0.0, f"{ct.name}.gap"),
                LineMeasure(b1, s1, b2, s2, u, False, 0.0, f"{ct.name}.slip"))
        self.switches = []
        lock_names = set(self.welds) | set(self.coord_locks)
        names_seen: dict[str, str] = {}
        for kind, names in (("lock", lock_names), ("stop", self.stops),
                            ("contact", self.contacts)):
            for n in names:
                if n in names_seen:
                    probs.append(f"{kind} {n!r}: the name is already used by a {names_seen[n]}")
                names_seen[n] = kind
        for sw in ex.get("switches", []):
            p = sw.problems()
            if sw.target not in lock_names:
                p.append(f"switch {sw.name!r}: target: "
                         + did_you_mean(sw.target, lock_names, "lock"))
            meas = None
            if sw.variable is not None:
                try:
                    meas = parse_variable(model, sw.variable, allow_time=True, allow_rate=True,
                                          allow_distance=True)
                except ModelError as exc:
                    p.append(f"switch {sw.name!r}: variable: {exc}")
            guards = []
            for var, op, val in sw.guard:
                try:
                    guards.append((parse_variable(model, var, allow_time=True, allow_rate=True,
                                                  allow_distance=True), op, val))
                except ModelError as exc:
                    p.append(f"switch {sw.name!r}: guard: {exc}")
            probs.extend(p)
            self.switches.append((sw, meas, guards))
        if probs:
            raise ModelError(probs)
        self.lock_names = tuple(sorted(lock_names))
        self.fm = force_model(model)
        self.drive_inertia = drive_inertia(model)

    def with_drive_inertia(self, M, h, G, quad_g):
        """M and h with the rotor and gear inertia J_e of every drive on its coordinate k:
        the kinetic energy 1/2 J_e qdot_k^2 adds J_e g_k^T g_k to M and J_e quad_k g_k to h
        (g_k the coordinate's gradient, quad_k its velocity-quadratic term)."""
        if not self.drive_inertia.any():
            return M, h
        for k in np.flatnonzero(self.drive_inertia):
            je = self.drive_inertia[k]
            M = M + je * np.outer(G[k], G[k])
            h = h + je * quad_g[k] * G[k]
        return M, h

    # ------------------------------------------------------------------ modes
    @property
    def has_switching(self) -> bool:
        """True if there is anything for the event loop to do."""
        return bool(self.coord_locks or self.stops or self.contacts or self.switches
                    or self.welds)

    def initial_locks(self) -> frozenset:
        """Locks engaged at the start."""
        return frozenset([n for n, w in self.welds.items() if w["engaged"]]
                         + [n for n, (cl, _) in self.coord_locks.items() if cl.engaged])

    def lock_frees(self, name: str) -> tuple:
        """Coordinates a lock declares it makes dependent."""
        if name in self.coord_locks:
            return self.coord_locks[name][0].frees
        return tuple(getattr(self.model.mechanism.joints.get(name), "frees", ()) or ())

    def capture_target(self, name: str, x, targets: dict):
        """Store in ``targets`` the value a lock holds when it engages at pose ``x``."""
        X = extend(self.model, x)
        if name in self.welds:
            w = self.welds[name]
            if w["declared"]:
                targets[name] = (w["c"].copy(), w["angle"])
                return
            pi, pj = X[w["i"]], X[w["j"]]
            c, s = np.cos(pi[2]), np.sin(pi[2])
            d = pj[:2] - pi[:2]
            targets[name] = (np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]]),
                             float(pj[2] - pi[2]))
        elif name in self.coord_locks:
            cl, meas = self.coord_locks[name]
            targets[name] = cl.value if cl.value is not None else meas.value(X)
        elif ":" in name:
            c = name.split(":")[0]
            targets[name] = self.contacts[c][2].value(X)

    def rows(self, mode, targets: dict) -> list[Row]:
        """The switchable rows of a mode, in a fixed order (locks, stops, contacts)."""
        out: list[Row] = []
        fr = mode_friction(mode)
        for n in sorted(mode_locks(mode)):
            if n in self.welds:
                w = self.welds[n]
                c, ang = targets.get(n, (w["c"], w["angle"]))
                i, j = w["i"], w["j"]
                # child frame origin on two lines of the parent through c, and the angle
                out.append(Row(n, f"{n}.x", "lock",
                               LineMeasure(j, (0, 0), i, c, (1.0, 0.0), False), 0.0))
                out.append(Row(n, f"{n}.y", "lock",
                               LineMeasure(j, (0, 0), i, c, (1.0, 0.0), True), 0.0))
                out.append(Row(n, f"{n}.angle", "lock", RelAngleMeasure(i, j), ang))
            elif n in self.coord_locks:
                cl, meas = self.coord_locks[n]
                out.append(Row(n, n, "lock", meas, float(targets[n])))
            else:
                raise ModelError(did_you_mean(n, self.lock_names, "lock"))
        for tok in sorted(mode_unilateral(mode)):
            n, side = tok.split("@")
            if side == "contact":
                if n not in self.contacts:
                    raise ModelError(did_you_mean(n, self.contacts, "contact"))
                ct, gap, slip = self.contacts[n]
                s = fr.get(n, "")
                sgn = 1 if s == "slip+" else -1 if s == "slip-" else 0
                out.append(Row(n, tok, "contact", gap, 0.0, 1.0,
                               mu=ct.friction if sgn else 0.0, slip=sgn, tangent=slip,
                               compliance=ct.compliance))
                continue
            if n not in self.stops:
                raise ModelError(did_you_mean(n, self.stops, "stop"))
            st, meas = self.stops[n]
            lim = getattr(st, side)
            out.append(Row(n, tok, "stop", meas, lim, 1.0 if side == "lower" else -1.0))
        for c, s in sorted(fr.items()):
            if s == "stick":
                ct, gap, slip = self.contacts[c]
                out.append(Row(c, f"{c}.tangent", "stick", slip, float(targets[f"{c}:stick"])))
        return out


# ============================================================================ batched rows
class _MeasureBatch:
    """Values, gradients and quadratic terms of a list of measures, in a few NumPy calls.

    Every measure of a mode (joint rows, lock/stop/contact rows, coordinates) has
    the form ``m(x) = w . (p1 - p2) + ka theta_a + kb theta_b + c`` with
    ``p = r_b + A(theta_b) s`` body points and ``w = A(theta_d) u`` a direction
    fixed in body ``d``; body index ``nb`` is the ground (zero pose).  The index
    arrays and the scatter pattern of the gradients are built once per mode.
    """

    def __init__(self, terms, nb):
        n = len(terms)
        self.n, self.nb = n, nb
        n_x = 3 * nb
        arr = np.array([t[:12] for t in terms], float).reshape(n, 12)
        idx = arr[:, [0, 3, 6, 9, 10]].astype(int)
        self.b1, self.b2, self.d, self.a, self.bb = (idx[:, k] for k in range(5))
        self.s1x, self.s1y = arr[:, 1].copy(), arr[:, 2].copy()
        self.s2x, self.s2y = arr[:, 4].copy(), arr[:, 5].copy()
        self.ux, self.uy = arr[:, 7].copy(), arr[:, 8].copy()
        self.ka = np.array([t[11] for t in terms], float)
        self.kb = np.array([t[12] for t in terms], float)
        self.c = np.array([t[13] for t in terms], float)
        # gradient scatter: columns of (b1 x, y, th), (b2 x, y, th), d th, a th, bb th
        cols = []
        for b, k in ((self.b1, 0), (self.b1, 1), (self.b1, 2), (self.b2, 0), (self.b2, 1),
                     (self.b2, 2), (self.d, 2), (self.a, 2), (self.bb, 2)):
            col = 3 * b + k
            cols.append(np.where(b >= nb, n_x, col))  # ground -> a dump column
        rows = np.arange(n)
        self._flat = np.concatenate([rows * (n_x + 1) + c for c in cols])
        self._size = n * (n_x + 1)
        self._has_w = bool(np.any(self.ux) or np.any(self.uy))

    def parts(self, k):
        """Geometric parts at a pose: ``k`` = (cos, sin, theta, px, py) of the
        bodies with the ground appended (see :func:`_pose_parts`)."""
        c, s, th, px, py = k
        b1, b2, d = self.b1, self.b2, self.d
        c1, sn1, c2, sn2, cd, sd = c[b1], s[b1], c[b2], s[b2], c[d], s[d]
        r1x = c1 * self.s1x - sn1 * self.s1y
        r1y = sn1 * self.s1x + c1 * self.s1y
        r2x = c2 * self.s2x - sn2 * self.s2y
        r2y = sn2 * self.s2x + c2 * self.s2y
        wx = cd * self.ux - sd * self.uy
        wy = sd * self.ux + cd * self.uy
        dx = px[b1] + r1x - px[b2] - r2x
        dy = py[b1] + r1y - py[b2] - r2y
        return r1x, r1y, r2x, r2y, wx, wy, dx, dy

    def values(self, k, parts=None):
        """m(x), shape (n,)."""
        th = k[2]
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = parts or self.parts(k)
        return wx * dx + wy * dy + self.ka * th[self.a] + self.kb * th[self.bb] + self.c

    def jacobian(self, k, parts=None) -> np.ndarray:
        """m_x, shape (n, n_x)."""
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = parts or self.parts(k)
        vals = np.concatenate([wx, wy, wy * r1x - wx * r1y, -wx, -wy, wx * r2y - wy * r2x,
                               wx * dy - wy * dx, self.ka, self.kb])
        out = np.bincount(self._flat, vals, self._size).reshape(self.n, 3 * self.nb + 1)
        return out[:, :-1]

    def quad(self, k, kv, parts=None) -> np.ndarray:
        """Velocity-quadratic part of d2m/dt2, shape (n,); ``kv`` = (vx, vy, omega)
        of the bodies with the ground appended."""
        if not self._has_w:
            return np.zeros(self.n)
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = parts or self.parts(k)
        vx, vy, om = kv
        w1, w2, wd = om[self.b1], om[self.b2], om[self.d]
        ddx = vx[self.b1] - w1 * r1y - vx[self.b2] + w2 * r2y
        ddy = vy[self.b1] + w1 * r1x - vy[self.b2] - w2 * r2x
        w1s, w2s = w1 * w1, w2 * w2
        return (-wd * wd * (wx * dx + wy * dy) + 2.0 * wd * (wx * ddy - wy * ddx)
                + wx * (w2s * r2x - w1s * r1x) + wy * (w2s * r2y - w1s * r1y))


def _pose_parts(x, nb):
    """(cos, sin, theta, px, py) of the bodies, ground (zeros) appended."""
    X = np.zeros((nb + 1, 3))
    X[:nb] = np.reshape(x, (nb, 3))
    th = X[:, 2]
    return np.cos(th), np.sin(th), th, X[:, 0], X[:, 1]


def _rate_parts(xdot, nb):
    """(vx, vy, omega) of the bodies, ground (zeros) appended."""
    V = np.zeros((nb + 1, 3))
    V[:nb] = np.reshape(xdot, (nb, 3))
    return V[:, 0], V[:, 1], V[:, 2]


def _measure_term(meas, nb, sign=1.0, const=0.0):
    """The term of :class:`_MeasureBatch` of ``sign * (meas(x) - target)``
    (``const`` = -target), or None for a measure of another kind."""
    g = nb
    t = type(meas)
    z = (0.0, 0.0)
    if t is AngleMeasure:
        spec = (g, z, g, z, g, z, meas.b, 1.0, g, 0.0, meas.offset)
    elif t is RelAngleMeasure:
        spec = (g, z, g, z, g, z, meas.j, 1.0, meas.i, -1.0, meas.offset)
    elif t is PointMeasure:
        u = (1.0, 0.0) if meas.comp == 0 else (0.0, 1.0)
        spec = (meas.b, meas.s, g, z, g, u, g, 0.0, g, 0.0, 0.0)
    elif t is LineMeasure:
        u = meas.u if not meas.normal else (-meas.u[1], meas.u[0])
        spec = (meas.b1, meas.s1, meas.b2, meas.s2, meas.b2, u, g, 0.0, g, 0.0, meas.offset)
    else:
        return None
    b1, s1, b2, s2, d, u, a, ka, bb, kb, off = spec
    return (b1, s1[0], s1[1], b2, s2[0], s2[1], d, sign * u[0], sign * u[1], a, bb,
            sign * ka, sign * kb, sign * (off + const))


def _base_terms(model: Model) -> list:
    """Terms of the revolute and prismatic joint rows (the rows of the layout
    without locks)."""
    nb = model.n_bodies
    terms = []
    rv = model.rev
    for k in range(len(rv.names)):
        i, j = int(rv.i[k]), int(rv.j[k])
        si, sj = rv.si[k], rv.sj[k]
        for u in ((1.0, 0.0), (0.0, 1.0)):
            terms.append((i, si[0], si[1], j, sj[0], sj[1], nb, u[0], u[1], nb, nb, 0.0, 0.0,
                          0.0))
    pr = model.pri
    for k in range(len(pr.names)):
        i, j = int(pr.i[k]), int(pr.j[k])
        si, sj, ui = pr.si[k], pr.sj[k], pr.ui[k]
        terms.append((j, sj[0], sj[1], i, si[0], si[1], i, -ui[1], ui[0], nb, nb, 0.0, 0.0,
                      0.0))
        terms.append((nb, 0.0, 0.0, nb, 0.0, 0.0, nb, 0.0, 0.0, j, i, 1.0, -1.0,
                      -float(pr.angle[k])))
    return terms


# ============================================================================ the mode system
@dataclass
class ModeEval:
    """Everything computed at one state of a mode.

    Attributes
    ----------
    x, xdot, xddot : ndarray, shape (n_x,)
    q, qdot, qddot : ndarray, shape (n_q,)
        All declared coordinates (dependent ones measured on the pose).
    lam : ndarray, shape (n_rows,)
        Multipliers of the base joint rows, then of the switchable rows.
    F : ndarray, shape (n_x,)
        Applied forces on the poses, drives included.
    F_conservative : ndarray, shape (n_x,) or None
        Forces of gravity and spring stiffness alone at the pose, when they
        came out of the same evaluation of the loads (None otherwise).
    """

    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    lam: np.ndarray
    F: np.ndarray = field(repr=False, default=None)
    F_conservative: np.ndarray | None = field(repr=False, default=None)


class ModeSystem:
    """The constraint rows, independent coordinates and dynamics of one mode.

    Parameters
    ----------
    sm : SwitchedModel
    mode : frozenset of str
    targets : dict
        Held values of the engaged locks and sticking contacts (see
        :meth:`SwitchedModel.capture_target`).
    x : ndarray, shape (n_x,)
        The pose at which rows and coordinates are chosen.
    prefer : sequence of str
        Declared coordinates to keep independent if possible (the previous set).
    avoid : sequence of str
        Declared coordinates to drop first (``frees`` of the locks just engaged).

    Raises
    ------
    LockupError
        The mode leaves no freedom that the declared coordinates can describe.
    """

    def __init__(self, sm: SwitchedModel, mode, targets: dict, x, *, prefer=(), avoid=()):
        self.sm = sm
        model = sm.model
        self.model = model
        self.mode = frozenset(mode)
        self.targets = dict(targets)
        self.rows = sm.rows(self.mode, targets)
        self.n_base = sm.base_layout.n_rows
        self.n_rows = self.n_base + len(self.rows)
        n_x = model.n_x
        L = model.length_scale
        self._colscale = np.tile([L, L, 1.0], model.n_bodies)
        base_is_angle = np.zeros(self.n_base, bool)
        for n, r in sm.base_layout.rows.items():
            if model.joint_kind(n) == "prismatic":
                base_is_angle[r[1]] = True
        self._row_is_angle = np.concatenate(
            [base_is_angle, np.array([r.measure.is_angle for r in self.rows], bool)])
        self._rowscale = np.where(self._row_is_angle, 1.0, 1.0 / L)
        self.x_ref = np.array(x, float)
        # batched kernels of the rows (None: a measure of another kind, generic path)
        self._rows_batch = self._pos_batch = self._slip_batch = None
        own = [_measure_term(r.measure, sm.nb, r.sign, -r.target) for r in self.rows]
        if sm._coord_batch is not None and None not in own:
            self._rows_batch = _MeasureBatch(sm._base_terms + own, sm.nb)
            slip = [(self.n_base + k, _measure_term(r.tangent, sm.nb, -r.mu * r.slip))
                    for k, r in enumerate(self.rows) if r.slip]
            if slip and None in [t_ for _, t_ in slip]:
                self._rows_batch = None
            elif slip:
                self._slip_rows = np.array([k for k, _ in slip], int)
                self._slip_batch = _MeasureBatch([t_ for _, t_ in slip], sm.nb)
        R = self.row_jacobian(self.x_ref)
        Rs = R * self._rowscale[:, None] * self._colscale[None, :]
        self.independent_rows = _independent_rows(Rs)
        Ri = Rs[self.independent_rows]
        self.dof = n_x - len(self.independent_rows)
        # coordinates: pivots of G N, N the null space of the rows
        G = self._coord_jac(self.x_ref)
        cscale = np.where(model.coord_is_angle, 1.0, 1.0 / L)
        Gs = G * cscale[:, None] * self._colscale[None, :]
        if self.dof == 0:
            self.coords = np.zeros(0, int)
        else:
            if Ri.shape[0]:
                _, s, vt = np.linalg.svd(Ri)
                N = vt[Ri.shape[0]:].T
            else:
                N = np.eye(n_x)
            GN = Gs @ N  # (n_q, dof)
            w = np.ones(model.n_q)
            names = model.coordinate_names
            for k, n in enumerate(names):
                if n in avoid:
                    w[k] = 1e-6
                elif prefer and n not in prefer:
                    w[k] = 0.5
            _, rr, piv = scipy.linalg.qr((GN * w[:, None]).T, pivoting=True)
            chosen = np.sort(piv[:self.dof])
            sub = GN[chosen]
            sv = np.linalg.svd(sub, compute_uv=False)
            if sv.size < self.dof or sv[-1] < 1e-8 * max(1.0, sv[0]):
                from ..errors import LockupError

                raise LockupError(
                    f"mode {_fmt_mode(self.mode)} leaves {self.dof} degree(s) of freedom that "
                    f"the declared coordinates ({', '.join(names)}) cannot describe")
            self.coords = chosen
        self.coord_names = tuple(model.coordinate_names[k] for k in self.coords)
        self.n_i = len(self.coords)
        if self._rows_batch is not None:
            terms = sm._base_terms + own
            cterms = [_measure_term(m_, sm.nb) for m_ in sm.coord_measures]
            self._pos_batch = _MeasureBatch([terms[k] for k in self.independent_rows]
                                            + [cterms[k] for k in self.coords], sm.nb)
            # rows and coordinates in one batch, for the dynamics
            self._all_batch = _MeasureBatch(terms + cterms, sm.nb)
        self._eye_i = np.zeros((n_x, self.n_i))
        self._eye_i[len(self.independent_rows):, :] = np.eye(self.n_i)
        self._rs = np.tile([1.0, 1.0, 1.0 / L], model.n_bodies)
        self._x_last = self.x_ref.copy()
        self._B_last = None
        self._qi_last = None

    # ------------------------------------------------------------------ rows
    def row_values(self, x) -> np.ndarray:
        """Residuals of every row (base joints, then switchable rows), m or rad."""
        if self._rows_batch is not None:
            return self._rows_batch.values(_pose_parts(x, self.sm.nb))
        X = extend(self.model, x)
        base = residual(self.model, x, self.sm.base_layout)
        own = [r.sign * (r.measure.value(X) - r.target) for r in self.rows]
        return np.concatenate([base, np.array(own, float)])

    def row_jacobian(self, x) -> np.ndarray:
        """Jacobian of every row, shape (n_rows, n_x)."""
        if self._rows_batch is not None:
            return self._rows_batch.jacobian(_pose_parts(x, self.sm.nb))
        X = extend(self.model, x)
        base = jacobian(self.model, x, self.sm.base_layout)
        own = [r.sign * r.measure.grad(X, self.sm.nb) for r in self.rows]
        if own:
            return np.concatenate([base, np.array(own)])
        return base

    def row_quad(self, x, xdot) -> np.ndarray:
        """Velocity-quadratic part of every row's second derivative."""
        from ..kinematics.constraints import gamma

        if self._rows_batch is not None:
            nb = self.sm.nb
            return self._rows_batch.quad(_pose_parts(x, nb), _rate_parts(xdot, nb))
        X, V = extend(self.model, x), extend(self.model, xdot)
        base = -gamma(self.model, x, xdot, self.sm.base_layout)
        own = [r.sign * r.measure.quad(X, V) for r in self.rows]
        return np.concatenate([base, np.array(own, float)])

    def _coord_jac(self, x) -> np.ndarray:
        if self.sm._coord_batch is not None:
            return self.sm._coord_batch.jacobian(_pose_parts(x, self.sm.nb))
        X = extend(self.model, x)
        if not self.model.n_q:
            return np.zeros((0, self.model.n_x))
        return np.array([m.grad(X, self.sm.nb) for m in self.sm.coord_measures])

    def coordinates(self, x) -> np.ndarray:
        """All declared coordinates measured on a pose, shape (n_q,)."""
        if self.sm._coord_batch is not None:
            return self.sm._coord_batch.values(_pose_parts(x, self.sm.nb))
        X = extend(self.model, x)
        return np.array([m.value(X) for m in self.sm.coord_measures], float)

    def residual_norm(self, x) -> float:
        """Largest constraint residual of the mode at ``x`` (m or rad)."""
        v = self.row_values(x)
        return float(np.max(np.abs(v))) if v.size else 0.0

    # ------------------------------------------------------------------ positions
    def _system(self, x):
        idx = self.independent_rows
        G = self._coord_jac(x)[self.coords]
        J = np.concatenate([self.row_jacobian(x)[idx], G])
        return J

    def solve_position(self, qi, x_guess=None, t=None) -> np.ndarray:
        """Pose x (n_x,) at independent coordinates ``qi`` (n_i,), by Newton from ``x_guess``.

        Without ``x_guess`` the start is the last solution moved to ``qi`` along
        its velocity analogs (a first-order predictor), which keeps the branch.
        """
        model = self.model
        qi = np.asarray(qi, float)
        if x_guess is None:
            x = self._x_last.copy()
            if self._B_last is not None and self.n_i:
                x = x + self._B_last @ (qi - self._qi_last)
        else:
            x = np.array(x_guess, float)
        idx = self.independent_rows
        tol = 1e-13 * max(model.length_scale, 1e-3)
        err_prev = np.inf
        J = None
        pb, nb, n_r = self._pos_batch, self.sm.nb, len(idx)
        for _ in range(40):
            if pb is not None:
                k = _pose_parts(x, nb)
                parts = pb.parts(k)
                F = pb.values(k, parts)
                F[n_r:] -= qi
            else:
                F = np.concatenate([self.row_values(x)[idx],
                                    self.coordinates(x)[self.coords] - qi])
            err = float(np.max(np.abs(F))) if F.size else 0.0
            if err <= tol or (err <= 1e3 * tol and err >= 0.5 * err_prev):
                break
            err_prev = err
            J = pb.jacobian(k, parts) if pb is not None else self._system(x)
            try:
                dx = np.linalg.solve(J, F)
            except np.linalg.LinAlgError:
                dx = np.linalg.lstsq(J, F, rcond=None)[0]
            x = x - dx
            if not np.all(np.isfinite(x)):
                break
        else:
            err = np.inf
        if not (err <= 1e3 * tol):
            res = {r: float(v) for r, v in zip(self.row_labels(), self.row_values(x), strict=True)
                   if abs(v) > 1e3 * tol} if np.all(np.isfinite(x)) else {}
            raise AssemblyError(
                f"the mechanism cannot be assembled in mode {_fmt_mode(self.mode)}",
                t=t, q=qi, residuals=res)
        self._x_last = x
        return x

    def row_labels(self) -> list[str]:
        """A label per row (joint name + component, then the switchable rows)."""
        labels = [""] * self.n_base
        for n, r in self.sm.base_layout.rows.items():
            comps = "xy" if self.model.joint_kind(n) == "revolute" else ("normal", "angle")
            for k, ri in enumerate(r):
                labels[ri] = f"{n}.{comps[k]}"
        return labels + [r.label for r in self.rows]

    def row_elements(self) -> list[str]:
        """The element (joint, lock, stop, contact) of each row."""
        el = [""] * self.n_base
        for n, r in self.sm.base_layout.rows.items():
            for ri in r:
                el[ri] = n
        return el + [r.element for r in self.rows]

    def velocity_analogs(self, x):
        """B (n_x, n_i) and the square Jacobian [rows; g_I] at x."""
        J = self._system(x)
        rhs = np.zeros((self.model.n_x, self.n_i))
        rhs[len(self.independent_rows):, :] = np.eye(self.n_i)
        B = np.linalg.solve(J, rhs) if J.size else np.zeros((self.model.n_x, 0))
        return B, J

    def state(self, qi, qdoti, x_guess=None, t=None):
        """(x, xdot, B) at independent coordinates and rates."""
        x = self.solve_position(qi, x_guess, t)
        B, _ = self.velocity_analogs(x)
        self._B_last, self._qi_last = B, np.array(qi, float)
        return x, B @ np.asarray(qdoti, float), B

    def independent(self, x, xdot):
        """(q_I, qdot_I) measured on a pose and its rates."""
        G = self._coord_jac(x)[self.coords]
        return self.coordinates(x)[self.coords], G @ xdot

    # ------------------------------------------------------------------ dynamics
    def evaluate(self, t, qi, qdoti, x_guess=None) -> ModeEval:
        """Accelerations and every multiplier at a state of the mode."""
        x = self.solve_position(qi, x_guess, t)
        ev = self.evaluate_x(t, x, None, qdoti=qdoti)
        self._qi_last = np.array(qi, float)
        return ev

    def evaluate_x(self, t, x, xdot, B=None, *, qdoti=None) -> ModeEval:
        """As :meth:`evaluate`, from a consistent pose and velocity (or, with
        ``xdot`` None, the independent rates ``qdoti``)."""
        if self._rows_batch is not None:
            return self._evaluate_batched(t, x, xdot, B, qdoti)
        model = self.model
        idx = self.independent_rows
        R = self.row_jacobian(x)
        G = self._coord_jac(x)
        J = np.concatenate([R[idx], G[self.coords]])
        if B is None:
            rhs = np.zeros((model.n_x, self.n_i))
            rhs[len(idx):, :] = np.eye(self.n_i)
            B = np.linalg.solve(J, rhs) if J.size else np.zeros((model.n_x, 0))
        if xdot is None:
            xdot = B @ np.asarray(qdoti, float)
            self._B_last = B
        quad_all = self.row_quad(x, xdot)
        X, V = extend(model, x), extend(model, xdot)
        quad_g = np.array([m.quad(X, V) for m in self.sm.coord_measures], float)
        rhs_b = -np.concatenate([quad_all[idx], quad_g[self.coords]])
        b = np.linalg.solve(J, rhs_b) if J.size else np.zeros(0)
        q = self.coordinates(x)
        qdot = G @ xdot
        F, Qd = self.sm.fm.applied(t, x, xdot, q, qdot)
        F = F + G.T @ Qd
        M, h = self.sm.with_drive_inertia(*mass_matrix_x(model, x, xdot), G, quad_g)
        Reff = R.copy()
        for k, r in enumerate(self.rows):
            if r.slip:
                Reff[self.n_base + k] -= r.mu * r.slip * r.tangent.grad(X, self.sm.nb)
        rs = np.tile([1.0, 1.0, 1.0 / model.length_scale], model.n_bodies)
        qddi, lam = self._solve_motion(M, B, Reff, F - h - M @ b, rs)
        xddot = B @ qddi + b
        qddot = G @ xddot + quad_g
        return ModeEval(x, xdot, xddot, q, qdot, qddot, lam, F)

    def _evaluate_batched(self, t, x, xdot, B, qdoti) -> ModeEval:
        """:meth:`evaluate_x` with the batched row kernels (same equations)."""
        model = self.model
        sm = self.sm
        nb = sm.nb
        idx, coords = self.independent_rows, self.coords
        ab, n_rows = self._all_batch, self.n_rows
        k = _pose_parts(x, nb)
        parts = ab.parts(k)
        RG = ab.jacobian(k, parts)
        R, G = RG[:n_rows], RG[n_rows:]
        J = np.concatenate([R[idx], G[coords]])
        if B is None:
            B = np.linalg.solve(J, self._eye_i) if J.size else np.zeros((model.n_x, 0))
        if xdot is None:
            xdot = B @ np.asarray(qdoti, float)
            self._B_last = B
        quad = ab.quad(k, _rate_parts(xdot, nb), parts)
        quad_all, quad_g = quad[:n_rows], quad[n_rows:]
        rhs_b = -np.concatenate([quad_all[idx], quad_g[coords]])
        b = np.linalg.solve(J, rhs_b) if J.size else np.zeros(0)
        q = ab.values(k, parts)[n_rows:]
        qdot = G @ xdot
        F, Qd, Fc = sm.fm.applied_and_conservative(t, x, xdot, q, qdot)
        F = F + G.T @ Qd
        M, h = self.sm.with_drive_inertia(*mass_matrix_x(model, x, xdot), G, quad_g)
        Reff = R
        if self._slip_batch is not None:
            Reff = R.copy()
            Reff[self._slip_rows] += self._slip_batch.jacobian(k)
        qddi, lam = self._solve_motion(M, B, Reff, F - h - M @ b, self._rs)
        xddot = B @ qddi + b
        qddot = G @ xddot + quad_g
        return ModeEval(x, xdot, xddot, q, qdot, qddot, lam, F, Fc)

    def _solve_motion(self, M, B, Reff, rhs, rs):
        """Solve [M B, -Reff^T] [qddot_i; lam] = rhs (rows scaled by ``rs``) for the
        independent accelerations and the multipliers; redundant sets by least squares."""
        Ks = np.concatenate([M @ B, -Reff.T], axis=1) * rs[:, None]
        try:
            sol = np.linalg.solve(Ks, rhs * rs) if Ks.shape[0] == Ks.shape[1] else None
        except np.linalg.LinAlgError:
            sol = None
        if sol is None:
            sol = self._redundant_solve(Ks, rhs * rs)
        return sol[:self.n_i], sol[self.n_i:]

    def _redundant_solve(self, Ks, rhs):
        """Least-squares solution of a rank-deficient [M B, -Phi^T] system whose
        multipliers are not unique: among all solutions, the one minimizing
        sum c_k lambda_k^2 over the compliant contact rows (c_k their compliances;
        1 for rigid unilateral rows, ~0 for the rigid joints and locks)."""
        sol0, *_ = np.linalg.lstsq(Ks, rhs, rcond=None)
        u, s, vt = np.linalg.svd(Ks)
        rank = int(np.sum(s > 1e-11 * (s[0] if s.size else 1.0)))
        N = vt[rank:].T
        if N.shape[1] == 0:
            return sol0
        w = np.full(Ks.shape[1], 1e-9)
        comp = np.array([r.compliance for r in self.rows], float)
        cpos = comp[comp > 0]
        cref = float(np.mean(cpos)) if cpos.size else 1.0
        for k, r in enumerate(self.rows):
            if r.unilateral:
                w[self.n_i + self.n_base + k] = comp[k] / cref if comp[k] > 0 else 1.0
        NW = N.T * w
        z = -np.linalg.lstsq(NW @ N, NW @ sol0, rcond=None)[0]
        return sol0 + N @ z

    def terms(self, t, x, xdot):
        """Reduced dynamics at a consistent state: A qddot_I = f (no friction terms).

        Returns
        -------
        dict with B (n_x, n_i), b (n_x,) [xddot = B qddot_I + b], A (n_i, n_i)
        generalized mass matrix, f (n_i,) = B^T (F - h - M b), M (n_x, n_x).
        """
        model = self.model
        B, J = self.velocity_analogs(x)
        idx = self.independent_rows
        quad_all = self.row_quad(x, xdot)
        X, V = extend(model, x), extend(model, xdot)
        quad_g = np.array([m.quad(X, V) for m in self.sm.coord_measures], float)
        rhs_b = -np.concatenate([quad_all[idx], quad_g[self.coords]])
        b = np.linalg.solve(J, rhs_b) if J.size else np.zeros(0)
        G = self._coord_jac(x)
        q, qdot = self.coordinates(x), G @ xdot
        F, Qd = self.sm.fm.applied(t, x, xdot, q, qdot)
        F = F + G.T @ Qd
        M, h = self.sm.with_drive_inertia(*mass_matrix_x(model, x, xdot), G, quad_g)
        return dict(B=B, b=b, A=B.T @ M @ B, f=B.T @ (F - h - M @ b), M=M, F=F, h=h)

    def kinetic_energy(self, x, xdot) -> float:
        """T = 1/2 xdot^T M xdot of the bodies and the drives' rotors and gears, J."""
        M, _ = self.sm.with_drive_inertia(*mass_matrix_x(self.model, x), self._coord_jac(x),
                                          np.zeros(self.model.n_q))
        return 0.5 * float(xdot @ M @ xdot)


def _independent_rows(Rs, tol=1e-9) -> np.ndarray:
    """Indices of a maximal set of linearly independent rows, earlier rows first."""
    keep = []
    basis = np.zeros((0, Rs.shape[1]))
    scale = max(np.max(np.abs(Rs)) if Rs.size else 1.0, 1e-300)
    for k in range(Rs.shape[0]):
        r = Rs[k] / scale
        if basis.shape[0]:
            r = r - basis.T @ (basis @ r)
            r = r - basis.T @ (basis @ r)
        nr = np.linalg.norm(r)
        if nr > tol * max(np.linalg.norm(Rs[k] / scale), 1e-300) and nr > 1e-12:
            basis = np.vstack([basis, r / nr])
            keep.append(k)
    return np.array(keep, int)


def _fmt_mode(mode) -> str:
    return "{" + ", ".join(sorted(mode)) + "}" if mode else "{} (no switchable constraint)"
