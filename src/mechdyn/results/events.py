"""Listings of a run's events: a text table and a DataFrame (``mechdyn simulate``, reports)."""

from __future__ import annotations

__all__ = ["format_events", "events_table", "frame_impulse"]


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


def frame_impulse(event):
    """The impulse the frame receives at an impact, (Jx N s, Jy N s, angular N m s about
    the run's reference point), or None for an event without one.

    Examples
    --------
    >>> from types import SimpleNamespace as E
    >>> frame_impulse(E(impulses={"stop@up": 3.0, "frame": (-2.5, 0.5, 0.1)}))
    (-2.5, 0.5, 0.1)
    >>> frame_impulse(E(impulses={})) is None
    True
    """
    imp = getattr(event, "impulses", None) or {}
    # "frame (total)" where an element of the model is itself named "frame"
    value = imp.get("frame (total)", imp.get("frame"))
    return None if value is None else tuple(float(v) for v in value)


def events_table(events, coordinate_names=()):
    """One row per event: ``t_s``, ``kind``, ``element``, ``mode_before``, ``mode_after``,
    ``energy_lost_J``, the impulse the frame receives at an impact (``Jx_frame_Ns``,
    ``Jy_frame_Ns``, ``H_frame_Nms``; 0 for other events) and the coordinates after it
    (``<c>_after``): a pandas DataFrame."""
    import pandas as pd

    rows = []
    for ev in events:
        row = {"t_s": ev.t, "kind": ev.kind, "element": ev.element,
               "mode_before": " ".join(sorted(ev.mode_before)),
               "mode_after": " ".join(sorted(ev.mode_after)), "energy_lost_J": ev.energy_lost}
        jx, jy, h = ((frame_impulse(ev) or ()) + (0.0, 0.0, 0.0))[:3]
        row.update(Jx_frame_Ns=jx, Jy_frame_Ns=jy, H_frame_Nms=h)
        if ev.q_after is not None:
            row.update({f"{n}_after": v for n, v in zip(coordinate_names, ev.q_after,
                                                        strict=False)})
        rows.append(row)
    return pd.DataFrame(rows)
