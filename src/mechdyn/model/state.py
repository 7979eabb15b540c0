"""The mode of a variable-structure mechanism, and the state of a mechanism: time,
coordinates, their rates and the mode.

A mode is a set of tokens; this module alone makes and reads them
(:func:`side_token`, :func:`contact_token`, :func:`friction_token`, :func:`stick_key`;
:func:`side_of`, :func:`contact_of`, :func:`friction_of`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Mode", "State", "side_token", "contact_token", "friction_token", "stick_key",
           "side_of", "contact_of", "friction_of"]

#: the friction states of a closed contact or a stick-slip pair
FRICTION_STATES = ("stick", "slip+", "slip-")


# ------------------------------------------------------------------ the tokens, made
def side_token(stop: str, side: str) -> str:
    """The token of a closed stop side: ``"stop@lower"`` or ``"stop@upper"``.

    Examples
    --------
    >>> side_token("ram_stop", "upper")
    'ram_stop@upper'
    """
    if side not in ("lower", "upper"):
        raise ValueError(f"a stop side is 'lower' or 'upper', got {side!r}")
    return f"{stop}@{side}"


def contact_token(contact: str) -> str:
    """The token of a closed contact: ``"name@contact"``.

    Examples
    --------
    >>> contact_token("pin")
    'pin@contact'
    """
    return f"{contact}@contact"


def friction_token(element: str, state: str) -> str:
    """The friction state of a closed contact or a stick-slip pair: ``"name:stick"``,
    ``"name:slip+"`` or ``"name:slip-"``.

    Examples
    --------
    >>> friction_token("guide", "slip+")
    'guide:slip+'
    """
    if state not in FRICTION_STATES:
        raise ValueError(f"a friction state is one of {FRICTION_STATES}, got {state!r}")
    return f"{element}:{state}"


def stick_key(element: str) -> str:
    """The key of the value a sticking contact or pair holds (in a run's held values),
    the token of its sticking state.

    Examples
    --------
    >>> stick_key("guide")
    'guide:stick'
    """
    return friction_token(element, "stick")


# ------------------------------------------------------------------ the tokens, read
def side_of(token: str) -> tuple[str, str]:
    """``(element, side)`` of a closed-side token: side ``"lower"``, ``"upper"`` or
    ``"contact"``.

    Examples
    --------
    >>> side_of("ram_stop@upper"), side_of("pin@contact")
    (('ram_stop', 'upper'), ('pin', 'contact'))
    """
    name, sep, side = token.rpartition("@")
    if not sep:
        raise ValueError(f"not the token of a closed stop or contact: {token!r}")
    return name, side


def contact_of(token: str) -> str | None:
    """The contact of a closed-contact token, None for any other token.

    Examples
    --------
    >>> contact_of("pin@contact"), contact_of("ram_stop@upper")
    ('pin', None)
    """
    name, sep, side = token.rpartition("@")
    return name if sep and side == "contact" else None


def friction_of(token: str) -> tuple[str, str] | None:
    """``(element, state)`` of a friction-state token, None for any other token.

    Examples
    --------
    >>> friction_of("guide:slip-"), friction_of("clutch")
    (('guide', 'slip-'), None)
    """
    name, sep, state = token.partition(":")
    return (name, state) if sep else None



class Mode(frozenset):
    """The active switchable constraints: a frozen set of tokens, typed.

    Tokens: an engaged lock by its name (``"clutch"``), a closed stop side
    (``"stop@lower"``, ``"stop@upper"``), a closed contact (``"c@contact"``) and the
    friction state of a closed contact (``"c:stick"``, ``"c:slip+"``, ``"c:slip-"``).
    A ``Mode`` compares and hashes like the frozenset of its tokens.

    Examples
    --------
    >>> m = Mode({"clutch", "ram@upper", "pin@contact", "pin:stick"})
    >>> sorted(m.locks), sorted(m.closed), m.friction, sorted(m.contacts)
    (['clutch'], ['pin@contact', 'ram@upper'], {'pin': 'stick'}, ['pin'])
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
    def contacts(self) -> frozenset:
        """The names of the closed contacts."""
        return frozenset(c for t in self if (c := contact_of(t)) is not None)

    @property
    def friction(self) -> dict:
        """{contact or pair: 'stick' | 'slip+' | 'slip-'} of the friction states."""
        return dict(f for t in self if (f := friction_of(t)) is not None)

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
