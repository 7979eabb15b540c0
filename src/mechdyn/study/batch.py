"""Variants of one topology evaluated as one batch: the kinetostatic cycle of V variants
with a variant axis through the rows, the position continuation and the solve.

Variants of one model file differ only in numbers (body points, masses, inertias,
loads, speeds).  Their constraint rows share the integers (which bodies) and each has
its own floats (:func:`mechdyn.kernels.rows_numpy.variant_rows`,
:mod:`mechdyn.kernels.rows_variants`), so that

* the continuation solves every variant's poses at one crank angle together (Newton
  on each variant's Jacobian, warm-started from the previous angle plus the tangent),
  keeping each variant's assembly branch by the sign of det J;
* the rates and accelerations, and the kinetostatic solve
  ``[-Phi_x^T, g_d,x^T] z = I - F`` of :func:`mechdyn.dynamics.reactions._inverse`
  (the same balanced units), are solved for every variant and position in one call;
* the applied and inertia forces are those of :mod:`mechdyn.dynamics.forces` and
  :mod:`mechdyn.dynamics.inertia` (one call per variant over all its positions), the
  joint reactions and frame loads those of :mod:`mechdyn.dynamics.reactions`, and
  the figures those of :meth:`KinetostaticExtremes.figures
  <mechdyn.study.analyses.KinetostaticExtremes.figures>` on a
  :class:`~mechdyn.Kinetostatics` record of each variant.

A variant the batch cannot finish -- its path meets a dead or bifurcation position, a
Newton step fails, its kinetostatic matrix is (nearly) singular -- is returned as None:
the caller analyses it on its own (:func:`mechdyn.kinetostatics`), which gives its
status and the message naming the joints whose loop does not close.
"""

from __future__ import annotations

import math

import numpy as np

from ..dynamics.forces import applied_forces
from ..dynamics.inertia import inertia_forces
from ..dynamics.prescribed_motion import _independent_subset
from ..dynamics.reactions import joint_reaction, net_on_ground, reaction_frame
from ..errors import Status
from ..kernels import rows_numpy
from ..kernels.rows_variants import inverse_variants, motion_variants, path_variants
from ..kinematics.sweep import DEFAULT_MAX_STEP
from ..results.kinetostatics_record import Kinetostatics
from .analyses import KinetostaticExtremes, Outcome

__all__ = ["batched", "batch_reason", "kinetostatic_batch", "MAX_NEWTON", "MIN_PIVOT_RATIO",
           "SUB_BATCH"]

#: Newton iterations per step of the batched continuation
MAX_NEWTON = 12
#: pivot ratio min|u_ii| / max|u_ii| of a Jacobian below which a variant leaves the batch
#: (a dead, toggle or bifurcation position: the single-model analysis decides)
MIN_PIVOT_RATIO = 1e-6
#: variants whose cycle is solved in one call (bounds the memory: the Jacobians of a
#: sub-batch are kept for the reactions, SUB_BATCH x steps x n x n_x floats)
SUB_BATCH = 64


def _friction(model) -> bool:
    """True if a joint of the model has friction (not in the batched solve)."""
    return any(getattr(j, f, 0.0) for j in model.mechanism.joints.values()
               for f in ("friction", "viscous"))


def batched(analysis) -> bool:
    """Whether a study analyses variants with this analysis as one batch (when they
    allow it: :func:`batch_reason`).

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
    inner = [values[:1]]
    for k, g in enumerate(gaps):
        inner.append(values[k] + (values[k + 1] - values[k]) * np.arange(1, g + 1) / g)
    inner = np.concatenate(inner)
    keep = lead + np.concatenate([[0], np.cumsum(gaps)])
    drive = np.concatenate([first, np.broadcast_to(inner[1:], (V, inner.size - 1))], axis=1)
    Q = np.concatenate([drive[..., None],
                        np.broadcast_to(held[:, None, :], drive.shape + held.shape[1:])],
                       axis=-1)
    return np.ascontiguousarray(Q), keep


def kinetostatic_batch(models, analysis: KinetostaticExtremes) -> list[Outcome | None]:
    """The outcome of the kinetostatic cycle of every variant, solved as one batch (see
    the module docstring); None for a variant the batch leaves to the single-model
    analysis.

    Parameters
    ----------
    models : sequence of Model
        Compiled variants that :func:`batch_reason` accepts.
    analysis : KinetostaticExtremes

    Returns
    -------
    list of Outcome or None
        In the order of ``models``; an Outcome's figures are those of
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
    out: list[Outcome | None] = []
    for k in range(0, len(models), SUB_BATCH):
        out.extend(_cycle(list(models[k:k + SUB_BATCH]), analysis))
    return out


