"""The modes of a variable-structure model: its switchable elements (locks, stops,
contacts and switches), compiled once, and the constraint rows of each mode.

A *mode* (``State.mode``) is a set of tokens: the names of the engaged locks
(welds :class:`~mechdyn.mechanism.joint.Lock` and
:class:`~mechdyn.mechanism.switch.CoordinateLock`), closed stop sides
(``"stop@lower"``, ``"stop@upper"``), closed contacts (``"contact@contact"``) and
their friction state (``"contact:stick"``, ``"contact:slip+"``, ``"contact:slip-"``).

:class:`SwitchedModel` resolves the elements' variables (:mod:`mechdyn.model.variable`)
and gives the constraint rows of a mode (:meth:`SwitchedModel.rows`): each a
:class:`Row`, one row of :mod:`mechdyn.model.rows` held at a target,

    sign * (m(x) - target) = 0,

a weld lock three of them (ground x and y of r_child - (r_parent + A_parent c),
then theta_child - theta_parent - angle: the lowering rule
:func:`mechdyn.model.rows.weld`, as the model's own ``weld_rows``).  The
kinematics and dynamics in a mode are :class:`~mechdyn.dynamics.mode_system.ModeSystem`
(:mod:`mechdyn.dynamics.mode_system`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kernels.planar import rotate_back
from . import Model
from . import rows as R
from .constraints import extend
from .forces import force_model
from .inertia import drive_inertia
from .rows import Rows
from .state import Mode, friction_of, side_of, stick_key
from .variable import Measure, TimeMeasure, parse_variable

__all__ = ["Row", "SwitchedModel", "switched_model", "mode_locks", "mode_unilateral",
           "mode_friction",
           "Measure", "TimeMeasure",
           "parse_variable"]


@dataclass(frozen=True)
class Row:
    """One constraint row of a mode: sign * (measure(x) - target) = 0.

    ``kind`` is 'lock', 'stop', 'contact' or 'stick'; unilateral rows ('stop',
    'contact') carry a force lambda >= 0 that opens the gap.  ``slip`` (+1/-1,
    0 for none) and ``mu`` describe sliding friction on a contact row, with
    ``tangent`` the slip measure; ``compliance`` weighs the row's multiplier
    when a redundant set of rows leaves the multipliers free.
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
        """True for stops and contacts (a force that only pushes)."""
        return self.kind in ("stop", "contact")

    @cached_property
    def rows(self) -> Rows:
        """The row as data, with its label and element."""
        return self.measure.rows.scaled(self.sign, -self.target).renamed(self.label,
                                                                         self.element)

    @cached_property
    def friction_rows(self) -> Rows | None:
        """-mu slip T(x) of a sliding contact (T its slip measure), added to the row's
        Jacobian to give the direction of its force; None without sliding."""
        if not self.slip:
            return None
        return self.tangent.rows.scaled(-self.mu * self.slip).renamed(self.label,
                                                                      self.element)


def mode_locks(mode) -> frozenset:
    """The lock names of a mode (:attr:`Mode.locks`)."""
    return Mode(mode).locks


def mode_unilateral(mode) -> frozenset:
    """Closed stop sides and contacts of a mode (:attr:`Mode.closed`)."""
    return Mode(mode).closed


def mode_friction(mode) -> dict:
    """{contact: 'stick' | 'slip+' | 'slip-'} of a mode (:attr:`Mode.friction`)."""
    return Mode(mode).friction


