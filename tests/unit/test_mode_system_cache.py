"""The fixed cost of a run: what a mode system keeps in the run's workspace and its
shortcuts give what the full computation gives."""

import numpy as np

from mechdyn.dynamics import mode_system as MS
from mechdyn.dynamics.mode_system import ModeSystem
from mechdyn.examples.paper_case import press_idle
from mechdyn.model.switchable import switched_model
from mechdyn.model.workspace import Workspace


def _greedy(Rs):
    """Rows kept, earlier first, where each raises the rank of those kept (by SVD rank,
    a second way of deciding independence)."""
    keep: list = []
    for k in range(Rs.shape[0]):
        if np.linalg.matrix_rank(Rs[keep + [k]]) > len(keep):
            keep.append(k)
    return keep


def test_independent_rows_shortcut_agrees_with_gram_schmidt():
    rng = np.random.default_rng(3)
    for m, n in ((3, 6), (6, 6), (5, 9)):
        A = rng.normal(size=(m, n))
        assert MS.independent_row_indices(A).tolist() == _greedy(A) == list(range(m))
        B = np.vstack([A, A[0] + 2 * A[1]])  # a dependent row: the greedy path
        if B.shape[0] <= n:
            assert MS.independent_row_indices(B).tolist() == _greedy(B) == list(range(m))
        C = A.copy()
        C[1] = 3.0 * C[0]  # dependent among the first rows
        assert MS.independent_row_indices(C).tolist() == _greedy(C)


def test_mode_rows_kept_in_a_workspace_give_the_same_mode_system():
    model = press_idle().compile()
    sm = switched_model(model)
    ws = Workspace()
    a = ModeSystem(sm, frozenset(), {}, model.x0, workspace=ws)
    b = ModeSystem(sm, frozenset(), {}, model.x0, workspace=ws)
    assert b.layout is a.layout  # built once, kept in the run's workspace
    assert b.rows is not a.rows  # each mode system has its own list
    assert a.coords.tolist() == b.coords.tolist()
    assert a.independent_rows.tolist() == b.independent_rows.tolist()
    assert MS.held_key({"w": (np.array([1.0, 2.0]), 0.5)}) == MS.held_key(
        {"w": (np.array([1.0, 2.0]), 0.5)})
    assert MS.held_key({"w": 1.0}) != MS.held_key({"w": 1.0 + 1e-15})
