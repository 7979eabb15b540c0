"""The compiled kernel's start for the position solve: a prediction of second order.

Oracle: the order of the prediction, seen in the Newton corrections it leaves. From a
converged pose, a change of q_I by q_I' d (d small) is predicted by the analogs alone
with an error of order d^2 and with the curvature term to order d^3: for a turn of the
slider-crank's crank by 1e-5 rad the first (about 1e-11 m) is above the solve's
tolerance (1e-13 of the length scale, 2e-14 m) and the second (under 1e-15 m) below
it, so the solve must end without a correction. From a pose solved at rest the
curvature along the rates is unknown: the same change then needs a correction. The
poses are checked against the NumPy path's position solve.
"""

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.dynamics.lagrange import EquationsOfMotion
from mechdyn.kernels.lagrange_numba import N_FLAGS, W_ERR, W_ITER
from mechdyn.simulate.run import simulate


@pytest.fixture(scope="module")
def setup():
    model = examples.load("slider_crank").compile()
    fast = EquationsOfMotion(model, backend="auto")
    if fast.backend != "numba":
        pytest.skip(f"compiled backend not available: {fast.backend_note}")
    slow = EquationsOfMotion(model, backend="numpy")
    tr = simulate(model, 0.02, rtol=1e-10, backend="numpy")
    return model, fast, slow, tr


def _corrections(fast):
    return int(fast.kernel.ws[-N_FLAGS + W_ITER]), float(fast.kernel.ws[-N_FLAGS + W_ERR])


@pytest.mark.parametrize("k", [2, 6, 11])
def test_a_small_change_along_the_rates_needs_no_correction(setup, k):
    model, fast, slow, tr = setup
    q, qd = tr.q[k], tr.qdot[k]
    fast.reset(tr.x[k])
    assert fast.rhs(tr.t[k], q, qd) is not None  # converged there: the analogs and b kept
    d = 1e-5 / np.max(np.abs(qd))  # s: the crank turns by 1e-5 rad
    assert fast.rhs(tr.t[k] + d, q + d * qd, qd) is not None
    it, err = _corrections(fast)
    assert it == 0, f"{it} Newton corrections after the second-order prediction"
    assert err <= 1e-13 * max(model.length_scale, 1e-3)
    slow.reset(tr.x[k])
    slow.rhs(tr.t[k] + d, q + d * qd, qd)
    np.testing.assert_allclose(fast.kernel.x, slow.x, rtol=0, atol=1e-12)


def test_without_rates_the_prediction_is_of_first_order(setup):
    model, fast, slow, tr = setup
    k = 10
    q, qd = tr.q[k], tr.qdot[k]
    fast.reset(tr.x[k])
    # converged there at rest: no curvature along the rates is known
    assert fast.rhs(tr.t[k], q, np.zeros_like(qd)) is not None
    d = 1e-5 / np.max(np.abs(qd))
    assert fast.rhs(tr.t[k] + d, q + d * qd, qd) is not None
    it, _ = _corrections(fast)
    assert it >= 1
    slow.reset(tr.x[k])
    slow.rhs(tr.t[k] + d, q + d * qd, qd)
    np.testing.assert_allclose(fast.kernel.x, slow.x, rtol=0, atol=1e-12)
