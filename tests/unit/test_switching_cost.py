"""The per-step and per-switch shortcuts of switched runs give what the full computation
gives: the mode systems a run keeps for the pose of a switching instant, the compiled
values of the event functions' measures, the compiled evaluation's parts."""

import numpy as np
import pytest

import mechdyn
from mechdyn.dynamics.compiled import numba_available
from mechdyn.dynamics.mode_equations import ModeEquations
from mechdyn.dynamics.mode_system import ModeSystem, mode_system
from mechdyn.kernels import rows_numpy
from mechdyn.model.switchable import switched_model
from mechdyn.model.workspace import Workspace
from mechdyn.simulate.gaps import gap_measures
from mechdyn.simulate.switching import _PoseValues


@pytest.fixture(scope="module")
def sm():
    return switched_model(mechdyn.examples.load("press_cycle").compile())


def test_a_run_builds_a_mode_once_per_pose(sm):
    ws, x = Workspace(), sm.model.x_sketch
    a = mode_system(sm, frozenset(), {}, x, workspace=ws)
    ws.x = None  # used by a solve since: the one kept is restarted at its pose
    assert mode_system(sm, frozenset(), {}, x.copy(), workspace=ws) is a
    assert np.array_equal(ws.x, x)
    # other choices, another run, no run: other mode systems, as a new one would be
    b = mode_system(sm, frozenset(), {}, x, prefer=("phi",), workspace=ws)
    assert b is not a
    assert mode_system(sm, frozenset(), {}, x, workspace=Workspace()) is not a
    c = mode_system(sm, frozenset(), {}, x)
    assert c is not a and c.coords.tolist() == a.coords.tolist()
    # a new pose forgets the last one
    x2 = ModeSystem(sm, frozenset(), {}, x).solve_position(a.coordinates(x)[a.coords] + 0.01, x)
    d = mode_system(sm, frozenset(), {}, x2, workspace=ws)
    assert d is not a and np.array_equal(d.x_ref, x2)
    assert mode_system(sm, frozenset(), {}, x, workspace=ws) is not a


def test_a_kept_mode_system_is_keyed_on_the_mode_and_its_held_values(sm):
    # the same pose and workspace: a lock held at another value, or another mode, is
    # another mode system (its lock row holds its own value: residual -0.01 rad at x)
    ws, x = Workspace(), sm.model.x_sketch
    lock = sm.lock_names[0]
    held = {}
    sm.capture_target(lock, x, held)
    a = mode_system(sm, frozenset({lock}), held, x, workspace=ws)
    moved = {lock: held[lock] + 0.01}
    b = mode_system(sm, frozenset({lock}), moved, x, workspace=ws)
    assert b is not a
    assert a.row_values(x)[-1] == pytest.approx(0.0, abs=1e-15)
    assert b.row_values(x)[-1] == pytest.approx(-0.01, abs=1e-12)
    assert mode_system(sm, frozenset({lock}), dict(held), x, workspace=ws) is a
    free = mode_system(sm, frozenset(), held, x, workspace=ws)
    assert free is not a and free.n_rows == a.n_rows - 1


def test_pose_values_as_the_numpy_rows(sm):
    measures = [m for _, m, _, _ in gap_measures(sm)]
    pv = _PoseValues(sm.nb, measures)
    rng = np.random.default_rng(1)
    for _ in range(3):
        x = sm.model.x_sketch + 0.01 * rng.normal(size=sm.model.n_x)
        ev = type("Ev", (), {"x": x})()
        want = rows_numpy.values(pv.rows, x)
        got = [pv.value(m, ev) for m in measures]
        np.testing.assert_allclose(got, want[[pv.index[id(m)] for m in measures]],
                                   rtol=0, atol=1e-15)


@pytest.mark.skipif(not numba_available(), reason="numba not installed")
def test_compiled_evaluation_parts_as_the_numpy_evaluation(sm):
    ms = ModeSystem(sm, frozenset(), {}, sm.model.x_sketch)
    eqs = ModeEquations(sm, ms)
    qi = ms.coordinates(sm.model.x_sketch)[ms.coords]
    qd = np.array([43.5, 1.0, 0.1])[:ms.n_i]
    got = eqs.evaluate(0.0, qi, qd)
    ref = ms.evaluate(0.0, qi, qd)
    for k in ("x", "xdot", "q", "qdot", "qddot", "lam", "F"):
        np.testing.assert_allclose(getattr(got, k), getattr(ref, k), rtol=1e-9,
                                   atol=1e-9, err_msg=k)
