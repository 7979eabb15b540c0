"""The friction law of revolute and prismatic pairs (issue 12), written once for every
analysis: kinetostatics, forward dynamics and the reporters.

The law (``docs/friction.md``), with R the reaction on the CHILD from the PARENT at the
joint point (:func:`mechdyn.dynamics.reactions.joint_reaction`, ground frame):

* revolute (friction circle): the moment on the child
  ``M_f = -(mu r |R| s(w) + c_v w)``, ``w = theta_dot_child - theta_dot_parent``;
  ``-M_f`` acts on the parent (a couple: no force);
* prismatic: the sliding velocity ``v`` of the child's joint point along the guide
  axis relative to the parent's material point there; ``N`` the normal force and ``M``
  the moment (about the joint point) of the reaction; with the guide length ``L > 0``
  the gib edge loads ``N/2 - M/L`` and ``N/2 + M/L`` and the total normal load
  ``S = |N/2 - M/L| + |N/2 + M/L|`` (``L = 0``: ``S = |N|``); the friction force on the
  child ``f = -(mu S s(v) + c_v v)`` along the axis, at the joint point; ``-f`` on the
  parent at the same point;
* ``s(v) = tanh(v / smoothing)`` when the joint's ``smoothing`` > 0; ``sgn(v)``
  otherwise (true Coulomb: ``sgn(0) = 0``, sticking is a matter of modes and events).

The multipliers ``lam`` are those of the forward convention
``M xddot + h = F + Phi_x^T lam`` (so the reaction on the child is linear in them);
the generalized forces are forces (N) and moments about each body frame origin (N m)
on the poses x, as everywhere in mechdyn.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..kernels import rows_numpy
from ..kernels.planar import cross, perp, rotate
from ..model import Model
from ..model.constraints import extend

__all__ = ["FrictionPair", "FrictionSet", "PreparedFriction", "friction_joints"]


@dataclass(frozen=True)
class FrictionPair:
    """One joint with friction, its parameters and where it lives in ``x``.

    Attributes
    ----------
    name : str
    kind : {"revolute", "prismatic"}
    parent, child : int
        Body indices in ``x`` (the ground is ``model.n_bodies``).
    point : ndarray, shape (2,)
        The joint point in the child frame, m.
    axis : ndarray, shape (2,)
        Unit guide axis in the parent frame (prismatic; zeros for a revolute).
    mu : float
        Coulomb coefficient.
    length : float
        The pin radius (revolute) or the guide length (prismatic), m.
    viscous : float
        N m s/rad (revolute) or N s/m (prismatic).
    smoothing : float
        rad/s or m/s; 0 for true Coulomb.
    rows : ndarray of int
        The joint's rows in ``model.joint_rows`` (the same indices in every mode's
        row set, whose joint rows come first).
    """

    name: str
    kind: str
    parent: int
    child: int
    point: np.ndarray
    axis: np.ndarray
    mu: float
    length: float
    viscous: float
    smoothing: float
    rows: np.ndarray


def friction_joints(model: Model) -> tuple[str, ...]:
    """Names of the revolute and prismatic joints of a model that dissipate (a Coulomb
    coefficient or a viscous term set), in the model's joint order
    (:attr:`Model.friction_joints <mechdyn.model.Model>`, found when it was compiled).

    Parameters
    ----------
    model : Model
        A compiled model.

    Returns
    -------
    tuple of str
        The joint names (empty for a frictionless model).

    Examples
    --------
    >>> from mechdyn import examples
    >>> friction_joints(examples.load("toggle_press_friction").compile())
    ('A', 'B', 'C', 'D', 'E', 'F', 'slide')
    >>> friction_joints(examples.load("toggle_press").compile())
    ()
    """
    return model.friction_joints


def _sign(v, smoothing: float):
    """s(v): tanh(v / smoothing) when smoothing > 0, else sgn(v) (0 at 0)."""
    return np.tanh(v / smoothing) if smoothing > 0 else np.sign(v)


class FrictionSet:
    """The friction of the pairs of a model, evaluated batched over positions.

    Parameters
    ----------
    model : Model
    joints : sequence of str, optional
        The pairs to include (default every joint with friction,
        :func:`friction_joints`).

    Attributes
    ----------
    pairs : tuple of FrictionPair
    names : tuple of str
    rows : dict
        {joint: indices of its rows in ``model.joint_rows``}, the default ``rows`` of
        the methods (valid for every mode: the joint rows come first in a mode's rows).

    Raises
    ------
    ModelError
        A name that is not a revolute or prismatic joint.

    Notes
    -----
    |R| and S are not differentiable where they vanish; there the derivative given
    is the zero subgradient (the friction is taken as not growing with the
    multipliers), which a Newton iteration steps away from.

    Examples
    --------
    A pin of radius 10 mm with mu = 0.1 carrying a 100 N reaction, the child turning
    at +2 rad/s relative to the ground: the friction moment on it is -0.1 N m, and
    0.2 W is lost.

    >>> import numpy as np, mechdyn as md
    >>> from mechdyn.friction.law import FrictionSet
    >>> m = md.Mechanism("pin")
    >>> _ = m.add_body("arm", mass=1.0, inertia=0.1)
    >>> _ = m.add_revolute("O", "ground", "arm", friction=0.1, pin_radius=0.01)
    >>> _ = m.add_coordinate("phi", kind="angle", body="arm")
    >>> fs = FrictionSet(m.compile())
    >>> x, xdot = np.zeros(3), np.array([0.0, 0.0, 2.0])
    >>> lam = np.array([0.0, -100.0])        # reaction (0, 100) N on the arm
    >>> F, dF = fs.generalized(x, xdot, lam)
    >>> float(F[2]), float(dF[2, 1])
    (-0.1, 0.001)
    >>> round(float(fs.power_lost(x, xdot, lam)["O"]), 12)
    0.2
    """

    def __init__(self, model: Model, joints=None):
        from ..errors import ModelError, did_you_mean
        self.model = model
        names = friction_joints(model) if joints is None else tuple(joints)
        labels = model.joint_rows.elements
        pairs = []
        for nm in names:
            kind = model.joint_kind(nm) if nm in model.joint_names else None
            if kind not in ("revolute", "prismatic"):
                raise ModelError(did_you_mean(nm, [n for n in model.joint_names if
                                                   model.joint_kind(n) != "lock"],
                                              "revolute or prismatic joint"))
            jt = model.mechanism.joints[nm]
            tab = model.rev if kind == "revolute" else model.pri
            k = tab.names.index(nm)
            pairs.append(FrictionPair(
                nm, kind, int(tab.i[k]), int(tab.j[k]), np.asarray(tab.sj[k], float),
                np.asarray(tab.ui[k], float) if kind == "prismatic" else np.zeros(2),
                float(jt.friction), float(jt.pin_radius if kind == "revolute"
                                          else jt.guide_length),
                float(jt.viscous), float(jt.smoothing),
                np.array([r for r, e in enumerate(labels) if e == nm], int)))
        self.pairs = tuple(pairs)
        self.names = tuple(p.name for p in pairs)
        self.rows = {p.name: p.rows for p in pairs}
        self._rowset = model.joint_rows.take(
            np.concatenate([p.rows for p in pairs]) if pairs else np.zeros(0, int))
        self._slices, at = {}, 0
        for p in pairs:
            self._slices[p.name] = slice(at, at + len(p.rows))
            at += len(p.rows)

    def __len__(self) -> int:
        return len(self.pairs)

    def __bool__(self) -> bool:
        return bool(self.pairs)

    # ------------------------------------------------------------------ kinematics
    def speeds(self, x, xdot) -> dict:
        """Relative speed of each pair: w (rad/s) of a revolute, v (m/s) of a prismatic
        (the child's joint point along the axis relative to the parent), shape (...)."""
        X, V = extend(self.model, np.asarray(x, float)), extend(self.model, np.asarray(xdot, float))
        out = {}
        for p in self.pairs:
            if p.kind == "revolute":
                out[p.name] = V[..., p.child, 2] - V[..., p.parent, 2]
                continue
            P, u = self._point_axis(X, p)
            vc = V[..., p.child, :2] + V[..., p.child, 2, None] * perp(P - X[..., p.child, :2])
            vp = V[..., p.parent, :2] + V[..., p.parent, 2, None] * perp(
                P - X[..., p.parent, :2])
            out[p.name] = np.sum((vc - vp) * u, axis=-1)
        return out

    @staticmethod
    def _point_axis(X, p: FrictionPair):
        """The joint point (..., 2) and the guide axis (..., 2) in the ground frame."""
        P = X[..., p.child, :2] + rotate(X[..., p.child, 2], p.point)
        return P, rotate(X[..., p.parent, 2], p.axis)

    def _row_map(self, rows) -> Mapping:
        """{joint: indices into the multipliers} from None (:attr:`rows`), a mapping, or
        an object with ``element_rows`` (a ConstraintLayout or a ModeSystem)."""
        if rows is None:
            return self.rows
        if not isinstance(rows, Mapping):
            rows = getattr(rows, "element_rows", None)
            if not isinstance(rows, Mapping):
                raise TypeError("rows: expected a mapping {joint: row indices}, a "
                                "ConstraintLayout or a ModeSystem")
        missing = [n for n in self.names if n not in rows]
        if missing:
            raise ValueError("rows: no multipliers given for the joint(s) with friction "
                             + ", ".join(repr(n) for n in missing))
        return rows

    # ------------------------------------------------------------------ loads
    def _maps(self, x) -> dict:
        """The per-pose part of the loads: {joint: linear maps (..., k, n_e) from the
        pair's multipliers to the reaction force (revolute, k = 2), to the two gib edge
        loads (prismatic, L > 0, k = 2) or to the normal force (L = 0, k = 1)}."""
        x = np.asarray(x, float)
        X = extend(self.model, x)
        J = rows_numpy.jacobian(self._rowset, x) if self.pairs else None
        out = {}
        for p in self.pairs:
            Je = J[..., self._slices[p.name], :]  # (..., n_e, n_x)
            b, sgn = (p.child, 1.0) if p.child < self.model.n_bodies else (p.parent, -1.0)
            Af = sgn * np.swapaxes(Je[..., 3 * b:3 * b + 2], -1, -2)  # (..., 2, n_e)
            if p.kind == "revolute":
                out[p.name] = Af
                continue
            P, u = self._point_axis(X, p)
            aN = np.einsum("...k,...ke->...e", perp(u), Af)
            if p.length > 0:
                aM = sgn * (Je[..., 3 * b + 2] - cross(P[..., None, :] - X[..., None, b, :2],
                                                       Je[..., 3 * b:3 * b + 2]))
                out[p.name] = np.stack([0.5 * aN - aM / p.length, 0.5 * aN + aM / p.length],
                                       axis=-2)
            else:
                out[p.name] = aN[..., None, :]
        return out

    def _loads(self, maps: dict, lam, rows) -> dict:
        """:meth:`loads` from the per-pose maps (:meth:`_maps`)."""
        lam = np.asarray(lam, float)
        rows = self._row_map(rows)
        out = {}
        for p in self.pairs:
            idx = np.asarray(rows[p.name], int)
            A = maps[p.name]
            batch = np.broadcast_shapes(A.shape[:-2], lam.shape[:-1])
            v = np.einsum("...ke,...e->...k", A, lam[..., idx])
            d = np.zeros(batch + lam.shape[-1:])
            if p.kind == "revolute":  # |R|, its derivative R/|R| (0 where |R| = 0)
                mag = np.hypot(v[..., 0], v[..., 1])
                unit = v / np.where(mag > 0, mag, 1.0)[..., None]
            else:  # S = sum |edge load| (or |N|), its derivative sum sgn(load) a
                mag, unit = np.sum(np.abs(v), axis=-1), np.sign(v)
            d[..., idx] = np.einsum("...k,...ke->...e", unit, A)
            out[p.name] = (mag, d)
        return out

    def loads(self, x, lam, rows: Mapping | None = None) -> dict:
        """The friction-producing load of each pair and its derivative.

        Parameters
        ----------
        x : array_like, shape (..., n_x)
        lam : array_like, shape (..., n_rows)
            Multipliers (forward convention) of a row set whose rows ``rows`` belong
            to the pairs.
        rows : mapping, ConstraintLayout or ModeSystem, optional
            {joint: indices into the last axis of ``lam``} (or the ``element_rows`` of a
            layout or mode system); default :attr:`rows`.

        Returns
        -------
        dict
            {joint: (load (...), dload_dlam (..., n_rows))}: |R| of a revolute, N;
            S = |N/2 - M/L| + |N/2 + M/L| (L > 0) or |N| of a prismatic, N.
        """
        return self._loads(self._maps(x), lam, rows)

    # ------------------------------------------------------------------ the law
    def prepare(self, x, xdot, rows: Mapping | None = None,
                signs: Mapping | None = None) -> PreparedFriction:
        """The law at fixed poses and rates, for any multipliers: everything that does not
        depend on them (Jacobians, speeds, directions, force patterns) computed once, as a
        Newton iteration on the multipliers needs (:class:`PreparedFriction`)."""
        return PreparedFriction(self, x, xdot, rows, signs)

    def magnitudes(self, x, xdot, lam, rows: Mapping | None = None,
                   signs: Mapping | None = None) -> dict:
        """{joint: (value (...), dvalue_dlam (..., n_rows), speed (...))}: the friction
        moment on the child (revolute, N m) or the friction force on the child along the
        guide axis (prismatic, N), its derivative with respect to the multipliers and
        the relative speed.

        ``signs`` ({joint: +1 / -1}, optional): the slip direction s of stick-slip pairs
        in a slipping mode; where such a pair's speed is zero or against s (the first
        instant of its segment), its Coulomb friction is that of sgn(v) = s (the
        viscous part stays that of the actual speed)."""
        return self.prepare(x, xdot, rows, signs).magnitudes(lam)

    def _patterns(self, x) -> dict:
        """{joint: (child pattern, parent pattern)}: the generalized force (..., 3) on each
        of the two bodies (None for the ground) of a unit friction value (a unit moment on
        the child; a unit force along the axis on the child at the joint point)."""
        X = extend(self.model, np.asarray(x, float))
        nb, out = self.model.n_bodies, {}
        for p in self.pairs:
            if p.kind == "revolute":
                unit = np.zeros(X.shape[:-2] + (3,))
                unit[..., 2] = 1.0
                g = [unit, -unit]
            else:
                P, u = self._point_axis(X, p)
                g = [sg * np.concatenate([u, cross(P - X[..., b, :2], u)[..., None]], axis=-1)
                     for b, sg in ((p.child, 1.0), (p.parent, -1.0))]
            out[p.name] = tuple(gb if b < nb else None
                                for gb, b in zip(g, (p.child, p.parent), strict=True))
        return out

    def generalized(self, x, xdot, lam, rows: Mapping | None = None,
                    signs: Mapping | None = None):
        """The generalized friction force on the poses and its derivative with respect
        to the multipliers.

        Parameters
        ----------
        x, xdot : array_like, shape (..., n_x)
            Poses (m, rad) and their rates.
        lam : array_like, shape (..., n_rows)
            Multipliers, forward convention ``M xddot + h = F + Phi_x^T lam``.
        rows : mapping, ConstraintLayout or ModeSystem, optional
            {joint: indices into the last axis of ``lam``} (or the ``element_rows`` of a
            layout or mode system); default :attr:`rows`.
        signs : mapping, optional
            {joint: +1 / -1}: slip directions of stick-slip pairs (:meth:`magnitudes`).

        Returns
        -------
        F : ndarray, shape (..., n_x)
            Forces (N) and moments about each body frame origin (N m) of the friction
            of every pair on the moving bodies.
        dF_dlam : ndarray, shape (..., n_x, n_rows)
            Its exact derivative (the zero subgradient where a pair's load vanishes).

        Raises
        ------
        ModelError
            ``lam`` has fewer multipliers than a pair's rows need (naming the joint).
        """
        return self.prepare(x, xdot, rows, signs).generalized(lam)

    def by_pair(self, x, xdot, lam, rows: Mapping | None = None,
                signs: Mapping | None = None) -> dict:
        """{joint: (F (..., n_x), value (...))}: the generalized friction force of each pair
        on the moving bodies (as :meth:`generalized`) and the friction moment on the child
        (revolute, N m) or the friction force on the child along the axis (prismatic, N)."""
        return self.prepare(x, xdot, rows, signs).by_pair(lam)

    def power_lost(self, x, xdot, lam, rows: Mapping | None = None,
                   signs: Mapping | None = None) -> dict:
        """Power dissipated in each pair, {joint: (...)}, W (>= 0): minus the power of
        the friction moment or force on the relative motion."""
        return {nm: -val * spd for nm, (val, _, spd)
                in self.magnitudes(x, xdot, lam, rows, signs).items()}


class PreparedFriction:
    """The friction law of a :class:`FrictionSet` at fixed poses ``x`` and rates ``xdot``
    (..., n_x), evaluated at any multipliers: the per-pose maps of the loads, the speeds,
    the Coulomb directions and the force patterns are computed once
    (:meth:`FrictionSet.prepare`), and every pair is evaluated at once (its load maps
    stacked, k rows a pair, over the multipliers); the methods are those of the set
    without x and xdot.
    """

    def __init__(self, fs: FrictionSet, x, xdot, rows=None, signs=None):
        x, xdot = np.asarray(x, float), np.asarray(xdot, float)
        self.fs, self.n_x = fs, fs.model.n_x
        self.rows = fs._row_map(rows)
        self.batch = np.broadcast_shapes(x.shape[:-1], xdot.shape[:-1])
        self.speeds = fs.speeds(x, xdot)
        maps, pat = fs._maps(x), fs._patterns(x)
        signs = signs or {}
        pairs = fs.pairs
        self.gain, self.visc = (np.zeros(self.batch + (len(pairs),)) for _ in range(2))
        self.G = np.zeros(self.batch + (self.n_x, len(pairs)))  # unit friction -> F
        for c, p in enumerate(pairs):  # value = gain * load + viscous
            v = self.speeds[p.name]
            s = _sign(v, p.smoothing)
            if p.name in signs:
                s = np.where(signs[p.name] * v > 0, s, float(signs[p.name]))
            self.gain[..., c] = -p.mu * (p.length if p.kind == "revolute" else 1.0) * s
            self.visc[..., c] = -p.viscous * v
            for b, g in zip((p.child, p.parent), pat[p.name], strict=True):
                if g is not None:
                    self.G[..., 3 * b:3 * b + 3, c] += g
        self.maps = [maps[p.name] for p in pairs]
        k = [m.shape[-2] for m in self.maps]
        self.starts = np.cumsum([0, *k[:-1]]).astype(int)
        self.owner = np.repeat(np.arange(len(pairs)), k)
        self.is_rev = np.array([p.kind == "revolute" for p in pairs], bool)
        self._E: dict = {}

    def _stacked(self, n_rows: int) -> np.ndarray:
        """The load maps of every pair over the multipliers, (..., K, n_rows)."""
        E = self._E.get(n_rows)
        if E is None:
            K = self.owner.size
            E = np.zeros(self.batch + (K, n_rows))
            for p, A, a in zip(self.fs.pairs, self.maps, self.starts, strict=True):
                idx = np.asarray(self.rows[p.name], int)
                if idx.size and idx.max() >= n_rows:
                    raise ModelError(f"lam has {n_rows} multiplier(s) on its last axis, but "
                                     f"joint {p.name!r} uses rows {idx.tolist()}: give the "
                                     "multipliers of every constraint row")
                E[..., a:a + A.shape[-2], idx] = A
            self._E[n_rows] = E
        return E

    def _values(self, lam):
        """(value (..., P), dvalue_dlam (..., P, n_rows)) of every pair."""
        lam = np.asarray(lam, float)
        if not self.fs.pairs:
            batch = np.broadcast_shapes(self.batch, lam.shape[:-1])
            return np.zeros(batch + (0,)), np.zeros(batch + (0, lam.shape[-1]))
        E = self._stacked(lam.shape[-1])
        v = np.einsum("...ke,...e->...k", E, lam)
        sq = np.sqrt(np.add.reduceat(v * v, self.starts, axis=-1))
        load = np.where(self.is_rev, sq, np.add.reduceat(np.abs(v), self.starts, axis=-1))
        # d load / d lam: R / |R| of a pin (0 where |R| = 0), sgn(edge loads) of a guide
        own = load[..., self.owner]
        unit = np.where(self.is_rev[self.owner], v / np.where(own > 0, own, 1.0), np.sign(v))
        d = np.add.reduceat(unit[..., None] * E, self.starts, axis=-2)
        return self.gain * load + self.visc, self.gain[..., None] * d

    def magnitudes(self, lam) -> dict:
        """As :meth:`FrictionSet.magnitudes`."""
        val, dval = self._values(lam)
        return {p.name: (val[..., c], dval[..., c, :], self.speeds[p.name])
                for c, p in enumerate(self.fs.pairs)}

    def generalized(self, lam):
        """As :meth:`FrictionSet.generalized`: (F (..., n_x), dF_dlam (..., n_x, n_rows))."""
        val, dval = self._values(lam)
        return (np.einsum("...xp,...p->...x", self.G, val),
                np.einsum("...xp,...pe->...xe", self.G, dval))

    def by_pair(self, lam) -> dict:
        """As :meth:`FrictionSet.by_pair`: {joint: (F (..., n_x), value (...))}."""
        val, _ = self._values(lam)
        return {p.name: (self.G[..., c] * val[..., c, None], val[..., c])
                for c, p in enumerate(self.fs.pairs)}
