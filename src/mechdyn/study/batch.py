"""Variants of one topology evaluated as one batch: the kinetostatic cycle of V variants
with a variant axis through the rows, the position continuation and the solve.

Variants of one model file differ only in numbers (body points, masses, inertias,
loads, speeds).  Their constraint rows share the integers (which bodies) and each has
its own floats (:func:`mechdyn.kernels.rows_numpy.variant_rows`,
:mod:`mechdyn.kernels.rows_variants`), so that

* the continuation solves every variant's poses at one crank angle together (Newton
  on each variant's Jacobian, warm-started from the previous angle plus the tangent and
  the curvature), keeping each variant's assembly branch by the sign of det J; the
  rates and accelerations come from the factors of J at the solved poses;
* the kinetostatic solve ``[-Phi_x^T, g_d,x^T] z = I - F`` of
  :func:`mechdyn.dynamics.reactions.batched_inverse`, whose matrix is J transposed (its
  balancing scales cancel in the solution), reuses those factors for every variant and
  position;
* the inertia forces and weights are those of
  :func:`~mechdyn.model.inertia.inertia_forces` and
  :class:`~mechdyn.model.forces.ForceModel`, compiled over the variant axis
  (:func:`~mechdyn.kernels.rows_variants.body_loads_variants`); other loads those of
  :func:`~mechdyn.model.forces.applied_forces`, one call per variant over its
  positions (with the inertia forces of the bodies of all variants side by side); the
  joint reactions and frame loads those of :mod:`mechdyn.dynamics.reactions`
  (:func:`~mechdyn.dynamics.reactions.joint_reaction`,
  :func:`~mechdyn.dynamics.reactions.net_on_ground`), compiled
  (:func:`~mechdyn.kernels.rows_variants.loads_variants`), and the figures those of
  :func:`~mechdyn.study.analyses.extremes`, which
  :meth:`KinetostaticExtremes.figures <mechdyn.study.analyses.KinetostaticExtremes.figures>`
  applies to one record;
* when the weights are the only loads, the continuation, the inertia forces, the solve
  and the reactions of one variant after another are one compiled call
  (:func:`~mechdyn.kernels.rows_variants.cycle_variants`): a variant's Jacobians and
  factors stay in the processor's cache.

A variant the batch cannot finish -- its sketch does not assemble, its path meets a dead
or bifurcation position, a Newton step fails, its kinetostatic matrix is nearly
singular -- is returned as None: the caller analyses it on its own
(:func:`mechdyn.kinetostatics`), which gives its status and the message naming the
joints whose loop does not close.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..dynamics.reactions import joint_reaction, reaction_frame
from ..errors import Status
from ..kernels import rows_numba, rows_numpy
from ..kernels.rows_variants import (
    cycle_variants,
    inverse_variants,
    loads_variants,
    path_variants,
)
from ..kinematics.sweep import DEFAULT_MAX_STEP
from ..kinetostatics.prescribed import independent_subset
from ..mechanism.joint import has_friction
from ..model import Model
from ..model.forces import applied_forces
from ..model.inertia import inertia_forces
from ..results.kinetostatics_record import Kinetostatics
from ..results.records import KinetostaticsStats
from .analyses import KinetostaticExtremes, Outcome, extremes

__all__ = ["batched", "batch_reason", "kinetostatic_batch", "Variants"]

#: Newton iterations per step of the batched continuation
_MAX_NEWTON = 12
#: a first Newton step of at most _SHORT_STEP x its tolerance (1e-5 of the length scale) is
#: checked by the change of the Jacobian along it, without evaluating the residual
_SHORT_STEP = 1e7
#: pivot ratio min|u_ii| / max|u_ii| of a Jacobian below which a variant leaves the batch
#: (a dead, toggle or bifurcation position: the single-model analysis decides)
_MIN_PIVOT_RATIO = 1e-6
#: most variants whose cycle is solved in one call
_SUB_BATCH = 64
#: floats of the Jacobians and their factors kept for one call (the call's variants x
#: positions x n x n_x, twice): bounds its memory (32 MB)
_SUB_BATCH_FLOATS = 4_000_000
#: the compiled kernels have been loaded (or compiled) in this process
_WARM = {"done": False}


def _friction(model) -> bool:
    """True if a joint of the model has friction (not in the batched solve)."""
    return any(map(has_friction, model.mechanism.joints.values()))


def batched(analysis) -> bool:
    """Whether a study analyses variants with this analysis as one batch (when they
    allow it: :func:`batch_reason`).

    Parameters
    ----------
    analysis : object
        A study analysis (:mod:`mechdyn.study.analyses`).

    Returns
    -------
    bool
        True for a :class:`~mechdyn.study.analyses.KinetostaticExtremes` (exactly that
        type), the one analysis with a batched path.

    Examples
    --------
    >>> batched(KinetostaticExtremes("1000 rpm")), batched(len)
    (True, False)
    """
    return type(analysis) is KinetostaticExtremes


def batch_reason(analysis, models) -> str | None:
    """Why these compiled variants cannot be analysed as one batch (None: they can).

    The batch path takes a :class:`~mechdyn.study.analyses.KinetostaticExtremes` of
    variants with the bodies, joints, coordinates, loads and constraint rows of the
    first one, no switchable elements, no extension loads and no joint friction, and as
    many driven (or held) coordinates as coordinates.

    Parameters
    ----------
    analysis : object
        A study analysis (:func:`batched` decides first).
    models : sequence of Model
        The compiled variants.

    Returns
    -------
    str or None
        The first reason found, a sentence, or None when the batch can take them.

    Examples
    --------
    >>> from mechdyn.study.parameters import BaseModel
    >>> base = BaseModel("slider_crank")
    >>> m = base.compile({})
    >>> batch_reason(KinetostaticExtremes("1000 rpm"), [m, m]) is None
    True
    >>> from mechdyn.study.analyses import KinematicSummary
    >>> batch_reason(KinematicSummary(), [m])
    'the kinematics analysis is evaluated variant by variant'
    """
    if not batched(analysis):
        return f"the {getattr(analysis, 'name', type(analysis).__name__)} analysis is " \
               f"evaluated variant by variant"
    if not models:
        return "no variant to batch"
    base = models[0]
    key = _structure(base)
    for m in models:
        if m.has_switching:
            return "the model has switchable elements"
        if any(hasattr(ld, "generalized") for ld in m.mechanism.loads):
            return "the model has extension loads"
        if _friction(m):
            return "the model has joint friction"
        if getattr(m, "x0", None) is None:
            return "a variant has no assembled sketch"
        if _structure(m) != key:
            return "the variants do not share one structure"
    return None


def _structure(model) -> tuple:
    """What variants of one batch must share: names, load types, row integers."""
    lay = model.layout()
    ints = model.coordinate_rows.packed()[0], lay.rowset.packed()[0]
    return (model.body_names, model.joint_names, model.coordinate_names,
            tuple(type(ld).__name__ for ld in model.mechanism.loads),
            tuple(dr.coordinate for dr in model.mechanism.drives),
            lay.rowset.labels, tuple(a.tobytes() for a in ints),
            model.coord_is_angle.tobytes())


@dataclass
class Variants:
    """The numbers of V variants of one topology, stacked.

    Attributes
    ----------
    base : Model
        A compiled variant: the structure (names, rows' integers, layout, loads).
    rows, coords : ndarray, shape (V, n_rows, 9) and (V, n_q, 9)
        Packed floats of the constraint rows and of the coordinate rows.
    x_start : ndarray, shape (V, n_x)
        Start poses: the assembled sketches, or the sketches (the batch's first Newton
        solve assembles them at their own coordinates, as the compiler does).
    mass, inertia : ndarray, shape (V, n_bodies)
    com : ndarray, shape (V, n_bodies, 2)
    length_scale : ndarray, shape (V,)
    models : list of Model or None
        The compiled variants, whose loads are evaluated one by one; None: no loads but
        the weights under the base's gravity and the drives of the driven coordinates.

    Examples
    --------
    Two copies of the bundled slider-crank (three moving bodies: crank, rod, slider):

    >>> from mechdyn.study.parameters import BaseModel
    >>> m = BaseModel("slider_crank").compile({})
    >>> v = Variants.of_models([m, m])
    >>> len(v), v.mass.shape, v.com.shape, len(v.take(slice(0, 1)))
    (2, (2, 3), (2, 3, 2), 1)
    """

    base: Model
    rows: np.ndarray
    coords: np.ndarray
    x_start: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    com: np.ndarray
    length_scale: np.ndarray
    models: list | None = None

    @classmethod
    def of_models(cls, models) -> Variants:
        """The stacked numbers of compiled variants (:func:`batch_reason` accepted)."""
        return cls(models[0], np.stack([m.layout().rowset.packed()[1] for m in models]),
                   np.stack([m.coordinate_rows.packed()[1] for m in models]),
                   np.stack([m.x0 for m in models]),
                   np.stack([m.mass for m in models]), np.stack([m.inertia for m in models]),
                   np.stack([m.com for m in models]),
                   np.array([m.length_scale for m in models]),
                   list(models) if _own_loads(models) else None)

    def __len__(self) -> int:
        return self.rows.shape[0]

    def take(self, index) -> Variants:
        """The variants at ``index`` (a slice or an index array)."""
        models = None if self.models is None else list(np.asarray(self.models,
                                                                  dtype=object)[index])
        return replace(self, rows=self.rows[index], coords=self.coords[index],
                       x_start=self.x_start[index], mass=self.mass[index],
                       inertia=self.inertia[index], com=self.com[index],
                       length_scale=self.length_scale[index], models=models)


def _own_loads(models) -> bool:
    """True if the variants' applied forces are more than the weights under the first
    one's gravity (and the drives of the driven coordinates, replaced)."""
    g = models[0].gravity
    return bool(models[0].mechanism.loads) or any(np.any(m.gravity != g) for m in models)


class _SideBySide:
    """The moving bodies of V variants side by side as the bodies of one model (V n_b
    bodies): inertia forces and weights, body by body, need nothing else."""

    def __init__(self, v: Variants, gravity):
        self.mass, self.inertia = v.mass.reshape(-1), v.inertia.reshape(-1)
        self.com, self.gravity = v.com.reshape(-1, 2), np.asarray(gravity, float)
        self.n_bodies = self.mass.size
        self.n_x, self.n_q = 3 * self.n_bodies, 0


def _path_coordinates(q_start, values, held, max_step: float):
    """Each variant's path of driven coordinates: from its start (V, n_d) to the first
    position, then through the positions (N,), in steps of at most ``max_step``; and
    the indices of the positions in it.  Held coordinates (V, n_h) stay."""
    V = q_start.shape[0]
    lead = max(1, math.ceil(float(np.max(np.abs(values[0] - q_start[:, 0]))) / max_step))
    s = np.linspace(0.0, 1.0, lead + 1)
    first = q_start[:, :1] + s[None, :] * (values[0] - q_start[:, :1])  # (V, lead + 1)
    # within the positions: substeps where they are farther apart than max_step
    gaps = np.maximum(1, np.ceil(np.abs(np.diff(values)) / max_step).astype(int))
    k = np.repeat(np.arange(gaps.size), gaps)  # the interval of each substep
    j = np.arange(k.size) - np.repeat(np.cumsum(gaps) - gaps, gaps) + 1  # 1 .. gap
    inner = np.concatenate([values[:1], values[k] + np.diff(values)[k] * j / gaps[k]])
    keep = lead + np.concatenate([[0], np.cumsum(gaps)])
    drive = np.concatenate([first, np.broadcast_to(inner[1:], (V, inner.size - 1))], axis=1)
    Q = np.concatenate([drive[..., None],
                        np.broadcast_to(held[:, None, :], drive.shape + held.shape[1:])],
                       axis=-1)
    return np.ascontiguousarray(Q), keep


def kinetostatic_batch(variants, analysis: KinetostaticExtremes) -> list[Outcome | None]:
    """The outcome of the kinetostatic cycle of every variant, solved as one batch (see
    the module docstring); None for a variant the batch leaves to the single-model
    analysis.

    Parameters
    ----------
    variants : Variants or sequence of Model
        The variants' numbers, or compiled variants that :func:`batch_reason` accepts.
    analysis : KinetostaticExtremes

    Returns
    -------
    list of Outcome or None
        In the order of the variants; an Outcome's figures are those of
        :meth:`KinetostaticExtremes.figures` (its ``warm`` is None).

    Examples
    --------
    >>> from mechdyn.study.parameters import BaseModel
    >>> base = BaseModel("slider_crank")
    >>> p = base.parameter("bodies.rod.mass")
    >>> models = [base.compile({p: m}) for m in (1.0, 2.0)]
    >>> out = kinetostatic_batch(models, KinetostaticExtremes("1000 rpm", steps=36))
    >>> [round(o.figures["M_drive_phi_peak_Nm"], 3) for o in out]
    [21.053, 29.55]
    """
    if not isinstance(variants, Variants):
        variants = Variants.of_models(variants)
    n = variants.base.n_x
    size = max(1, min(_SUB_BATCH, _SUB_BATCH_FLOATS // (2 * analysis.steps * n * n)))
    out: list[Outcome | None] = []
    work: dict = {}
    for k in range(0, len(variants), size):
        part = variants.take(slice(k, k + size))
        if _WARM["done"]:
            out.extend(_cycle(part, analysis, work))
            continue
        with rows_numba.compiling("numba kernels of the batched study"):
            out.extend(_cycle(part, analysis, work))
        _WARM["done"] = True
    return out


def _scratch(work: dict, name: str, shape: tuple, dtype=float) -> np.ndarray:
    """An array of ``shape`` from the reusable memory ``work`` (its contents undefined):
    the calls of one batch share their large arrays instead of each mapping new ones."""
    size = math.prod(shape)
    a = work.get(name)
    if a is None or a.size < size or a.dtype != dtype:
        a = work[name] = np.empty(size, dtype=dtype)
    return a[:size].reshape(shape)


def _cycle(vs: Variants, analysis: KinetostaticExtremes, work: dict) -> list[Outcome | None]:
    """:func:`kinetostatic_batch` of one sub-batch (``work``: see :func:`_scratch`)."""
    base = vs.base
    V, nb, n_x = len(vs), base.n_bodies, base.n_x
    over, values = analysis.values(base)
    lay0 = base.layout()
    x_ref = base.x0 if getattr(base, "x0", None) is not None else base.x_sketch
    didx = np.asarray(independent_subset(base, lay0, x_ref, [base.coordinate_index(over)]),
                      dtype=int)
    n_rows, n_d = lay0.n_rows, len(didx)
    if n_rows + n_d != n_x or n_d != base.n_q:
        return [None] * V  # redundant, or coordinates neither driven nor held
    ints = np.ascontiguousarray(np.concatenate(
        [lay0.rowset.packed()[0], base.coordinate_rows.take(didx).packed()[0]]))
    flts = np.ascontiguousarray(np.concatenate([vs.rows, vs.coords[:, didx]], axis=1))
    # the coordinates of each variant's start: where it is assembled, and its held values
    q0 = rows_numpy.values(rows_numpy.variant_rows(base.coordinate_rows, vs.coords),
                           vs.x_start[:, None, :])[:, 0, :]
    Q, keep = _path_coordinates(q0[:, didx], values, q0[:, didx[1:]], DEFAULT_MAX_STEP)
    N, M = values.size, Q.shape[1]
    at = np.full(M, -1, dtype=np.int64)
    at[keep] = np.arange(N)
    dQ, ddQ = np.zeros((M, n_d)), np.zeros((M, n_d))
    dQ[keep, 0] = analysis.speed
    rows = _reaction_rows(base, lay0, x_ref, n_rows)
    if rows is None:
        return [None] * V
    joints, weight, group, cols, sign = rows
    X, Xd, Xdd, Z = (_scratch(work, k, (V, N, n_x)) for k in ("X", "Xd", "Xdd", "Z"))
    frame, Fj = _scratch(work, "frame", (V, N, 3)), _scratch(work, "Fj", (len(joints), V, N, 2))
    rc = _scratch(work, "rc", (V, N))
    ok = np.ones(V, dtype=bool)
    fail = np.empty(V, dtype=np.int64)
    path = (np.ascontiguousarray(vs.x_start), Q, dQ, ddQ, at, nb, ints, flts, n_rows,
            1e-12 * np.maximum(vs.length_scale, 1e-3), _MAX_NEWTON, _SHORT_STEP, _MIN_PIVOT_RATIO)
    loads = (weight, group, cols, sign)
    qd_dot = dQ[keep]
    t = (values - values[0]) / analysis.speed if analysis.speed != 0 else np.zeros(N)
    if vs.models is None:  # the weights alone: the whole cycle compiled, variant by variant
        cycle_variants(*path, np.ascontiguousarray(vs.mass), np.ascontiguousarray(vs.inertia),
                       np.ascontiguousarray(vs.com), np.asarray(base.gravity, float), *loads,
                       X, Xd, Xdd, Z, frame, Fj, rc, ok, fail)
        live = np.flatnonzero(ok)
        if live.size < V:
            X, Xd, Xdd, Z, frame, rc = (a[live] for a in (X, Xd, Xdd, Z, frame, rc))
            Fj = Fj[:, live]
        q, qdot = _prescribed(q0[live], values, qd_dot, didx)
    else:
        J, LU = _scratch(work, "J", (V, N, n_x, n_x)), _scratch(work, "LU", (V, N, n_x, n_x))
        piv = _scratch(work, "piv", (V, N, n_x), np.int64)
        path_variants(*path, X, Xd, Xdd, J, LU, piv, rc, ok, fail)
        live = np.flatnonzero(ok)
        if live.size < V:
            X, Xd, Xdd, J, LU, piv, rc, Z, frame = (
                a[live] for a in (X, Xd, Xdd, J, LU, piv, rc, Z, frame))
            Fj = Fj[:, live]
        if not live.size:
            return [None] * V
        q, qdot = _prescribed(q0[live], values, qd_dot, didx)
        rhs, F_ground = _rhs(vs.take(live), base, t, X, Xd, Xdd, q, qdot, didx)
        # C-contiguous whatever _rhs returns (a strided view or not): one specialization
        # of the kernel, the one mechdyn.warmup compiles
        inverse_variants(LU, piv, np.ascontiguousarray(rhs), n_rows, Z)
        loads_variants(X, J, Z, *loads, frame, Fj)
        frame += F_ground  # the frame's share of the loads (point of the moments: the origin)
    if not live.size:
        return [None] * V
    good = np.all(rc >= _MIN_PIVOT_RATIO, axis=1) & np.all(np.isfinite(Z), axis=(1, 2))
    reactions = {name: Fj[g] for g, name in enumerate(joints)}
    names = base.coordinate_names
    driven = {names[k]: Z[..., n_rows + c] for c, k in enumerate(didx)}
    rec = Kinetostatics(
        over=names[didx[0]], t=t, values=values, q=q, qdot=qdot, qddot=np.zeros_like(q),
        x=X, xdot=Xd, xddot=Xdd, coordinate_names=tuple(names),
        driven=tuple(names[k] for k in didx), reactions=reactions, moments={}, joint_frame={},
        joint_points={}, driving=driven,
        power={c: tau * qdot[..., names.index(c)] for c, tau in driven.items()},
        frame_force=frame[..., :2], frame_moment=frame[..., 2], frame_point=np.zeros(2),
        frame_loads={}, multipliers=Z[..., :n_rows], joint_kinds={}, mode=lay0.mode,
        redundant_joints=(), status=Status.SUCCESS, message="", warnings=(),
        stats=KinetostaticsStats(),
        model=base)

    def rms(y):  # the record's rule (Kinetostatics.rms): time-weighted, here at once
        if np.isfinite(y).all() and np.all(np.diff(t) > 0):
            return np.sqrt(np.trapezoid(y**2, t, axis=-1) / (t[-1] - t[0]))
        return np.array([Kinetostatics.rms(rec, row) for row in y])

    figs = extremes(rec, rec.driving, rec.power, rec.reactions, rec.frame_force,
                    rec.frame_moment, rms)
    keys = list(figs)
    table = np.column_stack([np.broadcast_to(np.asarray(figs[k], float), live.shape)
                             for k in keys])[good].tolist()  # Python floats, row by row
    out: list[Outcome | None] = [None] * V
    status = str(Status.SUCCESS)
    for v, row in zip(live[good].tolist(), table, strict=True):
        out[v] = Outcome(dict(zip(keys, row, strict=True)), status)
    return out


def _prescribed(q0, values, qd_dot, didx):
    """q and qdot (V, N, n_q) at the positions: every coordinate is driven or held, so
    they are the prescribed values (the held ones from each variant's start ``q0``)."""
    q = np.empty((q0.shape[0], values.size, q0.shape[1]))
    q[:] = q0[:, None, :]
    q[..., didx[0]] = values
    qdot = np.zeros_like(q)
    qdot[..., didx] = qd_dot
    return q, qdot


def _rhs(vs: Variants, base, t, X, Xd, Xdd, q, qdot, didx):
    """Inertia forces minus applied forces, (V, N, n_x), and the loads on the frame
    (V, N, 3), of variants with loads besides the weights: the bodies of all variants
    side by side as one model (:func:`~mechdyn.model.inertia.inertia_forces`) and
    each variant's loads (:func:`~mechdyn.model.forces.applied_forces`)."""
    V, N, n_x = X.shape

    def side(a):  # (V, N, n_x) -> (N, V n_x)
        return np.ascontiguousarray(a.transpose(1, 0, 2)).reshape(N, V * n_x)

    F_ground = np.zeros((V, N, 3))
    rhs = inertia_forces(_SideBySide(vs, base.gravity), side(X), side(Xd), side(Xdd))
    rhs = rhs.reshape(N, V, n_x).transpose(1, 0, 2)
    for i, m in enumerate(vs.models):
        F, F_ground[i], _ = applied_forces(m, t, X[i], Xd[i], q[i], qdot[i], skip_drives=didx)
        rhs[i] -= F
    return np.ascontiguousarray(rhs), F_ground


def _reaction_rows(base, lay, x, n_rows):
    """What :func:`~mechdyn.kernels.rows_variants.loads_variants` needs to give the joint
    reactions (on the child from the parent, as
    :func:`~mechdyn.dynamics.reactions.joint_reaction`) and what the frame receives
    from the joints to the ground and from the drives' stators (as ``batched_inverse``'s frame
    loads; they are linear in the forces on the bodies, so their sum is taken once):
    the joints, the rows' weights and groups, each joint's two columns and sign; None
    when a joint's reaction is not two columns of its rows' force (the variants are then
    left to the single-model analysis).

    A joint's force is two columns of ``-Phi_e,x^T lambda_e`` with a sign, which
    :func:`joint_reaction` tells by its answer to each unit column at a pose ``x``."""
    n_x = x.size
    joints = [n for n in base.joint_names if n in lay.rows]
    group = np.full(n_x, -1, dtype=np.int64)
    weight = np.zeros(n_x)
    weight[n_rows:] = 1.0  # the drives' stators: the driving torques on the poses
    cols = np.zeros((len(joints), 2), dtype=np.int64)
    sign = np.zeros(len(joints))
    probe = np.broadcast_to(x, (n_x, n_x))
    for g, name in enumerate(joints):
        idx = np.asarray(lay.rows[name])
        group[idx] = g
        f = joint_reaction(base, name, probe, np.eye(n_x))[0]  # (n_x, 2): its columns
        cols[g] = np.argmax(np.abs(f), axis=0)
        sign[g] = f[cols[g, 0], 0]
        select = np.zeros((n_x, 2))
        select[cols[g], [0, 1]] = sign[g]
        if abs(sign[g]) != 1.0 or not np.array_equal(f, select):
            return None
        if base.n_bodies in reaction_frame(base, name)[1:3]:
            weight[idx] = -1.0  # -Phi_e,x^T lambda_e: the joint's force on the bodies
    return joints, weight, group, cols, sign
