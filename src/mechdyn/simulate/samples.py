"""The samples of a run: recorded as it goes, evaluated and handed over as a Trajectory.

Each sample of the segment loop (:func:`mechdyn.simulate.segments.simulate_events`) is the
time, the mode system, the evaluation (poses, rates, every coordinate and multiplier),
the integrated work and the impact losses so far (:class:`Samples`).  The forces of
every element, the loads on the frame and the energies are evaluated from them batched
over each mode's samples -- at the end of the run (:func:`finish`) or, with a ``sink``,
chunk by chunk as they come -- into the run's
:class:`~mechdyn.results.trajectory.Trajectory`.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..dynamics.lagrange import kinetic_energy
from ..dynamics.reactions import element_forces, element_width, frame_forces, net_on_ground
from ..errors import ModelError, Status
from ..friction.law import friction_joints
from ..kernels import rows_numpy as RN
from ..kernels.planar import cross
from ..results.lazy_table import LazyDict
from ..results.records import RunCounters, RunStats, StreamedStats
from ..results.trajectory import SwitchedSamples, Trajectory
from .gaps import gaps
from .impact import frame_impulse_key

__all__ = ["Samples", "finish", "element_shapes"]


def element_shapes(model, sm) -> dict:
    """Every element that can carry a force in some mode, with the trailing shape of its
    force: joints (2,) or (3,), coordinate locks, stops and contacts () (see
    :func:`~mechdyn.dynamics.reactions.element_forces`)."""
    out: dict = {j: (element_width(model, j),) for j in model.mechanism.joints}
    for names in (sm.coord_locks, sm.stops, sm.contacts):
        out.update({n: () for n in names if n not in out})
    return out


class Samples:
    """The samples of a run as they are recorded, and their hand-over in chunks.

    Each sample is ``(t, mode system, evaluation, (w_nc[, w_f]), impact losses so far)``.  Without
    a ``sink`` they are all kept and evaluated at the end (:func:`finish`).  With a
    ``sink``, every ``chunk`` samples are evaluated (forces, frame loads and energies,
    batched over each mode's samples: the numbers of the end-of-run table) into a partial
    :class:`~mechdyn.results.trajectory.Trajectory` that is handed to ``sink(part, start)``
    (``start``: the index of its first row in the run) and, unless ``keep``, dropped; its
    force columns cover every element of the model from the first chunk on (zeros while
    an element is not engaged).

    Parameters
    ----------
    model, sm
        The compiled model and its switchable elements.
    point : (2,) m
        The point of the frame moment.
    sink : callable, optional
    chunk : int
        Samples per chunk (>= 1).
    keep : bool
        Keep every chunk for the Trajectory returned (else it holds the last chunk, and
        ``stats.streamed`` (:class:`~mechdyn.results.records.StreamedStats`) the run's
        row count, first time, energy drift and largest constraint residual).

    Raises
    ------
    ModelError
        ``chunk`` is not a positive integer.
    """

    def __init__(self, model, sm, point, *, sink=None, chunk: int = 2000, keep: bool = True):
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise ModelError(f"chunk must be a positive number of samples, got {chunk!r}")
        self.model, self.sm, self.point = model, sm, np.asarray(point, float)
        self.sink, self.chunk, self.keep = sink, int(chunk), keep or sink is None
        self.state: tuple = (0, [])  # (samples handed over, samples waiting): set at once
        self.last = None  # the last sample recorded (also once handed over)
        self.modes: list = []  # the modes in the order they appeared, over the whole run
        self.blocks: list = []
        self.shapes = element_shapes(model, sm) if sink is not None else None
        self.streamed: StreamedStats | None = None
        self.penetration = 0.0

    def append(self, sample, stats: RunCounters) -> None:
        """Record a sample; hand a full chunk to the sink."""
        self.state[1].append(sample)
        self.last = sample
        if self.sink is not None and len(self.state[1]) >= self.chunk:
            self.flush(stats)

    def flush(self, stats: RunCounters) -> None:
        """Evaluate the waiting samples and hand them to the sink."""
        start, rows = self.state
        if not rows:
            return
        block = _block(self.model, self.sm, rows, self.point, self.modes, self.shapes)
        self.sink(_trajectory(self.model, block, self.modes, [], RunStats(mode=stats.mode),
                              Status.SUCCESS, ""), start)
        self.state = (start + len(rows), [])
        bal, res = block["balance"], block["residual"]
        s = self.streamed or StreamedStats(0, float(block["t"][0]), float(bal[0]), 0.0, 0.0)
        self.streamed = s.joined(len(rows), float(np.max(np.abs(bal - s.balance0))),
                                 float(np.max(res)))
        self.penetration = max(self.penetration, block["penetration"])
        self.blocks = [*self.blocks, block] if self.keep else [block]


def _block(model, sm, rec, point, modes: list, shapes=None) -> dict:
    """Forces, frame loads and energies of samples ``rec``, batched over each mode's
    samples; ``modes`` (the run's modes so far) is extended by the new ones; ``shapes``
    (element -> trailing shape) makes a force entry of every element listed."""
    n = len(rec)
    t, W, W_f, lost, x, xd, q, qd, qdd = _motion(model, rec)
    frame, res, p_f = np.zeros((n, 3)), np.zeros(n), np.zeros(n)
    forces: dict = {el: np.zeros((n, *shape)) for el, shape in (shapes or {}).items()}
    starts = [k for k in range(n) if k == 0 or rec[k][1] is not rec[k - 1][1]] + [n]
    # the frame also carries the load elements anchored on it (spring ends, torque
    # reactions) and the stators of the drives between it and the bodies: the loads do not
    # depend on the mode, so they are evaluated over every sample at once
    _, on_ground, Qd = sm.fm.loads(t, x, xd, q, qd)
    on_ground[:, 2] -= cross(point, on_ground[:, :2])  # about P
    drives = np.einsum("nqx,nq->nx", RN.jacobian(model.coordinate_rows, x), Qd)
    stators = net_on_ground(model, x, drives, point)
    for a, b in zip(starts[:-1], starts[1:], strict=True):
        ms, sl = rec[a][1], slice(a, b)
        lam = np.array([r[2].lam for r in rec[a:b]], float).reshape(b - a, ms.n_rows)
        parts = RN.Parts(ms.rowset, x[sl])  # the rows' Jacobian and values share them
        R = RN.jacobian(ms.rowset, x[sl], parts)
        frame[sl] = (frame_forces(ms, x[sl], lam, point=point, R=R)["total"] + on_ground[sl]
                     + stators[sl])
        pairs = None
        if ms.friction is not None:
            # the friction of the pairs: a pair between two bodies adds no net force or
            # moment to them, so the net of the friction on the bodies is that of the
            # pairs with the frame, whose opposite the frame receives
            Ff = np.array([r[2].F_friction for r in rec[a:b]], float).reshape(b - a, model.n_x)
            frame[sl] += net_on_ground(model, x[sl], Ff, point)
            p_f[sl] = -np.einsum("nx,nx->n", Ff, xd[sl])  # the power friction dissipates
            pairs = ms.friction.by_pair(x[sl], xd[sl], lam)  # part of their reactions
        for el, v in element_forces(ms, x[sl], lam, pairs, R=R).items():
            forces.setdefault(el, np.zeros((n,) + np.shape(v)[1:]))[sl] = v
        if ms.n_rows:
            res[sl] = np.max(np.abs(RN.values(ms.rowset, x[sl], parts)), axis=-1)
    mode_index = _modes(rec, modes)
    # the bodies, plus the rotors and gears of the drives reduced to their coordinates
    T = kinetic_energy(model, x, xd) + 0.5 * (qd**2) @ sm.drive_inertia
    U = sm.fm.potential_energy(x)
    return dict(t=t, q=q, qdot=qd, qddot=qdd, x=x, xdot=xd, frame=frame, forces=forces,
                mode=[r[1].mode for r in rec], mode_index=mode_index,
                kinetic=T, potential=U, work_nc=W, work_friction=W_f, power_friction=p_f,
                balance=T + U - W + lost, residual=res,
                impact_losses=lost, penetration=_penetration(sm, x))


def _motion(model, rec) -> tuple:
    """The columns of samples ``rec`` that they hold: t, W_nc, W_f, the impact losses, x,
    x', q, q', q''."""
    n_q, n_x, n = model.n_q, model.n_x, len(rec)
    t = np.array([r[0] for r in rec], float)
    W = np.array([r[3][0] for r in rec], float)
    W_f = np.array([r[3][1] if len(r[3]) > 1 else 0.0 for r in rec], float)
    lost = np.array([r[4] for r in rec], float)
    x, xd, q, qd, qdd = (np.array([getattr(r[2], k) for r in rec], float).reshape(n, w)
                         for k, w in (("x", n_x), ("xdot", n_x), ("q", n_q), ("qdot", n_q),
                                      ("qddot", n_q)))
    return t, W, W_f, lost, x, xd, q, qd, qdd


def _modes(rec, modes: list) -> np.ndarray:
    """The index of each sample's mode in ``modes``, extended by the new ones."""
    for r in rec:
        if r[1].mode not in modes:
            modes.append(r[1].mode)
    return np.array([modes.index(r[1].mode) for r in rec], int)


def _penetration(sm, x) -> float:
    """The largest penetration of a stop (lengths only) or contact at the poses x, m."""
    pen = [float(np.max(-g)) for g, angle in gaps(sm, x).values() if not angle] if len(x) \
        else []
    return max([0.0, *pen])


def _joined(blocks: list) -> dict:
    """The blocks of a run as one block (rows in order)."""
    if len(blocks) == 1:
        return blocks[0]
    out = {k: np.concatenate([b[k] for b in blocks]) for k in blocks[0]
           if isinstance(blocks[0][k], np.ndarray)}
    out["mode"] = [m for b in blocks for m in b["mode"]]
    out["forces"] = {el: np.concatenate([b["forces"][el] for b in blocks])
                     for el in blocks[0]["forces"]}
    out["penetration"] = max(b["penetration"] for b in blocks)
    return out


def _trajectory(model, block, modes, events, stats: RunStats, status,
                message) -> Trajectory:
    """The Trajectory of an evaluated block of samples."""
    b = block
    stats = replace(stats, penetration=b["penetration"], variable_structure=SwitchedSamples(
        mode=b["mode"], modes=list(modes), mode_index=b["mode_index"],
        impact_losses=b["impact_losses"], penetration=b["penetration"],
        loads=dict(frame_force=b["frame"][:, :2], frame_moment=b["frame"][:, 2],
                   forces=b["forces"])))
    return Trajectory(b["t"], b["q"], b["qdot"], b["qddot"], b["x"], b["xdot"],
                      status=status, message=message, events=list(events), stats=stats,
                      energy=_energy(bool(friction_joints(model)), b),
                      coordinate_names=model.coordinate_names, body_names=model.body_names,
                      coordinate_is_angle=tuple(bool(v) for v in model.coord_is_angle),
                      model=model)


def finish(model, rec: Samples, events, stats: RunCounters, wall0, status, message, sm,
            point=(0.0, 0.0)) -> Trajectory:
    """The Trajectory of a run from its samples: forces, frame loads and energies are
    evaluated here (or chunk by chunk as they were handed to the sink), batched over the
    samples of each mode segment."""
    point = np.asarray(point, float)
    streamed = None
    if rec.sink is not None:
        rec.flush(stats)
        blocks = rec.blocks
        if rec.streamed is not None and not rec.keep:
            streamed = rec.streamed
    key = frame_impulse_key(sm)
    for ev in events:  # the frame's impulse of an impact: its angular part about the point
        if key in ev.impulses:
            f = np.array(ev.impulses[key], float)
            f[2] -= cross(point, f[:2])
            ev.impulses[key] = f
    if rec.sink is None:  # forces, frame loads and energies: evaluated on first use
        done = stats.freeze(wall_time_s=time.perf_counter() - wall0)
        return _lazy_trajectory(model, sm, rec.state[1], point, rec.modes, events, done,
                                status, message)
    if not blocks:  # nothing recorded
        blocks = [_block(model, sm, [], point, rec.modes)]
    block = _joined(blocks)
    if rec.sink is not None:
        block["penetration"] = max(rec.penetration, block["penetration"])
    done = stats.freeze(wall_time_s=time.perf_counter() - wall0, streamed=streamed)
    return _trajectory(model, block, rec.modes, events, done, status, message)


class _Table:
    """The evaluation of samples ``rec`` (:func:`_block`), made on first use and kept (an
    error is raised again at the next use)."""

    def __init__(self, model, sm, rec, point, modes):
        self._args, self._block = (model, sm, rec, point, list(modes)), None
        self.friction = bool(friction_joints(model))

    def block(self) -> dict:
        if self._block is None:
            model, sm, rec, point, modes = self._args
            self._block = _block(model, sm, rec, point, modes)
            self._args = None  # the samples: no longer needed
        return self._block

    def energy(self) -> dict:
        return _energy(self.friction, self.block())

    def frame_and_forces(self) -> dict:
        b = self.block()
        return dict(frame_force=b["frame"][:, :2], frame_moment=b["frame"][:, 2],
                    forces=b["forces"])


def _energy(friction: bool, b: dict) -> dict:
    """The energy columns of a block."""
    energy = {k: b[k] for k in ("kinetic", "potential", "work_nc", "balance", "residual")}
    if friction:
        energy.update(work_friction=b["work_friction"], power_friction=b["power_friction"])
    return energy


def _lazy_trajectory(model, sm, rec, point, modes, events, stats: RunStats, status,
                     message) -> Trajectory:
    """The Trajectory of samples ``rec`` with its forces, frame loads and energies
    evaluated on first use (the numbers of :func:`_block`): the motion and the modes
    now."""
    t, _, _, lost, x, xd, q, qd, qdd = _motion(model, rec)
    mode_index = _modes(rec, modes)
    table = _Table(model, sm, rec, point, modes)
    pen = _penetration(sm, x)
    stats = replace(stats, penetration=pen, variable_structure=SwitchedSamples.lazy(
        table.frame_and_forces, mode=[r[1].mode for r in rec], modes=list(modes),
        mode_index=mode_index, impact_losses=lost, penetration=pen))
    return Trajectory(t, q, qd, qdd, x, xd, status=status, message=message,
                      events=list(events), stats=stats, energy=LazyDict.lazy(table.energy),
                      coordinate_names=model.coordinate_names, body_names=model.body_names,
                      coordinate_is_angle=tuple(bool(v) for v in model.coord_is_angle),
                      model=model)
