"""What happens at a switching instant of a variable-structure run, and what is watched
for it.

:func:`event_functions` lists the event functions of a mode (switch conditions and
schedules, gaps of open stops and contacts, forces of closed ones, the friction cone
of a sticking contact, the slip velocity of a slipping one); :func:`apply_switch`
applies the events fired at one instant: releases, engagements (the held value
captured), the impact (:func:`mechdyn.simulate.impact.impact`), the new mode by
complementarity (:func:`mechdyn.simulate.gaps.resolve_mode`), its coordinates,
and an :class:`~mechdyn.integrate.events.EventRecord` per thing that happened.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field

import numpy as np

from ..dynamics.mode_system import ModeSystem, held_key, mode_system
from ..errors import AssemblyError
from ..friction.forward import joint_states, stick_slip_joints
from ..friction.stick_slip import resolve_joints, state_tokens
from ..integrate.events import EventRecord
from ..integrate.segment import EventFunction
from ..kernels import rows_numpy
from ..kernels.rows_numba import NUMBA, rows_values
from ..model.rows import concat
from ..model.state import contact_token
from ..model.switchable import (
    Measure,
    SwitchedModel,
    TimeMeasure,
    mode_friction,
    mode_locks,
    mode_unilateral,
)
from .gaps import gap_measures, resolve_mode, touching
from .impact import impact

__all__ = ["event_functions", "guard_holds", "apply_switch"]


def _value(meas, t, x, xd):
    """A switch's or guard's variable at a state: the time, a pose measure or a rate."""
    if isinstance(meas, TimeMeasure):
        return t
    return meas.value(x, xd)


class _PoseValues:
    """The values m(x) of the one-row measures a mode's event functions read (gaps, switch
    variables of the pose), all rows evaluated together once per evaluation ``ev``: at a
    step end every gap and switch function reads the same ``ev`` (m or rad).  With numba,
    by the compiled row evaluator (a few microseconds where the NumPy one, built for
    batches of poses, takes some 40)."""

    def __init__(self, nb: int, measures):
        self.index: dict[int, int] = {}
        rows = []
        for m in measures:
            if type(m) is Measure and id(m) not in self.index:
                self.index[id(m)] = len(rows)
                rows.append(m.rows)
        self.rows = concat(nb, *rows) if rows else None  # None: no measure to evaluate
        self._packed = (nb, *self.rows.packed()) if NUMBA and rows else None
        self._ev, self._vals = None, np.zeros(len(rows))

    def value(self, m, ev) -> float:
        """m(ev.x) of a measure of the batch (else from the measure itself)."""
        k = self.index.get(id(m))
        if k is None:
            return m.value(ev.x)
        if ev is not self._ev:
            if self._packed is not None:
                rows_values(np.asarray(ev.x, float), *self._packed, self._vals, 0)
            else:
                self._vals = rows_numpy.values(self.rows, ev.x)
            self._ev = ev
        return float(self._vals[k])


def _row(ms: ModeSystem, element: str, kind: str) -> int:
    """Index into the mode's rowset of the row of ``kind`` of a contact."""
    return next(ms.n_base + k for k, r in enumerate(ms.rows)
                if r.element == element and r.kind == kind)


