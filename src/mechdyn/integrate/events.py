"""Events: zero crossings of g(t, q, qdot) located on a step's dense output.

An event function changes sign where something happens (a velocity reverses,
a point reaches a stop ...).  Like SciPy's ``solve_ivp`` events it has a
``direction`` (+1 rising, -1 falling, 0 both) and may be ``terminal``; the
crossing is located by Brent's method on the step's interpolant, so its
accuracy is that of the dense output.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

__all__ = ["Event", "EventRecord", "as_events", "locate_events"]


@dataclass(frozen=True)
class Event:
    """An event function.

    Parameters
    ----------
    function : callable
        ``g(t, q, qdot) -> float``; the event is at a zero crossing.
    name : str
    direction : {-1, 0, 1}
        Only falling (-1), only rising (+1) or all (0) crossings.
    terminal : bool
        Stop the integration at the first occurrence.
    """

    function: Callable
    name: str = "event"
    direction: int = 0
    terminal: bool = False

    def __call__(self, t, q, qdot) -> float:
        return float(self.function(t, q, qdot))


@dataclass(frozen=True)
class EventRecord:
    """One occurrence of an event: its name, time (s) and state there."""

    name: str
    t: float
    q: np.ndarray
    qdot: np.ndarray


def as_events(events) -> list[Event]:
    """Normalise None, one event or a list of events/callables to a list of :class:`Event`.

    A plain callable may carry ``terminal`` and ``direction`` attributes (as for
    ``solve_ivp``).
    """
    if events is None:
        return []
    if callable(events) and not isinstance(events, (list, tuple)):
        events = [events]
    out = []
    for k, e in enumerate(events):
        if isinstance(e, Event):
            out.append(e)
        elif callable(e):
            out.append(Event(e, getattr(e, "__name__", f"event{k}"),
                             int(getattr(e, "direction", 0)),
                             bool(getattr(e, "terminal", False))))
        else:
            raise TypeError(f"event {k}: expected a callable g(t, q, qdot), got {e!r}")
    return out


def locate_events(events: list[Event], g_old: np.ndarray, step, g_new: np.ndarray | None = None,
                  xtol: float = 4 * np.finfo(float).eps):
    """Find the events crossed during one step.

    Parameters
    ----------
    events : list of Event
    g_old : ndarray, shape (n_events,)
        Event function values at the start of the step.
    step : Step
        The step, with its dense output.
    g_new : ndarray, optional
        Values at the end of the step (computed if not given).

    Returns
    -------
    records : list of EventRecord
        Crossings in time order, up to and including the first terminal one.
    g_new : ndarray
        Values at the end of the step.
    terminal : bool
        Whether a terminal event was crossed (the run should end at the last record).
    """
    if g_new is None:
        g_new = np.array([e(step.t, step.q, step.qdot) for e in events])
    found = []
    for k, e in enumerate(events):
        a, b = g_old[k], g_new[k]
        up = a <= 0 < b or (a < 0 <= b)
        down = a >= 0 > b or (a > 0 >= b)
        if a == 0 and b == 0:
            continue
        if (e.direction > 0 and up) or (e.direction < 0 and down) or (e.direction == 0 and
                                                                      (up or down)):
            def g(s, e=e):
                q, v, _ = step.dense(s)
                return e(s, q, v)

            if b == 0:
                ts = step.t
            elif a == 0:
                continue  # the crossing was reported at the end of the previous step
            else:
                ts = brentq(g, step.t_old, step.t, xtol=xtol, rtol=4 * np.finfo(float).eps)
            found.append((ts, k))
    found.sort()
    records, terminal = [], False
    for ts, k in found:
        q, v, _ = step.dense(ts)
        records.append(EventRecord(events[k].name, float(ts), np.array(q), np.array(v)))
        if events[k].terminal:
            terminal = True
            break
    return records, g_new, terminal
