"""The mode of a variable-structure mechanism, and the state of a mechanism: time,
coordinates, their rates and the mode."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Mode", "State"]


class Mode(frozenset):
    """The active switchable constraints: a frozen set of tokens, typed.

    Tokens: an engaged lock by its name (``"clutch"``), a closed stop side
    (``"stop@lower"``, ``"stop@upper"``), a closed contact (``"c@contact"``) and the
    friction state of a closed contact (``"c:stick"``, ``"c:slip+"``, ``"c:slip-"``).
    A ``Mode`` compares and hashes like the frozenset of its tokens.

    Examples
    --------
    >>> m = Mode({"clutch", "ram@upper", "pin@contact", "pin:stick"})
    >>> sorted(m.locks), sorted(m.closed), m.friction
    (['clutch'], ['pin@contact', 'ram@upper'], {'pin': 'stick'})
    >>> Mode() == frozenset()
    True
    """

    __slots__ = ()

    @property
    def locks(self) -> frozenset:
        """The engaged locks (tokens without '@' or ':')."""
        return frozenset(t for t in self if "@" not in t and ":" not in t)

    @property
    def closed(self) -> frozenset:
        """Closed stop sides ('name@lower', 'name@upper') and contacts ('name@contact')."""
        return frozenset(t for t in self if "@" in t)

    @property
    def friction(self) -> dict:
        """{contact: 'stick' | 'slip+' | 'slip-'} of the closed contacts."""
        return dict(t.split(":", 1) for t in self if ":" in t)

    def __repr__(self) -> str:
        return "Mode({" + ", ".join(repr(t) for t in sorted(self)) + "})"


@dataclass(frozen=True)
class State:
    """State(t, q, qdot, mode).

    Parameters
    ----------
    t : float
        Time, s.
    q, qdot : ndarray, shape (n_q,)
        Generalized coordinates (rad or m) and their rates (rad/s or m/s).
    mode : Mode
        The active switchable constraints.
    """

    t: float
    q: np.ndarray
    qdot: np.ndarray
    mode: Mode = field(default_factory=Mode)

    def __post_init__(self):
        object.__setattr__(self, "q", np.array(self.q, dtype=float).reshape(-1))
        object.__setattr__(self, "qdot", np.array(self.qdot, dtype=float).reshape(-1))
        object.__setattr__(self, "mode", Mode(self.mode))