def _cycle(models, analysis: KinetostaticExtremes) -> list[Outcome | None]:
    """:func:`kinetostatic_batch` of one sub-batch."""
    base = models[0]
    V, nb, n_x = len(models), base.n_bodies, base.n_x
    over, values = analysis.values(base)
    lay0 = base.layout()
    didx = np.asarray(_independent_subset(base, lay0, base.x0,
                                          [base.coordinate_index(over)]), dtype=int)
    n_rows, n_d = lay0.n_rows, len(didx)
    if n_rows + n_d != n_x or n_d != base.n_q:
        return [None] * V  # redundant, or coordinates neither driven nor held
    ints = np.ascontiguousarray(np.concatenate(
        [lay0.rowset.packed()[0], base.coordinate_rows.take(didx).packed()[0]]))
    cflts = np.stack([m.coordinate_rows.packed()[1] for m in models])
    flts = np.ascontiguousarray(np.concatenate(
        [np.stack([m.layout().rowset.packed()[1] for m in models]), cflts[:, didx]], axis=1))
    X0 = np.stack([m.x0 for m in models])
    # the coordinates of each variant's assembled sketch (its start and its held values)
    q0 = rows_numpy.values(rows_numpy.variant_rows(base.coordinate_rows, cflts),
                           X0[:, None, :])[:, 0, :]
    L = np.array([m.length_scale for m in models])
    Q, keep = _path_coordinates(q0[:, didx], values, q0[:, didx[1:]], DEFAULT_MAX_STEP)
    Xp = np.zeros(Q.shape[:2] + (n_x,))
    ok = np.ones(V, dtype=bool)
    fail = np.empty(V, dtype=np.int64)
    path_variants(X0, Q, nb, ints, flts, n_rows, 1e-12 * np.maximum(L, 1e-3), MAX_NEWTON,
                  MIN_PIVOT_RATIO, Xp, ok, fail)
    N = values.size
    qd = np.concatenate([np.broadcast_to(values[:, None], (N, 1)),
                         np.zeros((N, n_d - 1))], axis=1)  # (the held part per variant)
    qd_dot = np.zeros((N, n_d))
    qd_dot[:, 0] = analysis.speed
    qd_ddot = np.zeros((N, n_d))
    t = (values - values[0]) / analysis.speed if analysis.speed != 0 else np.zeros(N)
    live = np.flatnonzero(ok)
    if not live.size:
        return [None] * V
    X = np.ascontiguousarray(Xp[live][:, keep])
    fl = np.ascontiguousarray(flts[live])
    Xd, Xdd = np.empty_like(X), np.empty_like(X)
    J = np.empty(X.shape[:2] + (n_x, n_x))
    LU, piv = np.empty_like(J), np.empty(X.shape, dtype=np.int64)
    rc = np.empty(X.shape[:2])
    motion_variants(X, qd_dot, qd_ddot, nb, ints, fl, n_rows, Xd, Xdd, J, LU, piv, rc)
    rhs = np.empty_like(X)
    loads = []
    for i, v in enumerate(live):
        m = models[v]
        q = np.empty((N, base.n_q))
        q[:, didx] = qd
        q[:, didx[1:]] = q0[v, didx[1:]]
        qdot = np.zeros((N, base.n_q))
        qdot[:, didx] = qd_dot
        F, F_ground, _ = applied_forces(m, t, X[i], Xd[i], q, qdot, skip_drives=didx)
        rhs[i] = inertia_forces(m, X[i], Xd[i], Xdd[i]) - F
        loads.append((q, qdot, F_ground))
    Z = np.empty_like(X)
    inverse_variants(LU, piv, rhs, n_rows, Z)
    out: list[Outcome | None] = [None] * V
    good = np.all(rc >= MIN_PIVOT_RATIO, axis=1) & np.all(np.isfinite(Z), axis=(1, 2))
    reactions, frame = _reactions(base, lay0, X, J, Z, n_rows)
    names = base.coordinate_names
    for i, v in enumerate(live):
        if not good[i]:
            continue
        q, qdot, F_ground = loads[i]
        tau = Z[i, :, n_rows:]
        rec = Kinetostatics(
            over=names[didx[0]], t=t, values=values, q=q, qdot=qdot,
            qddot=np.zeros_like(q), x=X[i], xdot=Xd[i], xddot=Xdd[i],
            coordinate_names=tuple(names), driven=tuple(names[k] for k in didx),
            reactions={j: f[i] for j, f in reactions.items()}, moments={}, joint_frame={},
            joint_points={}, driving={names[k]: tau[:, c] for c, k in enumerate(didx)},
            power={names[k]: tau[:, c] * qdot[:, k] for c, k in enumerate(didx)},
            frame_force=frame[i, :, :2] + F_ground[:, :2], frame_moment=frame[i, :, 2]
            + F_ground[:, 2], frame_point=np.zeros(2), frame_loads={},
            multipliers=Z[i, :, :n_rows], joint_kinds={}, mode=lay0.mode, redundant_joints=(),
            status=Status.SUCCESS, message="", warnings=(), stats={}, model=models[v])
        fig = KinetostaticExtremes.figures(rec)
        out[v] = Outcome(fig.figures, fig.status, fig.message)
    return out


def _reactions(base, lay, X, J, Z, n_rows):
    """The joint reactions {joint: (V, N, 2)} N (on the child from the parent, as
    :func:`~mechdyn.dynamics.reactions.joint_reaction`), and what the frame receives
    from the joints to the ground and from the drives' stators, (V, N, 3): Fx, Fy (N)
    and the moment about the ground origin (N m) (as ``_inverse``'s frame loads)."""
    V, N, n_x = X.shape
    x = X.reshape(V * N, n_x)
    P = J[..., :n_rows, :].reshape(V * N, n_rows, n_x)
    lam = Z[..., :n_rows].reshape(V * N, n_rows)
    point = np.zeros(2)
    # the drives' stators: the driving torques on the poses, D = g_d,x^T tau
    D = np.einsum("nd,ndx->nx", Z[..., n_rows:].reshape(V * N, -1),
                  J[..., n_rows:, :].reshape(V * N, -1, n_x))
    frame = net_on_ground(base, x, D, point)
    reactions = {}
    for name in (n for n in base.joint_names if n in lay.rows):
        idx = lay.rows[name]
        gen = -np.einsum("nrx,nr->nx", P[:, idx, :], lam[:, idx])
        # the force does not depend on the joint point (the base's serves every variant)
        f, _, _ = joint_reaction(base, name, x, gen)
        reactions[name] = f.reshape(V, N, 2)
        if base.n_bodies in reaction_frame(base, name)[1:3]:
            frame = frame + net_on_ground(base, x, gen, point)
    return reactions, frame.reshape(V, N, 3)

