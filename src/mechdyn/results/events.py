"""Text listings of a run's events (for ``mechdyn simulate``)."""

from __future__ import annotations

__all__ = ["format_events"]


def format_events(events, coordinate_names=None, *, limit: int | None = None) -> str:
    """A text table of the switching events of a run (for ``mechdyn simulate``).

    Parameters
    ----------
    events : list of SwitchEvent
    coordinate_names : sequence of str, optional
        Adds the coordinates after each event.
    limit : int, optional
        Show at most this many (the first ``limit - 1`` and the last).
    """
    evs = [e for e in events if getattr(e, "kind", "event") != "event"]
    if not evs:
        return "no switching events"
    lines = [f"{len(evs)} switching event(s):",
             f"{'t [s]':>14}  {'kind':<9} {'element':<18} {'lost [J]':>10}  mode after"]
    shown = evs
    if limit is not None and len(evs) > limit:
        shown = evs[:max(limit - 1, 1)] + [None] + evs[-1:]
    for e in shown:
        if e is None:
            lines.append(f"{'...':>14}  ({len(evs) - limit} more)")
            continue
        mode = ", ".join(sorted(e.mode_after)) or "-"
        line = f"{e.t:14.9f}  {e.kind:<9} {e.element:<18} {e.energy_lost:10.4g}  {mode}"
        if coordinate_names is not None:
            line += "   " + ", ".join(f"{n}={v:.6g}" for n, v in
                                      zip(coordinate_names, e.q_after, strict=False))
        lines.append(line)
    return "\n".join(lines)
