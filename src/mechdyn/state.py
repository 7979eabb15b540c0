"""The state of a mechanism: time, coordinates, their rates, and the mode."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["State"]


@dataclass(frozen=True)
class State:
    """State(t, q, qdot, mode).

    Parameters
    ----------
    t : float
        Time, s.
    q, qdot : ndarray, shape (n_q,)
        Generalized coordinates (rad or m) and their rates (rad/s or m/s).
    mode : frozenset of str
        Names of the engaged locks and closed contacts (the active constraint set).
    """

    t: float
    q: np.ndarray
    qdot: np.ndarray
    mode: frozenset = field(default_factory=frozenset)

    def __post_init__(self):
        object.__setattr__(self, "q", np.array(self.q, dtype=float).reshape(-1))
        object.__setattr__(self, "qdot", np.array(self.qdot, dtype=float).reshape(-1))
        object.__setattr__(self, "mode", frozenset(self.mode))
