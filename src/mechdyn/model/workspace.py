"""The per-run caches of a simulation: created by the run and passed explicitly.

The :class:`~mechdyn.model.compile.Model` holds what never changes (rows, masses, loads,
derived constants in ``model.memo``); :class:`~mechdyn.model.state.State` what the
integrator advances.  A :class:`Workspace` holds what one run learns as it goes and
reuses: the last solved pose (the start of the next Newton solve, which keeps the
assembly branch by continuity), the velocity analogs there (a first-order predictor
to the next coordinates) and the evaluated row parts of that pose.  Every mode system
of a run shares the run's workspace, so a new mode starts its Newton solves from the
pose the previous one reached.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Workspace"]


@dataclass
class Workspace:
    """Per-run caches of the position solves.

    Attributes
    ----------
    x : ndarray, shape (n_x,) or None
        The last solved pose.
    B : ndarray, shape (n_x, n_i) or None
        The velocity analogs at ``x`` in the independent coordinates ``qi``.
    qi : ndarray, shape (n_i,) or None
        The independent coordinates of ``x``.
    parts : tuple or None
        ``(x, Parts, values)`` of the rows at ``x`` (reused by the evaluation at x).
    warned : set
        Keys of the warnings already given in this run (each is given once per run).
    at_pose : tuple or None
        ``(pose bytes, {key: value})``: the mode systems and coordinate choices made at
        the pose of the last switching instant (see
        :func:`mechdyn.dynamics.mode_system.mode_system`).

    Examples
    --------
    >>> ws = Workspace()
    >>> ws.reset([0.0, 0.0, 0.5])
    >>> ws.x, ws.B is None
    (array([0. , 0. , 0.5]), True)
    """

    x: np.ndarray | None = None
    B: np.ndarray | None = None
    qi: np.ndarray | None = None
    parts: tuple | None = None
    warned: set = field(default_factory=set)
    at_pose: tuple | None = None

    def reset(self, x) -> None:
        """Restart from the pose ``x`` (n_x,): no predictor, no cached parts."""
        self.x = np.array(x, dtype=float)
        self.B = self.qi = self.parts = None

    def predict(self, qi) -> np.ndarray:
        """The start of a Newton solve at ``qi``: the last pose moved along its analogs."""
        if self.B is None or self.qi is None or not np.size(qi):
            return self.x.copy()
        return self.x + self.B @ (np.asarray(qi, float) - self.qi)
