"""The caches of a simulation: made by the run, or held by a caller and passed.

The :class:`~mechdyn.model.compile.Model` holds what never changes (rows, masses, loads,
the switchable elements, all built by the compiler); :class:`~mechdyn.model.state.State`
what the integrator advances.  A :class:`Workspace` holds what a run learns as it goes
and reuses:

- the last solved pose (the start of the next Newton solve, which keeps the assembly
  branch by continuity), the velocity analogs there (a first-order predictor to the
  next coordinates) and the evaluated row parts of that pose.  Every mode system of a
  run shares the run's workspace, so a new mode starts its Newton solves from the pose
  the previous one reached;
- what a run derives for the modes it meets: the rows of a mode with its held values,
  the packed arrays of a mode's compiled kernel, the coordinates that move a rigid
  assembly, the rows of the turning-point check (each table bounded by
  :data:`KEPT`);
- the starts of runs (their mode system, pose and rates) and the equations of their
  first segment, so that a caller who runs many times from the same initial state (a
  study, an optimiser) and passes the same workspace each time pays the start once.

The library keeps none of this between calls: a run without a workspace makes its own.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Workspace", "KEPT"]

#: the most entries kept in each of a workspace's tables
KEPT = 64


@dataclass
class Workspace:
    """The caches of one run, or of the runs given the same workspace.

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
    mode_rows, kernels, rigid, turn_rows : dict
        What the run derived for the modes it met (see the module's text).
    starts, equations, poses : dict
        Run starts, the equations of their first segment and the assembled initial
        poses, for the next run given this workspace.

    Examples
    --------
    >>> ws = Workspace()
    >>> ws.reset([0.0, 0.0, 0.5])
    >>> ws.x, ws.B is None
    (array([0. , 0. , 0.5]), True)
    >>> ws.keep(ws.poses, "a", 1), ws.poses
    (1, {'a': 1})
    """

    x: np.ndarray | None = None
    B: np.ndarray | None = None
    qi: np.ndarray | None = None
    parts: tuple | None = None
    warned: set = field(default_factory=set)
    at_pose: tuple | None = None
    mode_rows: dict = field(default_factory=dict)
    kernels: dict = field(default_factory=dict)
    rigid: dict = field(default_factory=dict)
    turn_rows: dict = field(default_factory=dict)
    starts: dict = field(default_factory=dict)
    equations: dict = field(default_factory=dict)
    poses: dict = field(default_factory=dict)

    def reset(self, x) -> None:
        """Restart from the pose ``x`` (n_x,): no predictor, no cached parts."""
        self.x = np.array(x, dtype=float)
        self.B = self.qi = self.parts = None

    def begin(self) -> Workspace:
        """Begin a run: forget the last run's pose, warnings and instant (the tables of
        what it derived stay); returns the workspace."""
        self.x = self.B = self.qi = self.parts = self.at_pose = None
        self.warned = set()
        return self

    def predict(self, qi) -> np.ndarray:
        """The start of a Newton solve at ``qi``: the last pose moved along its analogs."""
        if self.B is None or self.qi is None or not np.size(qi):
            return self.x.copy()
        return self.x + self.B @ (np.asarray(qi, float) - self.qi)

    @staticmethod
    def keep(table: dict, key, value):
        """Put ``value`` into one of the workspace's tables under ``key`` (nothing when
        ``key`` is None or the table holds :data:`KEPT` entries); returns ``value``."""
        if key is not None and len(table) < KEPT:
            table[key] = value
        return value
