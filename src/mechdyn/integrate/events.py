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
from dataclasses import dataclass, field

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


@dataclass
class EventRecord:
    """One occurrence of an event during a run: the one event record of the package.

    A caller's event function crossing zero has kind ``"event"`` and its name as
    ``element``; a variable-structure run records its switching instants with the
    same type (kinds ``"engage"``, ``"release"`` of a lock by a switch, ``"impact"``
    of a stop or contact closing with a velocity jump, ``"close"``, ``"separate"``,
    ``"slip"``, ``"stick"``, ``"ignored"`` for a switch whose guard failed or whose
    action changed nothing).

    Attributes
    ----------
    t : float
        Time, s (located on the step's dense output).
    kind : str
    element : str
        The event's name, or the switch, lock, stop (``"name@side"``) or contact.
    mode_before, mode_after : frozenset of str
        The active switchable constraints before and after (empty without switching).
    q_before, qdot_before, q_after, qdot_after : ndarray, shape (n_q,)
        Coordinates and rates just before and just after (equal without a jump).
    energy_lost : float
        Kinetic energy dissipated by an impact, J (0 without a jump).
    impulses : dict
        Impulse of every element of an impact: (Px, Py[, L]) on a joint's or lock's
        child body (N s, N m s), the normal impulse of stops and contacts (N s).
    message : str
    """

    t: float
    kind: str = "event"
    element: str = ""
    mode_before: frozenset = frozenset()
    mode_after: frozenset = frozenset()
    q_before: np.ndarray = None
    qdot_before: np.ndarray = None
    q_after: np.ndarray = None
    qdot_after: np.ndarray = None
    energy_lost: float = 0.0
    impulses: dict = field(default_factory=dict)
    message: str = ""

    @property
    def name(self) -> str:
        """The event's name, or ``kind:element`` of a switching instant."""
        return self.element if self.kind == "event" else f"{self.kind}:{self.element}"

    @property
    def q(self) -> np.ndarray:
        """Coordinates after the event."""
        return self.q_after

    @property
    def qdot(self) -> np.ndarray:
        """Rates after the event."""
        return self.qdot_after


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
