"""Events: zero crossings of g(t, q, qdot) located on a step's dense output.

An event function changes sign where something happens (a velocity reverses,
a point reaches a stop ...).  Like SciPy's ``solve_ivp`` events it has a
``direction`` (+1 rising, -1 falling, 0 both) and may be ``terminal``; the
crossing is located by Brent's method on the step's interpolant
(:func:`mechdyn.integrate.segment.locate`, the one event locator of the package),
so its accuracy is that of the dense output.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Event", "EventRecord", "as_events"]


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