def event_functions(sm: SwitchedModel, ms: ModeSystem, t, fired_once, force_scale, gap_tol,
                     L) -> list[EventFunction]:
    out: list[EventFunction] = []
    locks = mode_locks(ms.mode)
    gap_list = list(gap_measures(sm))
    pv = _PoseValues(sm.nb, [m for _, m, _, _ in gap_list]
                     + [m for _, m, _ in sm.switches if m is not None])
    for sw, meas, _guards in sm.switches:
        if sw.name in fired_once:
            continue
        if sw.action == "engage" and sw.target in locks:
            continue
        if sw.action == "release" and sw.target not in locks:
            continue
        if sw.is_scheduled:
            nxt = [tc for tc in sw.times if tc >= t and (sw.name, tc) not in fired_once]
            if nxt:
                out.append(EventFunction("time", sw.name, lambda tt, ev, tc=nxt[0]: tc - tt,
                                         0.0, (sw, nxt[0])))
            continue
        scale = 1.0 if isinstance(meas, TimeMeasure) or meas.is_angle else L
        for d in ((1, -1) if sw.direction == 0 else (sw.direction,)):
            # rising (d > 0) fires when value - v crosses zero upwards: watched as v - value
            def fn(tt, ev, m=meas, v=sw.value, d=d):
                if id(m) in pv.index:
                    return d * (v - pv.value(m, ev))
                return d * (v - _value(m, tt, ev.x, ev.xdot))
            out.append(EventFunction("switch", sw.name, fn, np.inf, (sw, d),
                                     arm=1e-11 * (abs(sw.value) + scale)))
    closed = set(mode_unilateral(ms.mode))
    # open stops and contacts: gaps
    for tok, meas, sgn, lim in gap_list:
        if tok not in closed:
            tol = gap_tol / L if meas.is_angle else gap_tol
            out.append(EventFunction("gap", tok, lambda tt, ev, m=meas, lim=lim, s=sgn:
                                     s * (pv.value(m, ev) - lim), tol, arm=1e-3 * tol))
    # closed ones: forces; the friction cone of sticking contacts, the slip of slipping ones
    for k, r in enumerate(ms.rows):
        if r.unilateral:
            out.append(EventFunction("force", r.label, lambda tt, ev, i=ms.n_base + k: ev.lam[i],
                                     1e-7 * force_scale, arm=1e-10 * force_scale))
    out += _joint_events(ms, force_scale, L)
    for c, s in mode_friction(ms.mode).items():
        if c not in sm.contacts:  # a joint's friction state: _joint_events
            continue
        ct, _, slip = sm.contacts[c]
        if s == "stick":
            kn, kt = _row(ms, c, "contact"), _row(ms, c, "stick")
            out.append(EventFunction("cone", c, lambda tt, ev, kn=kn, kt=kt, mu=ct.friction:
                                     mu * ev.lam[kn] - abs(ev.lam[kt]), 1e-7 * force_scale,
                                     arm=1e-10 * force_scale))
        else:
            sg = 1.0 if s == "slip+" else -1.0
            out.append(EventFunction("slip", c, lambda tt, ev, m=slip, sg=sg:
                                     sg * m.rate(ev.x, ev.xdot), np.inf, arm=1e-12 * L))
    return out


def _joint_events(ms: ModeSystem, force_scale, L) -> list[EventFunction]:
    """The events of the stick-slip pairs (:mod:`mechdyn.friction.forward`): the
    friction needed to hold a sticking pair reaching its capacity mu S (``"cone"``), the
    sliding velocity of a slipping one falling to zero (``"slip"``)."""
    jf, out = ms.friction, []
    if jf is None:
        return out
    group = jf.group(ms.x_ref) or {}
    if group:  # pairs holding one freedom together: one event for the group
        out.append(EventFunction("cone", min(group), lambda tt, ev, c=group:
                                 jf.group_margin(c, ev.x, ev.lam), 1e-7 * force_scale * L,
                                 arm=1e-10 * force_scale * L))
    for j, s in sorted(jf.states.items()):
        unit = L if ms.model.joint_kind(j) == "revolute" else 1.0  # N m or N
        if j in group:
            continue
        if s == "stick":
            out.append(EventFunction("cone", j, lambda tt, ev, j=j: jf.margin(j, ev.x, ev.lam),
                                     1e-7 * force_scale * unit,
                                     arm=1e-10 * force_scale * unit))
        else:
            sg = 1.0 if s == "slip+" else -1.0
            # fires also where the pair moves against s (a direction that did not hold)
            out.append(EventFunction("slip", j, lambda tt, ev, j=j, sg=sg:
                                     sg * jf.velocity(j, ev.x, ev.xdot), 1e-6 * L / unit,
                                     arm=1e-12 * L / unit))
    return out


_OPS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}


def guard_holds(sm, guards, t, x, xd) -> bool:
    return all(_OPS[op](_value(meas, t, x, xd), val) for meas, op, val in guards)


@dataclass
class _Requests:
    """What the fired events ask of a switching instant."""

    engage: list = field(default_factory=list)  # (lock, switch name)
    release: list = field(default_factory=list)  # (lock, switch name)
    forced_open: set = field(default_factory=set)  # closed rows whose force fell to zero
    forced_slip: dict = field(default_factory=dict)  # {contact: slip direction}
    forced_stick: set = field(default_factory=set)  # slipping rows that came to rest
    notes: list = field(default_factory=list)  # (kind, element, message) of ignored ones


