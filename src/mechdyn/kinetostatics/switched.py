"""Kinetostatics of a switched (variable-structure) trajectory, segment by segment.

The samples are split into segments of constant recorded mode; each segment is the
kinetostatics of its mode (:func:`~mechdyn.kinetostatics.mode._kinetostatics`
on the rows of the forward dynamics, :meth:`~mechdyn.model.switchable.SwitchedModel.rows`,
with the values the locks held in the run), driving the independent coordinates of the
mode; the segments are concatenated into one record, NaN where a joint, drive or
element is not part of a sample's mode.  The rules are stated in
``docs/kinetostatics.md``, section "Switched trajectories".
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from ..dynamics.mode_system import fmt_mode
from ..errors import MechdynError, Status
from ..friction.forward import capture_stick, split_mode, stick_row
from ..model import ConstraintLayout, Model
from ..model.forces import force_model
from ..model.state import stick_key
from ..model.switchable import SwitchedModel, mode_friction, mode_locks, switched_model
from ..results.kinetostatics_record import Kinetostatics
from ..results.records import KinetostaticsStats, SegmentStats
from .mode import MESSAGES, _kinetostatics

__all__ = ["kinetostatics_switched"]


def _mode_rows(model: Model, sm: SwitchedModel, mode: frozenset, x0, first):
    """(layout, candidates) of a mode whose first pose is ``x0``: the rows of
    the forward dynamics (:meth:`SwitchedModel.rows`, and the stick rows of the pairs
    that stick, :func:`~mechdyn.friction.forward.stick_row`), the locks and
    sticking pairs holding what they held, and the order in which coordinates are tried
    as driven (``first``, the others, and last those the mode's locks free)."""
    targets: dict = {}
    base, jstates = split_mode(model, mode)  # the joints' stick-slip states apart
    sticks = [stick_key(c) for c, s in mode_friction(base).items() if s == "stick"]
    for n in [*mode_locks(base), *sticks]:
        sm.capture_target(n, x0, targets)
    held = sorted(j for j, s in jstates.items() if s == "stick")
    for j in held:  # a sticking pair is held at its travel or angle where it stuck
        capture_stick(model, j, x0, targets)
    extra = sm.rows(base, targets) + [stick_row(model, j, targets) for j in held]
    # (the mode's joint friction states, kept with the layout, give the slip directions)
    lay = ConstraintLayout(model, mode, extra) if extra or jstates else model.layout(frozenset())
    late = {model.coordinate_index(f) for n in mode_locks(mode) for f in sm.lock_frees(n)
            if f in model.coordinate_names}
    return lay, sorted(dict.fromkeys([*first, *range(model.n_q)]), key=late.__contains__)


def kinetostatics_switched(model: Model, trajectory, vs, *, over=None,
                           point=(0.0, 0.0), model_drives="replace",
                           reacting_loads=()) -> Kinetostatics:
    """Kinetostatics of a switched trajectory (called by
    :func:`mechdyn.kinetostatics.inverse.kinetostatics`; see the module docstring)."""
    t_start = time.perf_counter()
    names = model.coordinate_names
    tt = np.asarray(trajectory.t, dtype=float).reshape(-1)
    n = tt.size
    if n == 0:
        raise ValueError("no positions to analyse")
    if len(vs.mode) != n:
        raise ValueError("the trajectory's variable_structure record does not match its "
                         f"samples ({len(vs.mode)} modes for {n} samples)")
    Q, Qd, Qdd = (np.asarray(getattr(trajectory, a), dtype=float).reshape(n, model.n_q)
                  for a in ("q", "qdot", "qddot"))
    X = getattr(trajectory, "x", None)
    if np.shape(X) != (n, model.n_x):
        raise ValueError("a switched trajectory needs its body poses x (n, n_x) to be "
                         "analysed mode by mode")
    X = np.asarray(X, dtype=float)
    if over is not None and not isinstance(over, str):
        raise ValueError("over= names one coordinate for a switched trajectory (the driven "
                         "coordinates are the independent ones of each mode)")
    over_k = None if over is None else model.coordinate_index(over)
    sm = switched_model(model)
    first = ([] if over_k is None else [over_k]) + [k for _, k in force_model(model).drives]
    sample_modes = tuple(frozenset(m) for m in vs.mode)
    modes = tuple(dict.fromkeys(sample_modes))
    mode_index = np.array([modes.index(m) for m in sample_modes], int)

    parts = []
    cuts = [0, *(np.flatnonzero(np.diff(mode_index)) + 1).tolist(), n]
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        mode = sample_modes[a]
        seg = SimpleNamespace(t=tt[a:b], q=Q[a:b], qdot=Qd[a:b], qddot=Qdd[a:b], x=X[a:b])
        try:
            lay, candidates = _mode_rows(model, sm, mode, X[a], first)
            res = _kinetostatics(model, trajectory=seg, point=point, model_drives=model_drives,
                                 reacting_loads=reacting_loads, lay=lay, candidates=candidates,
                                 x_guess=X[a])
            parts.append((a, b, mode, res, None))
        except (MechdynError, np.linalg.LinAlgError) as exc:
            parts.append((a, b, mode, None, exc))

    done = [p[3] for p in parts if p[3] is not None]
    if over_k is None:
        over_k = names.index(done[0].driven[0]) if done and done[0].driven else 0

    # ------------------------------------------------------------ concatenation
    def nan(*tail):
        return np.full((n, *tail), np.nan)

    def merged(attr, keys, *tail):
        """Per key, the series of record attribute ``attr`` of every segment (NaN elsewhere)."""
        out = {k: nan(*tail) for k in keys}
        for a, b, _, r, _ in parts:
            for k, v in (getattr(r, attr).items() if r is not None else ()):
                out[k][a:b] = v
        return out

    tx = getattr(trajectory, "xdot", None)
    arrays = dict(q=Q.copy(), qdot=Qd.copy(), qddot=Qdd.copy(), x=X.copy(),
                  xdot=np.array(tx, dtype=float) if np.shape(tx) == (n, model.n_x)
                  else nan(model.n_x), xddot=nan(model.n_x), frame_force=nan(2),
                  frame_moment=nan())
    multipliers = nan(max([r.multipliers.shape[1] for r in done], default=0))
    driven = [c for c in names if any(c in r.driven for r in done)]
    joints = [j for j in model.joint_names if any(j in r.reactions for r in done)]
    loads = dict.fromkeys(k for r in done for k in r.frame_loads)
    elements = dict.fromkeys(e for r in done for e in r.element_forces)
    series = {attr: merged(attr, keys, *tail) for attr, keys, *tail in (
        ("reactions", joints, 2), ("moments", joints), ("joint_frame", joints, 2),
        ("joint_points", joints, 2), ("driving", driven), ("power", driven),
        ("frame_loads", loads, 3), ("element_forces", elements),
        ("losses", dict.fromkeys(k for r in done for k in r.losses)))}
    friction = any(r.losses for r in done)
    if friction:
        arrays.update(power_out=nan(), locked=np.zeros(n, dtype=bool))
    warn: list[str] = []
    notes: list[str] = []
    seg_stats = []
    for a, b, mode, r, exc in parts:
        span = dict(mode=mode, start=a, stop=b, t_start=float(tt[a]), t_end=float(tt[b - 1]))
        if r is None:
            seg_stats.append(SegmentStats(**span, driven=(), status=f"not analysed: {exc}"))
            warn.append(f"samples {a}..{b - 1} (t = {tt[a]:.6g} .. {tt[b - 1]:.6g} s, mode "
                        f"{fmt_mode(mode)}) could not be analysed ({type(exc).__name__}: {exc}); "
                        f"their forces are NaN")
            continue
        for k, v in arrays.items():
            got = getattr(r, k)
            v[a:b] = got if got is not None else (False if k == "locked" else np.nan)
        multipliers[a:b, :r.multipliers.shape[1]] = r.multipliers
        warn.extend(w for w in (f"mode {fmt_mode(mode)}: {w}" for w in r.warnings) if w not in warn)
        notes.extend(nt for nt in r.message.split("; ")[1:] if nt not in notes)
        seg_stats.append(SegmentStats(**span, driven=r.driven, status=r.status,
                                      power_balance_rel=r.stats.power_balance_rel,
                                      rcond_min=r.stats.rcond_min))

    statuses = {Status.PARTIAL if r is None else r.status for *_, r, _ in parts}
    status = next((s for s in (Status.PARTIAL, Status.SELF_LOCKING, Status.SINGULAR_POSITION,
                               Status.REDUNDANT)
                   if s in statuses), Status.SUCCESS)
    head = (f"{MESSAGES[status]} for a switched trajectory: {len(parts)} segment(s) in "
            f"{len(modes)} mode(s)")
    over_done = {key: agg([getattr(r.stats, key) for r in done] or [empty])
                 for key, agg, empty in (
                     ("position_solves", sum, 0), ("power_balance_rel", max, np.nan),
                     ("rcond_min", min, np.nan), ("redundant_equations", max, 0),
                     ("singular_positions", sum, 0))}
    stats = KinetostaticsStats(positions=n, segments=tuple(seg_stats),
                               seconds=time.perf_counter() - t_start, **over_done)
    return Kinetostatics(
        over=names[over_k], t=tt, values=arrays["q"][:, over_k].copy(), **arrays, **series,
        multipliers=multipliers, coordinate_names=tuple(names), driven=tuple(driven),
        frame_point=np.asarray(point, dtype=float).copy(),
        joint_kinds={j: r.joint_kinds[j] for r in done for j in r.reactions},
        mode=frozenset().union(*sample_modes),
        redundant_joints=tuple(sorted({j for r in done for j in r.redundant_joints})),
        status=status, message="; ".join([head, *notes]), warnings=tuple(warn), stats=stats,
        model=model, element_units={e: r.element_units.get(e, "N") for r in done
                                    for e in r.element_forces},
        sample_modes=sample_modes, mode_index=mode_index, modes=modes)
