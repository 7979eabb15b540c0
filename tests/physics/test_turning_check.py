"""The turning-point check decides 'dead' from the singular values and vectors of the
scaled position Jacobian alone: the decision of the full singularity report, on a
Jacobian the compiled rows give bit for bit as the NumPy rows do."""

import numpy as np
import pytest
from dynamics_models import four_bar

import mechdyn
from mechdyn.dynamics import dead_position as D
from mechdyn.dynamics.compiled import numba_available
from mechdyn.dynamics.mode_system import ModeSystem
from mechdyn.examples.paper_case import press_idle
from mechdyn.kernels import rows_numpy as RN
from mechdyn.model.switchable import switched_model


def _systems():
    for model in (press_idle().compile(), mechdyn.examples.load("four_bar").compile(),
                  mechdyn.examples.load("toggle_press").compile(),
                  four_bar("psi", gravity=(0.0, 0.0)).compile()):  # a rocker's dead position
        sm = switched_model(model)
        yield ModeSystem(sm, frozenset(), {}, model.x_sketch)


@pytest.mark.skipif(not numba_available(), reason="numba not installed")
def test_compiled_rows_jacobian_is_the_numpy_one_bit_for_bit():
    rng = np.random.default_rng(3)
    for ms in _systems():
        rows = ms.layout.position_rows
        nb, ints, flts = D._packed_rows(ms)
        for k in range(200):
            x = ms.model.x_sketch + rng.normal(size=ms.model.n_x) * (3.0 if k % 2 else 0.05)
            J = np.zeros((len(rows), ms.model.n_x))
            D.rows_jacobian(x, nb, ints, flts, J, 0)
            assert np.array_equal(J, RN.jacobian(rows, x))


def test_dead_decision_is_that_of_the_singularity_report():
    """At poses along a line through each sketch, some near the singular ones."""
    seen = set()
    for ms in _systems():
        qi0 = ms.coordinates(ms.model.x_sketch)[ms.coords]
        for k, sign in ((k, s) for k in range(ms.n_i) for s in (1.0, -1.0)):
            x = ms.model.x_sketch
            for dq in sign * np.linspace(0.0, 6.3, 631):  # by continuation to a fold, if any
                qi = qi0.copy()
                qi[k] += dq
                try:
                    x = ms.solve_position(qi, x)
                except mechdyn.errors.AssemblyError:
                    break
                rep = ms.singularity(x)
                want = bool(rep["rcond"] < D.TURN_RCOND
                            and ms.coord_names[k] in rep["coordinates"])
                assert D._dead_at(ms, x, k) == want
                assert D._dead_at(ms, x, k, rep) == want
                seen.add(want)
    assert seen == {True, False}  # both decisions met


@pytest.mark.skipif(not numba_available(), reason="numba not installed")
def test_the_warm_up_compiles_the_jacobian_the_check_calls():
    from mechdyn.dynamics.compiled import warm_up_groups
    from mechdyn.kernels.rows_numba import rows_jacobian

    warm_up_groups()
    before = len(rows_jacobian.signatures)
    tr = mechdyn.simulate(press_idle().compile(), 0.05, progress=False, rtol=1e-9)
    assert tr.success and len(rows_jacobian.signatures) == before