def _requests(sm: SwitchedModel, ms: ModeSystem, t, x, xd, fired, locks) -> _Requests:
    """Sort the fired events into engagements, releases and forced friction states
    (a switch whose guard fails, or whose lock is already so, is a note)."""
    req = _Requests()
    for e in fired:
        if e.kind in ("switch", "time"):
            sw = e.data[0]
            guards = [g for s_, _m, g in sm.switches if s_ is sw][0]
            if not guard_holds(sm, guards, t, x, xd):
                req.notes.append(("ignored", sw.name, "guard not met"))
                continue
            act = sw.action
            if act == "toggle":
                act = "release" if sw.target in locks else "engage"
            if act == "engage" and sw.target not in locks:
                req.engage.append((sw.target, sw.name))
            elif act == "release" and sw.target in locks:
                req.release.append((sw.target, sw.name))
            else:
                req.notes.append(("ignored", sw.name, f"{sw.target} already {act}d"))
        elif e.kind == "force":
            req.forced_open.add(e.key)
        elif e.kind == "cone":
            ev = ms.evaluate_x(t, x, xd)
            req.forced_slip[e.key] = -1 if ev.lam[_row(ms, e.key, "stick")] > 0 else 1
        elif e.kind == "slip":
            req.forced_stick.add(e.key)
    return req


def _mode_after(sm, t, ms, x, xd_plus, locks, targets, touch, req: _Requests, *,
                small_velocity, force_scale):
    """The mode after the instant: unilateral rows by complementarity, then the
    friction state of the stick-slip pairs."""
    vmax = float(np.max(np.abs(xd_plus), initial=0.0))
    # candidates: touching and not separating
    cand = [tok for tok, v in _rates(sm, touch, targets, x, xd_plus)
            if v <= max(small_velocity * 1e-3, 1e-9 * vmax)]
    ss = stick_slip_joints(sm.model)
    vtol = 1e-9 * max(vmax, small_velocity) + 1e-12
    mode_after, _ = resolve_mode(
        sm, t, x, xd_plus, locks, targets, cand,
        slip_velocity_tol=vtol, force_tol=1e-10 * force_scale, forced_open=req.forced_open,
        forced_slip={k: v for k, v in req.forced_slip.items() if k not in ss},
        forced_stick=req.forced_stick - set(ss), workspace=ms.ws)
    if ss:  # the friction state of the stick-slip pairs
        mode_after = frozenset(mode_after) | state_tokens(resolve_joints(
            ModeSystem, sm, t, x, xd_plus, mode_after, targets,
            before=joint_states(sm.model, ms.mode),
            forced_slip={k: v for k, v in req.forced_slip.items() if k in ss},
            forced_stick=req.forced_stick & set(ss), velocity_tol=vtol,
            force_tol=1e-10 * force_scale, workspace=ms.ws))
    return mode_after


def _no_jump(sm, ms_new: ModeSystem, x, engage, t, q_b) -> None:
    """An engaging lock must hold the pose it engages at (no position jump).

    Raises
    ------
    AssemblyError
        Naming the locks and the rows that are off, with their residuals.
    """
    tol_pos = 1e-8 * sm.model.length_scale
    bad = {lab: float(v) for lab, v, el in zip(ms_new.row_labels(), ms_new.row_values(x),
                                               ms_new.row_elements(), strict=True)
           if el in dict(engage) and abs(v) > tol_pos}
    if bad:
        raise AssemblyError(
            "engaging " + ", ".join(repr(n) for n, _ in engage) + " would need a position "
            "jump: the held value differs from the pose at the switch ("
            + ", ".join(f"{k} off by {v:.3g}" for k, v in bad.items()) + ")",
            t=t, q=q_b, residuals=bad)


