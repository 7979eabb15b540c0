"""The compiled, constant model: index layout and parameter arrays.

The state of a mechanism with ``n_bodies`` moving bodies is the absolute
coordinate vector ``x`` of length ``n_x = 3 n_bodies``, ordered
``(x_0, y_0, theta_0, x_1, ...)`` in the order the bodies were added.  The
ground is not part of ``x``; in the index arrays below it has index
``n_bodies`` and pose (0, 0, 0).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kernels.planar import rotate_back
from ..mechanism.body import GROUND
from ..mechanism.joint import Lock, Prismatic, Revolute, has_friction
from ..mechanism.placement import start_poses
from . import rows as R

__all__ = ["Model", "RevoluteRows", "PrismaticRows", "LockRows", "as_model"]

COORD_ANGLE, COORD_RELATIVE, COORD_TRAVEL, COORD_X, COORD_Y = 0, 1, 2, 3, 4
#: the most lock modes whose layouts a model builds when it is compiled
LAYOUTS_KEPT = 64
_KIND_CODE = {"angle": COORD_ANGLE, "relative_angle": COORD_RELATIVE, "travel": COORD_TRAVEL,
              "x": COORD_X, "y": COORD_Y}


@dataclass(frozen=True)
class RevoluteRows:
    """Arrays of all revolute joints: bodies ``i`` (parent), ``j`` (child), points."""

    names: tuple[str, ...]
    i: np.ndarray
    j: np.ndarray
    si: np.ndarray  # (n, 2) parent point, parent frame
    sj: np.ndarray  # (n, 2) child point, child frame


@dataclass(frozen=True)
class PrismaticRows:
    """Arrays of all prismatic joints (child ``j`` slides on a line of parent ``i``)."""

    names: tuple[str, ...]
    i: np.ndarray
    j: np.ndarray
    si: np.ndarray  # (n, 2) point of the line, parent frame
    ui: np.ndarray  # (n, 2) unit axis, parent frame
    sj: np.ndarray  # (n, 2) child point
    angle: np.ndarray  # (n,) theta_j - theta_i held


@dataclass(frozen=True)
class LockRows:
    """Arrays of all locks (welds): child frame origin held at ``c`` in the parent frame."""

    names: tuple[str, ...]
    i: np.ndarray
    j: np.ndarray
    c: np.ndarray  # (n, 2)
    angle: np.ndarray  # (n,)
    engaged: np.ndarray  # (n,) bool, initial mode


class Model:
    """Compiled form of a :class:`~mechdyn.mechanism.Mechanism`.

    Attributes
    ----------
    mechanism : Mechanism
        The description it was compiled from.
    body_names, joint_names, coordinate_names : tuple of str
    n_bodies, n_x, n_q : int
    mass, inertia : ndarray, shape (n_bodies,)
        kg and kg m^2 (about the centre of mass).
    com : ndarray, shape (n_bodies, 2)
        Centres of mass in the body frames, m.
    x_sketch : ndarray, shape (n_x,)
        The sketch poses, which choose the assembly branch.  A body given without a
        pose starts where :func:`~mechdyn.mechanism.placement.start_poses` places it; the
        initial assembly then puts the poses it found here.
    pose_given : ndarray of bool, shape (n_bodies,)
        Whether each body's pose was given (False: found by the assembly).
    found_poses : dict
        Body name -> (x m, y m, theta rad) of the bodies whose pose was omitted, as the
        initial assembly found them (set with ``x0``; empty when every pose is given).
    length_scale : float
        A characteristic length (m) used to scale tolerances and rotations.
    x0 : ndarray, shape (n_x,)
        The assembled sketch; set when the model is compiled
        (:func:`mechdyn.compiler.check_rank`, which also sets ``q_sketch``, its
        coordinates, and ``redundant``).
    tolerance_scale : ndarray, shape (n_q,)
        1 for angles, ``length_scale`` for travels and positions.
    force_scale : float
        The model's weight, at least 1 N.
    friction_joints : tuple of str
        The revolute and prismatic joints with friction, in joint order.
    forces, switchable
        The loads and drives resolved (:class:`~mechdyn.model.forces.ForceModel`)
        and the switchable elements (:class:`~mechdyn.model.switchable.SwitchedModel`),
        set by the compiler (:func:`mechdyn.compiler.check_loads`).

    A compiled model is constant: the compiler builds everything above, then freezes
    it, and no analysis writes to it (a run keeps its own caches in a
    :class:`~mechdyn.model.workspace.Workspace`).
    """

    def __init__(self, mechanism):
        self.mechanism = mechanism
        bodies = list(mechanism.bodies.values())
        self.body_names = tuple(b.name for b in bodies)
        self.n_bodies = nb = len(bodies)
        self.n_x = 3 * nb
        self._bindex = {**{n: k for k, n in enumerate(self.body_names)}, GROUND: nb}
        self._bodies = {**mechanism.all_bodies}

        self.mass = np.array([b.mass for b in bodies], dtype=float)
        self.inertia = np.array([b.inertia for b in bodies], dtype=float)
        self.com = np.array([b.com for b in bodies], dtype=float).reshape(nb, 2)
        self.gravity = np.asarray(mechanism.gravity, dtype=float)
        start = start_poses(mechanism)
        self.x_sketch = np.array([v for b in bodies for v in start[b.name]], dtype=float)
        self.pose_given = np.array([b.pose is not None for b in bodies], dtype=bool)
        self.found_poses: dict = {}
        self._start = {GROUND: (0.0, 0.0, 0.0), **start}

        revs, pris, locks = ([j for j in mechanism.joints.values() if isinstance(j, kind)]
                             for kind in (Revolute, Prismatic, Lock))
        self.rev = RevoluteRows(*self._ends(revs), self._points(revs, "parent"),
                                self._points(revs, "child"))
        self.pri = PrismaticRows(
            *self._ends(pris), self._points(pris, "parent"),
            np.array([np.asarray(j.axis, float) / np.hypot(*j.axis) for j in pris]).reshape(-1, 2),
            self._points(pris, "child"),
            np.array([self._start[j.child][2] - self._start[j.parent][2]
                      if j.angle is None else j.angle for j in pris], dtype=float))
        off = np.array([self._sketch_offset(j) if j.offset is None else j.offset[:3]
                        for j in locks], dtype=float).reshape(-1, 3)
        self.lock = LockRows(*self._ends(locks), off[:, :2], off[:, 2],
                             np.array([j.engaged for j in locks], dtype=bool))
        self.joint_names = tuple(mechanism.joints)
        self._jkind = {n: type(j).__name__.lower() for n, j in mechanism.joints.items()}

        coords = list(mechanism.coordinates.values())
        self.coordinate_names = tuple(c.name for c in coords)
        self.n_q = len(coords)
        self.coord_kind = np.array([_KIND_CODE[c.kind] for c in coords], dtype=int)
        self.coord_is_angle = np.array([c.is_angle for c in coords], dtype=bool)

        pts = [np.hypot(*p) for b in mechanism.all_bodies.values()
               for p in [b.com, *b.points.values()]]
        pts += list(np.abs(self.x_sketch[0::3])) + list(np.abs(self.x_sketch[1::3]))
        scale = max([p for p in pts if np.isfinite(p)] + [0.0])
        self.length_scale = scale if scale > 0 else 1.0

        # every joint and coordinate lowered to constraint rows (mechdyn.model.rows)
        rv, pr, lk = self.rev, self.pri, self.lock
        self.joint_rows = R.concat(
            nb,
            *[R.revolute(n, rv.i[k], rv.si[k], rv.j[k], rv.sj[k], nb=nb)
              for k, n in enumerate(rv.names)],
            *[R.prismatic(n, pr.i[k], pr.si[k], pr.ui[k], pr.j[k], pr.sj[k], pr.angle[k], nb=nb)
              for k, n in enumerate(pr.names)])
        self.weld_rows = {n: R.weld(n, lk.i[k], lk.c[k], lk.j[k], lk.angle[k], nb=nb)
                          for k, n in enumerate(lk.names)}
        self.coordinate_rows = R.concat(nb, *[self._coordinate_row(c) for c in coords])

        #: the engaged locks at the start (frozenset of lock names)
        self.initial_mode = frozenset(j.name for j in locks if j.engaged)
        #: declared assembly modes: (AssemblyMode, ((body index, local point) for P, Q, R))
        self.assembly_modes = [
            (am, tuple((self._bindex[b], np.asarray(self._point(b, ref), dtype=float))
                       for b, ref in am.points))
            for am in mechanism.extras.get("assembly", [])]
        ex = mechanism.extras or {}
        #: whether the model has switchable elements (switches, stops, contacts, coordinate
        #: locks): its runs go mode by mode
        self.has_switching = any(ex.get(k) for k in ("switches", "stops", "contacts",
                                                     "coordinate_locks"))
        #: the layouts of the lock modes, built here for every subset of the locks when
        #: there are at most LAYOUTS_KEPT of them (else for the initial mode and none)
        self._layouts = self._lock_layouts(lk.names)
        #: the scale of each coordinate's tolerances: 1 for angles, the length scale for
        #: travels and positions, shape (n_q,)
        self.tolerance_scale = np.where(self.coord_is_angle, 1.0, self.length_scale)
        #: the model's weight (at least 1 N): the scale of its forces, N
        self.force_scale = max(float(np.sum(self.mass)
                                     * max(np.hypot(*self.gravity), 1.0)), 1.0)
        #: the revolute and prismatic joints that dissipate (a Coulomb coefficient or a
        #: viscous term set), in joint order
        self.friction_joints = tuple(
            n for n, j in mechanism.joints.items()
            if isinstance(j, Revolute | Prismatic) and has_friction(j))
        #: the loads and drives resolved to indices (:class:`~mechdyn.model.forces.
        #: ForceModel`) and the switchable elements (:class:`~mechdyn.model.switchable.
        #: SwitchedModel`): set by the compiler (:func:`mechdyn.compiler.check_loads`)
        self.forces = None
        self.switchable = None

    def _coordinate_row(self, c) -> R.Rows:
        """The row of one coordinate (:mod:`mechdyn.model.rows`, lowering rules)."""
        if c.kind == "angle":
            return R.angle(c.name, self._bindex[c.body], c.offset, nb=self.n_bodies)
        if c.kind in ("x", "y"):  # the ground x or y of the body's origin
            return R.point(c.name, self._bindex[c.body], (0.0, 0.0), "xy".index(c.kind),
                           offset=c.offset, nb=self.n_bodies)
        return self.joint_variable(c.name, c.joint, c.offset)

    def joint_variable(self, label: str, joint: str, offset: float = 0.0) -> R.Rows:
        """The row of the relative angle theta_child - theta_parent of a revolute joint (rad)
        or of the travel of a prismatic joint along its axis (m), plus ``offset``.

        Raises
        ------
        ModelError
            ``joint`` is neither (the message lists the valid names).
        """
        rv, pr, nb = self.rev, self.pri, self.n_bodies
        if joint in rv.names:
            k = rv.names.index(joint)
            return R.relative_angle(label, rv.i[k], rv.j[k], offset, nb=nb)
        if joint in pr.names:
            k = pr.names.index(joint)
            return R.line(label, pr.j[k], pr.sj[k], pr.i[k], pr.si[k], pr.ui[k], normal=False,
                          offset=offset, nb=nb)
        raise ModelError(did_you_mean(joint, (*rv.names, *pr.names),
                                      "revolute or prismatic joint"))

    def __setattr__(self, name, value):
        if self.__dict__.get("_frozen", False):
            raise AttributeError(f"a compiled Model is frozen: {name!r} cannot be set (change "
                                 "the Mechanism and compile it again)")
        super().__setattr__(name, value)

    def freeze(self) -> Model:
        """Forbid setting attributes from now on (the compiler calls it when the model
        is complete and validated); returns the model."""
        super().__setattr__("_frozen", True)
        return self

    # ------------------------------------------------------------------ lookups
    def _ends(self, joints) -> tuple:
        """(names, parent indices, child indices) of some joints."""
        return (tuple(j.name for j in joints),
                *(np.array([self._bindex[getattr(j, end)] for j in joints], dtype=int)
                  for end in ("parent", "child")))

    def _points(self, joints, end: str) -> np.ndarray:
        """The (n, 2) points of some joints on their ``end`` ("parent" or "child") body."""
        return np.array([self._point(getattr(j, end), getattr(j, end + "_point"))
                         for j in joints]).reshape(-1, 2)

    def _point(self, body: str, ref) -> tuple[float, float]:
        if isinstance(ref, str):
            return self._bodies[body].point(ref)
        return (float(ref[0]), float(ref[1]))

    def _sketch_offset(self, j):
        pi = np.asarray(self._start[j.parent])
        pj = np.asarray(self._start[j.child])
        return (*rotate_back(pi[2], pj[:2] - pi[:2]), pj[2] - pi[2])

    def body_index(self, name: str) -> int:
        """Index of a moving body in ``x`` (ground: ``n_bodies``); clear error if unknown."""
        try:
            return self._bindex[name]
        except KeyError:
            raise ModelError(did_you_mean(name, self._bindex, "body")) from None

    def point_local(self, body: str, point) -> np.ndarray:
        """Body-frame coordinates of a named point (or pass-through of (x, y)), m."""
        self.body_index(body)
        if isinstance(point, str):
            b = self._bodies[body]
            if point not in b.point_names():
                raise ModelError(f"unknown point {point!r} of body {body!r}; valid point names: "
                                 + ", ".join(repr(p) for p in b.point_names()))
        return np.asarray(self._point(body, point), dtype=float)

    def named_points(self) -> list[tuple[str, str]]:
        """(body, point) of every named point of the moving bodies, centres of mass included."""
        return [(b, p) for b in self.body_names for p in self._bodies[b].point_names()]

    def joint_kind(self, name: str) -> str:
        """'revolute', 'prismatic' or 'lock'."""
        try:
            return self._jkind[name]
        except KeyError:
            raise ModelError(did_you_mean(name, self._jkind, "joint")) from None

    def coordinate_index(self, name: str) -> int:
        """Index of a generalized coordinate; clear error listing valid names."""
        try:
            return self.coordinate_names.index(name)
        except ValueError:
            raise ModelError(did_you_mean(name, self.coordinate_names, "coordinate")) from None

    # ------------------------------------------------------------------ modes
    def layout(self, mode=None) -> ConstraintLayout:
        """Row layout of the constraint equations in a mode of engaged locks (the initial
        mode by default); built with the model (see :attr:`LAYOUTS_KEPT`).

        Raises
        ------
        ModelError
            A name in ``mode`` that is not a lock (the message lists the locks).
        """
        mode = self.initial_mode if mode is None else frozenset(mode)
        got = self._layouts.get(mode)
        if got is not None:
            return got
        if unknown := set(mode) - set(self.lock.names):
            raise ModelError(did_you_mean(sorted(unknown)[0], self.lock.names, "lock"))
        return ConstraintLayout(self, mode)

    def _lock_layouts(self, locks) -> dict:
        """{mode: ConstraintLayout} of every subset of ``locks`` (at most
        :data:`LAYOUTS_KEPT` of them; else of the initial mode and of no lock)."""
        if 2 ** len(locks) > LAYOUTS_KEPT:
            modes = [self.initial_mode, frozenset()]
        else:
            modes = [frozenset(c) for r in range(len(locks) + 1)
                     for c in itertools.combinations(locks, r)]
        return {m: ConstraintLayout(self, m) for m in modes}


class ConstraintLayout:
    """Which rows of Phi belong to which joint or element, for one mode.

    Parameters
    ----------
    model : Model
    mode : frozenset of str
    extra : list of Row, optional
        The switchable rows of a variable-structure mode (weld locks included,
        :meth:`~mechdyn.model.switchable.SwitchedModel.rows`): they follow the joint rows
        instead of the welds of the engaged locks.  ``rows`` then has the joints and weld
        locks, ``elements`` the others (a sticking contact's row on its own, by its label;
        ``element_rows`` groups every row by element), ``slip_rows`` and ``friction`` the
        rows of sliding contacts and their friction terms.
    """

    def __init__(self, model: Model, mode: frozenset, extra=None):
        nb = model.n_bodies
        self.mode = frozenset(mode)
        self.extra = list(extra or ())
        welds = [model.weld_rows[n] for n in model.lock.names if n in mode and extra is None]
        self.rowset = R.concat(nb, model.joint_rows, *welds, *[r.rows for r in self.extra])
        self.n_rows = len(self.rowset)
        self.n_base = self.n_rows - len(self.extra)
        self.element_rows = _groups(self.rowset.elements)
        stick = {self.n_base + k: r.label for k, r in enumerate(self.extra) if r.kind == "stick"}
        self.row_joint = np.array([stick.get(k, el) for k, el in enumerate(self.rowset.elements)],
                                  dtype=object)
        groups = _groups(self.row_joint)
        self.rows = {k: v for k, v in groups.items() if k in model.mechanism.joints}
        self.elements = {k: v for k, v in groups.items() if k not in self.rows}
        slip = [(self.n_base + k, r.friction_rows) for k, r in enumerate(self.extra) if r.slip]
        self.slip_rows = np.array([k for k, _ in slip], int)
        self.friction = R.concat(nb, *[f for _, f in slip])
        #: the rows of the position problem [Phi(x); g(x)] = [0; q]
        self.position_rows = R.concat(nb, self.rowset, model.coordinate_rows)


def _groups(keys) -> dict:
    """{key: indices of its entries} of a sequence, keys in order of first appearance."""
    keys = np.asarray(keys, dtype=object)
    return {k: np.flatnonzero(keys == k) for k in dict.fromkeys(keys)}


def as_model(mech_or_model) -> Model:
    """The compiled :class:`Model` of a Mechanism (compiled and validated by
    :meth:`Mechanism.compile <mechdyn.mechanism.Mechanism.compile>`) or a Model."""
    if isinstance(mech_or_model, Model):
        return mech_or_model
    if hasattr(mech_or_model, "compile"):
        return mech_or_model.compile()
    raise TypeError(f"expected a Mechanism or a Model, got {type(mech_or_model).__name__}")
