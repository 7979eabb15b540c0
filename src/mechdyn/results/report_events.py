"""The switching events of a run as a report lists them: one row per transition.

A variable-structure run records one :class:`~mechdyn.integrate.events.EventRecord` per
element that takes part in a transition: a piston landing on the ram while the ram
leaves its stop is two records at the same time with the same modes before and after
and the same energy lost.  :func:`merged_events` makes them one event naming both
elements; :func:`mode_spans` gives the intervals of constant mode for shading plots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .events import frame_impulse
from .table import deg_or_mm

__all__ = ["Transition", "merged_events", "mode_label", "mode_spans", "events_rows"]


@dataclass(frozen=True)
class Transition:
    """One transition of a run (the records of its elements merged)."""

    t: float
    kinds: tuple
    elements: tuple
    mode_before: frozenset
    mode_after: frozenset
    energy_lost: float
    message: str
    q_after: object = None
    #: impulse the frame receives (Jx N s, Jy N s, angular N m s), or None
    frame_impulse: tuple | None = None

    @property
    def label(self) -> str:
        """``"impact: piston_on_ram@contact + ram_stop@upper"``."""
        return f"{'/'.join(self.kinds)}: {' + '.join(self.elements)}"


def mode_label(mode) -> str:
    """The tokens of a mode, sorted, joined by " + " ("free" for the empty mode)."""
    tokens = sorted(str(m) for m in mode)
    return " + ".join(tokens) if tokens else "free"


def _add(items: tuple, value) -> tuple:
    return items if value in items else items + (value,)


def merged_events(events, *, tol: float = 1e-12) -> list[Transition]:
    """The events of a run, records of one transition merged.

    Records at the same time (within ``tol`` s, relative to the time's size) with the same
    modes before and after are one transition: their kinds and elements are listed once
    each, the energy lost is counted once (every record of an impact carries the whole
    loss), their messages are joined.  Events that change nothing (kind ``"ignored"``)
    are kept; caller events (kind ``"event"``) too.

    Examples
    --------
    >>> from types import SimpleNamespace as E
    >>> a = E(t=0.1, kind="impact", element="pin@contact", mode_before=frozenset({"s@up"}),
    ...       mode_after=frozenset({"pin@contact"}), energy_lost=2.0, message="")
    >>> b = E(t=0.1, kind="impact", element="s@up", mode_before=frozenset({"s@up"}),
    ...       mode_after=frozenset({"pin@contact"}), energy_lost=2.0, message="rebound")
    >>> [(e.label, e.energy_lost, e.message) for e in merged_events([a, b])]
    [('impact: pin@contact + s@up', 2.0, 'rebound')]
    """
    out: list[Transition] = []
    for ev in events:
        before = frozenset(getattr(ev, "mode_before", ()) or ())
        after = frozenset(getattr(ev, "mode_after", ()) or ())
        msg = getattr(ev, "message", "") or ""
        lost = float(getattr(ev, "energy_lost", 0.0) or 0.0)
        last = out[-1] if out else None
        if (last is not None and abs(ev.t - last.t) <= tol * max(1.0, abs(ev.t))
                and before == last.mode_before and after == last.mode_after
                and ev.kind != "event" and "event" not in last.kinds):
            messages = [m for m in (last.message, msg) if m]
            out[-1] = Transition(
                last.t, _add(last.kinds, ev.kind), _add(last.elements, str(ev.element)),
                before, after, max(last.energy_lost, lost),
                "; ".join(dict.fromkeys(messages)), last.q_after,
                last.frame_impulse or frame_impulse(ev))
            continue
        out.append(Transition(float(ev.t), (ev.kind,), (str(ev.element),), before, after, lost,
                              msg, getattr(ev, "q_after", None), frame_impulse(ev)))
    return out


def events_rows(transitions, coordinate_names=(), coordinate_is_angle=()) -> list[dict]:
    """Rows of the events table: time, what, elements, modes, energy lost, the impulse the
    frame receives (in a run with impacts), coordinates after (deg or mm)."""
    rows = []
    impacts = any(t.frame_impulse for t in transitions)  # a run with impacts
    for e in transitions:
        row = {"t (s)": f"{e.t:.6f}", "event": "/".join(e.kinds),
               "element(s)": " + ".join(e.elements),
               "mode before": mode_label(e.mode_before) if e.mode_before or e.mode_after else "",
               "mode after": mode_label(e.mode_after) if e.mode_before or e.mode_after else "",
               "energy lost (J)": e.energy_lost}
        if impacts:
            jx, jy = (e.frame_impulse or (0.0, 0.0))[:2]
            row["frame impulse x (N s)"], row["frame impulse y (N s)"] = jx, jy
        if e.q_after is not None:
            for k, (name, v) in enumerate(zip(coordinate_names, e.q_after, strict=False)):
                ang = coordinate_is_angle[k] if k < len(coordinate_is_angle) else True
                val, unit = deg_or_mm(float(v), ang)
                row[f"{name} after ({unit})"] = 0.0 if abs(val) < 1e-9 else float(val)
        if e.message:
            row["note"] = e.message
        rows.append(row)
    return rows


def mode_spans(t, mode_index, modes, *, limit: int = 400):
    """Intervals of constant mode: a list of (t0, t1, label), or None when there are more
    than ``limit`` intervals (too many to shade) or a single mode."""
    t = np.asarray(t, float)
    idx = np.asarray(mode_index, int)
    if t.size < 2 or idx.size != t.size or np.all(idx == idx[0]):
        return None
    cuts = np.flatnonzero(np.diff(idx)) + 1
    if cuts.size + 1 > limit:
        return None
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [t.size - 1]])
    return [(float(t[a]), float(t[b]), mode_label(modes[idx[a]])) for a, b in
            zip(starts, ends, strict=True)]