def apply_switch(sm: SwitchedModel, t, ms: ModeSystem, x, xd, targets, events, *, fired,
                 small_velocity, gap_tol, force_scale, initial=False, plastic=()):
    """Apply the fired events at (t, x, xd); returns (new ModeSystem, x, xdot, energy lost).

    In order: the switches release and engage their locks (:func:`_requests`); an
    engaging lock or a touching row that closes makes an impact
    (:func:`~mechdyn.simulate.impact.impact`); the mode after is found by
    complementarity (:func:`_mode_after`); its mode system is built and the state
    projected onto its constraints; the events of the instant are recorded
    (:func:`_record`)."""
    mode_before = ms.mode
    q_b = ms.coordinates(x)
    qd_b = ms._coord_jac(x) @ xd
    locks = set(mode_locks(mode_before))
    req = _requests(sm, ms, t, x, xd, fired, locks)
    for n, _ in req.release:
        locks.discard(n)
        targets.pop(n, None)
    locks_before = frozenset(locks)
    for n, _ in req.engage:
        sm.capture_target(n, x, targets)
        locks.add(n)
    frees = [f for n, _ in req.engage for f in sm.lock_frees(n)]
    locks = frozenset(locks)
    # touching unilateral constraints (closed ones have zero gap by construction)
    touch = set(touching(sm, x, gap_tol=gap_tol)) | set(mode_unilateral(mode_before))
    lost, imp, xd_plus = 0.0, None, xd
    # an engaging lock, or a touching constraint approaching
    if set(locks) - set(locks_before) or any(v < 0.0 for _, v in _rates(sm, touch, targets,
                                                                          x, xd)):
        imp = impact(sm, x, xd, locks_before, locks, targets, touch,
                     restitution={k: 0.0 for k in plastic},
                     small_velocity=small_velocity, t=t, warned=ms.ws.warned, workspace=ms.ws)
        xd_plus = imp.xdot_plus
        lost = imp.energy_lost
    mode_after = _mode_after(sm, t, ms, x, xd_plus, locks, targets, touch, req,
                             small_velocity=small_velocity, force_scale=force_scale)
    if (initial and mode_after == ms.mode and not req.engage
            and held_key(targets) == held_key(ms.targets) is not None):
        # the mode the run starts in, built a moment ago: the same rows and coordinates,
        # restarted at this pose as a new one would be (a second build costs ~1 ms a run)
        ms_new = ms
        ms_new.x_ref = np.array(x, float)
        ms_new.ws.reset(ms_new.x_ref)
    else:
        ms_new = mode_system(sm, mode_after, targets, x, prefer=ms.coord_names, avoid=frees,
                             workspace=ms.ws)
    _no_jump(sm, ms_new, x, req.engage, t, q_b)
    # project onto the new mode's constraints (removes round-off of the located crossing)
    qi = ms_new.coordinates(x)[ms_new.coords]
    x_new = ms_new.solve_position(qi, x, t=t)
    B, _ = ms_new.velocity_analogs(x_new)
    G = ms_new._coord_jac(x_new)
    xd_new = B @ (G[ms_new.coords] @ xd_plus)
    q_a, qd_a = ms_new.coordinates(x_new), G @ xd_new
    if initial and mode_after == mode_before and not req.engage:
        return ms_new, x_new, xd_new, lost

    def add(kind, element, msg="", lost_=0.0, impulses=None):
        events.append(EventRecord(t, kind, element, mode_before, frozenset(mode_after),
                                  q_b, qd_b, q_a, qd_a, lost_, dict(impulses or {}), msg))

    _record(add, sm, mode_before, mode_after, req, imp, touch, lost)
    if len(events) == 0 or events[-1].t != t:
        if mode_after != mode_before:
            add("switch", ",".join(sorted(set(mode_after) ^ set(mode_before))))
    return ms_new, x_new, xd_new, lost


def _record(add, sm, mode_before, mode_after, req: _Requests, imp, touch, lost) -> None:
    """The events of a switching instant, through ``add(kind, element, message, energy
    lost, impulses)``: releases, engagements, rows closing, opening or bouncing, friction
    states changing, and the notes of ignored switches."""
    engage = req.engage
    impulses = imp.element_impulses if imp is not None else {}
    for n, swn in req.release:
        add("release", n, f"switch {swn!r} released lock {n!r}")
    for n, swn in engage:
        add("engage", n, f"switch {swn!r} engaged lock {n!r}", lost, impulses)
    closed_before = set(mode_unilateral(mode_before))
    closed_after = set(mode_unilateral(mode_after))
    for tok in sorted(closed_after - closed_before):
        kind = "impact" if imp is not None and not engage else "close"
        add(kind, tok, "", lost if not engage else 0.0, impulses)
    for tok in sorted(closed_before - closed_after):
        bounced = imp is not None and tok in touch
        add("impact" if bounced and tok not in closed_after else "separate", tok,
            "rebound" if bounced else "force fell to zero", lost if bounced and not engage
            else 0.0, impulses if bounced else None)
    for tok in sorted(touch - closed_before - closed_after):
        if imp is not None and not engage and tok not in req.forced_open:
            add("impact", tok, "rebound", lost, impulses)
    fb, fa = mode_friction(mode_before), mode_friction(mode_after)
    for c in sorted(set(fb) | set(fa)):
        if fb.get(c) != fa.get(c) and c in fa and contact_token(c) in closed_before:
            add("stick" if fa[c] == "stick" else "slip", c, fa[c])
    jb, ja = joint_states(sm.model, mode_before), joint_states(sm.model, mode_after)
    for j in sorted(ja):
        if jb.get(j) != ja[j]:
            add("stick" if ja[j] == "stick" else "slip", j, ja[j])
    for kind, name, msg in req.notes:
        add(kind, name, msg)


def _rates(sm, tokens, targets, x, xd) -> list:
    """(label, gap rate) of the unilateral rows of stop and contact tokens (< 0 closing)."""
    return [(r.label, r.sign * r.measure.rate(x, xd))
            for r in sm.rows(frozenset(tokens), targets) if r.unilateral]