class SwitchedModel:
    """A model with its switchable elements compiled (locks, stops, contacts, switches).

    Parameters
    ----------
    model : Model
        The compiled mechanism; its ``mechanism.extras`` may hold
        ``coordinate_locks``, ``stops``, ``contacts`` and ``switches``.

    Attributes
    ----------
    welds : dict
        Per weld lock: parent ``i``, child ``j``, offset ``c`` (2,) m, ``angle``
        rad, ``engaged`` (initially), ``declared`` (offset given, not captured).
    coord_locks, stops : dict
        ``{name: (element, Measure)}``.
    contacts : dict
        ``{name: (Contact, gap Measure, slip Measure)}``.
    switches : list
        ``(Switch, Measure or None, [(Measure, operator, value), ...])``.

    Raises
    ------
    ModelError
        Every problem of the switchable elements, at once.
    """

    def __init__(self, model: Model):
        self.model = model
        ex = model.mechanism.extras or {}
        self.nb = nb = model.n_bodies
        probs: list[str] = []
        self.welds = {}
        lk = model.lock
        for k, n in enumerate(lk.names):
            self.welds[n] = dict(i=int(lk.i[k]), j=int(lk.j[k]), c=lk.c[k].copy(),
                                 angle=float(lk.angle[k]), engaged=bool(lk.engaged[k]),
                                 declared=model.mechanism.joints[n].offset is not None)

        def measure(where, var, into=probs, **cond):
            """The Measure of a variable, or None with the problem noted."""
            try:
                return parse_variable(model, var, **cond)
            except ModelError as exc:
                into.append(f"{where}: {exc}")

        self.coord_locks = {}
        for cl in ex.get("coordinate_locks", []):
            meas = measure(f"coordinate lock {cl.name!r}: variable", cl.variable)
            if meas is None:
                continue
            for f in cl.frees:
                if f not in model.coordinate_names:
                    probs.append(f"coordinate lock {cl.name!r}: frees: "
                                 + did_you_mean(f, model.coordinate_names, "coordinate"))
            self.coord_locks[cl.name] = (cl, meas)
        self.stops = {}
        for st in ex.get("stops", []):
            meas = measure(f"stop {st.name!r}: variable", st.variable)
            if meas is not None:
                self.stops[st.name] = (st, meas)
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
            self.contacts[ct.name] = (ct, *(
                Measure(R.line(f"{ct.name}.{w}", b1, s1, b2, s2, u, normal=w == "gap", nb=nb))
                for w in ("gap", "slip")))
        lock_names = set(self.welds) | set(self.coord_locks)
        names_seen: dict[str, str] = {}
        for kind, names in (("lock", lock_names), ("stop", self.stops),
                            ("contact", self.contacts)):
            for n in names:
                if n in names_seen:
                    probs.append(f"{kind} {n!r}: the name is already used by a {names_seen[n]}")
                names_seen[n] = kind
        self.switches = []
        for sw in ex.get("switches", []):
            p = sw.problems()
            if sw.target not in lock_names:
                p.append(f"switch {sw.name!r}: target: "
                         + did_you_mean(sw.target, lock_names, "lock"))
            cond = dict(allow_time=True, allow_rate=True, allow_distance=True)
            meas = None if sw.variable is None else measure(f"switch {sw.name!r}: variable",
                                                             sw.variable, p, **cond)
            guards = [(measure(f"switch {sw.name!r}: guard", var, p, **cond), op, val)
                      for var, op, val in sw.guard]
            probs.extend(p)
            self.switches.append((sw, meas, guards))
        #: the Measure along the face of each stop with friction (its tangent variable)
        self.stop_tangents = {
            n: meas for n, (st, _) in self.stops.items()
            if st.friction > 0 and st.tangent_variable() is not None
            and (meas := measure(f"stop {n!r}: tangent", st.tangent_variable())) is not None}
        #: the travel or relative angle of each joint with friction (a Measure)
        self.joint_measures = {j: parse_variable(model, f"joint:{j}")
                               for j in model.friction_joints}
        if probs:
            raise ModelError(probs)
        self.lock_names = tuple(sorted(lock_names))
        self.fm = force_model(model)
        self.drive_inertia = drive_inertia(model)

    def with_drive_inertia(self, M, h, G, quad_g):
        """M and h with the rotor and gear inertia J_e of every drive on its coordinate k:
        the kinetic energy 1/2 J_e qdot_k^2 adds J_e g_k^T g_k to M and J_e quad_k g_k to h
        (g_k the coordinate's gradient, quad_k its velocity-quadratic term)."""
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

    def capture_target(self, name: str, x, targets: dict) -> None:
        """Store in ``targets`` the value a lock (or a sticking contact, ``"c:stick"``)
        holds when it engages at pose ``x`` (n_x,): a weld its declared offset or the
        child's pose in the parent frame ((2,) m, rad); a coordinate lock its declared
        value or its variable at ``x``; a sticking contact its slip measure, m."""
        if name in self.welds:
            w = self.welds[name]
            if w["declared"]:
                targets[name] = (w["c"].copy(), w["angle"])
                return
            X = extend(self.model, x)
            pi, pj = X[w["i"]], X[w["j"]]
            targets[name] = (rotate_back(pi[2], pj[:2] - pi[:2]), float(pj[2] - pi[2]))
        elif name in self.coord_locks:
            cl, meas = self.coord_locks[name]
            targets[name] = cl.value if cl.value is not None else meas.value(x)
        elif (fr := friction_of(name)) is not None:
            targets[name] = self.contacts[fr[0]][2].value(x)

    def weld_rows(self, name: str, targets: dict) -> Rows:
        """The three rows of weld lock ``name`` holding its target (or the model's offset)."""
        w = self.welds[name]
        c, ang = targets.get(name, (w["c"], w["angle"]))
        return R.weld(name, w["i"], c, w["j"], ang, nb=self.nb)

    def rows(self, mode, targets: dict) -> list[Row]:
        """The switchable rows of a mode, in a fixed order (locks, stops, contacts, stick).

        Raises
        ------
        ModelError
            A token names no lock, stop or contact (the message lists the valid names).
        """
        out: list[Row] = []
        fr = mode_friction(mode)
        for n in sorted(mode_locks(mode)):
            if n in self.welds:
                rows = self.weld_rows(n, targets)
                out.extend(Row(n, rows.labels[k], "lock", Measure(rows.take([k])), 0.0)
                           for k in range(3))
            elif n in self.coord_locks:
                out.append(Row(n, n, "lock", self.coord_locks[n][1], float(targets[n])))
            else:
                raise ModelError(did_you_mean(n, self.lock_names, "lock"))
        for tok in sorted(mode_unilateral(mode)):
            n, side = side_of(tok)
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
            out.append(Row(n, tok, "stop", meas, getattr(st, side),
                           1.0 if side == "lower" else -1.0))
        for c, s in sorted(fr.items()):
            if s == "stick":
                slip = self.contacts[c][2]
                out.append(Row(c, f"{c}.tangent", "stick", slip, float(targets[stick_key(c)])))
        return out


def switched_model(model: Model) -> SwitchedModel:
    """The switchable elements of a compiled model (:attr:`Model.switchable
    <mechdyn.model.Model>`, built and validated by the compiler).

    Raises
    ------
    ModelError
        Every problem of the switchable elements, at once.
    """
    if model.switchable is not None:  # built when the model was compiled
        return model.switchable
    return SwitchedModel(model)
