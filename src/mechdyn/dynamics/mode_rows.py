"""The constraint rows of one mode of a variable-structure mechanism, and their keys.

:class:`ModeRows` holds what a mode's rows are, whatever the pose: the model's joint
rows followed by one row per active switchable element, their layout
(:class:`~mechdyn.model.ConstraintLayout`) and the rows of each element, with their
values and Jacobian.  :class:`~mechdyn.dynamics.mode_system.ModeSystem` adds what is
chosen at a pose (independent rows and coordinates) and the dynamics; an impact's
impulses on every element need the rows alone (:func:`mechdyn.simulate.impact.impact`).
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ..friction.forward import split_mode, stick_row
from ..kernels import rows_numpy as RN
from ..model import ConstraintLayout
from ..model.state import Mode
from ..model.workspace import Workspace
from .reactions import ground_rows

if TYPE_CHECKING:
    from ..model.switchable import SwitchedModel

__all__ = ["ModeRows", "held_key"]


class ModeRows:
    """The rows of a mode with its held values.

    Parameters
    ----------
    sm : SwitchedModel
    mode : frozenset of str
    targets : dict
        Held values of the engaged locks and sticking contacts.
    workspace : Workspace, optional
        The run's workspace, which keeps the rows of the modes the run meets.

    Attributes
    ----------
    rows : list of Row
        The switchable rows of the mode.
    layout : ConstraintLayout
    rowset : Rows
        Every row of the mode: the joint rows (``n_base`` of them), then ``rows``.
    element_rows : dict
        The rows of each element (joint, lock, stop, contact), indices into ``rowset``.

    Examples
    --------
    >>> import mechdyn
    >>> from mechdyn.model.switchable import switched_model
    >>> sm = switched_model(mechdyn.examples.load("press_cycle").compile())
    >>> mr = ModeRows(sm, frozenset({"ram_stop@upper"}), {})
    >>> mr.n_rows - mr.n_base, mr.row_labels()[-1]
    (1, 'ram_stop@upper')
    """

    def __init__(self, sm: SwitchedModel, mode, targets: dict, workspace=None):
        self.sm = sm
        self.model = sm.model
        self.mode = Mode(mode)
        self.targets = dict(targets)
        kept = None if workspace is None else workspace.mode_rows
        self.rows, self.layout = _mode_rows(sm, self.mode, self.targets, kept)
        lay = self.layout
        self.rowset, self.n_rows, self.n_base = lay.rowset, lay.n_rows, lay.n_base
        self.element_rows = lay.element_rows

    def row_values(self, x) -> np.ndarray:
        """Residuals of every row of :attr:`rowset`, shape (n_rows,), m or rad."""
        return RN.values(self.rowset, x)

    def row_jacobian(self, x) -> np.ndarray:
        """Jacobian of every row, shape (n_rows, n_x)."""
        return RN.jacobian(self.rowset, x)

    def row_labels(self) -> list[str]:
        """A label per row (joint name + component, then the switchable rows)."""
        return list(self.rowset.labels)

    def row_elements(self) -> list[str]:
        """The element (joint, lock, stop, contact) of each row."""
        return list(self.rowset.elements)

    @cached_property
    def grounded(self) -> frozenset:
        """The elements whose rows act between the frame and the moving bodies."""
        on_ground = ground_rows(self.rowset)
        return frozenset(el for el, idx in self.element_rows.items() if np.any(on_ground[idx]))


def held_key(targets: dict) -> tuple | None:
    """The held values of the engaged locks and sticking contacts as a hashable key (their
    names and bytes), equal for equal values; None for a held value that is not numbers.

    Examples
    --------
    >>> held_key({"lock": 0.5}) == held_key({"lock": 0.5}), held_key({"lock": 0.5}) == ()
    (True, False)
    """
    def held(value) -> bytes:
        parts = value if isinstance(value, tuple) else (value,)
        return np.concatenate([np.ravel(np.asarray(p, float)) for p in parts]).tobytes()

    try:
        return tuple(sorted((k, held(v)) for k, v in targets.items()))
    except (TypeError, ValueError):
        return None


def _mode_rows(sm: SwitchedModel, mode: Mode, targets: dict, kept: dict | None):
    """(switchable rows, :class:`~mechdyn.model.ConstraintLayout`) of a mode with its held
    values, kept in ``kept`` (a run's :attr:`Workspace.mode_rows
    <mechdyn.model.workspace.Workspace>`, or None) so that a run builds those of each
    mode it meets again once (the rows list is the caller's own copy)."""
    model = sm.model
    held = held_key(targets)
    key = None if held is None or kept is None else (mode, held)  # not numbers: not kept
    got = None if key is None else kept.get(key)
    if got is None:
        base, jstates = split_mode(model, mode)
        rows = sm.rows(base, targets) + [stick_row(model, j, targets)
                                         for j, s in sorted(jstates.items()) if s == "stick"]
        got = (tuple(rows), ConstraintLayout(model, mode, rows))
        if kept is not None:
            Workspace.keep(kept, key, got)
    return list(got[0]), got[1]
