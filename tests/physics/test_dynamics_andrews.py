"""Andrews' squeezing mechanism against the Test Set for IVP Solvers.

Reference: F. Mazzia, C. Magherini, *Test Set for Initial Value Problem
Solvers*, release 2.4 (2008), problem ``andrews`` (reference solution computed
with PSIDE at rtol = atol = 1e-14), values at t = 0.03 s started at rest:
beta = 15.81077119629904, Theta = -15.75637105984298, gamma = 0.04082224013073101,
Phi = -0.5347301163226948, delta = 0.5244099658805304, Omega = 0.5347301163226948,
epsilon = 1.048080741042263, beta' = 1139.920302151208, Theta' = -1424.379294994111.
mechdyn integrates one coordinate (beta) with the other six angles re-solved
from the constraints; the mass matrix is checked against the Test Set's own
seven-angle mass matrix (kinetic energy), an independent formula.
"""

import numpy as np
import pytest

from mechdyn.dynamics.lagrange import EquationsOfMotion, kinetic_energy
from mechdyn.examples import andrews
from mechdyn.kinematics.analogs import velocity_analogs
from mechdyn.simulate.run import simulate

REF = andrews.REFERENCE_T003
REF_RATES = andrews.REFERENCE_T003_RATES


@pytest.fixture(scope="module")
def model():
    return andrews.build().compile()


@pytest.fixture(scope="module")
def run_003(model):
    return simulate(model, 0.03, integrator="dop853", rtol=1e-10, atol=1e-13)


def test_angles_match_test_set_at_t003(model, run_003):
    assert run_003.success, run_003.message
    assert run_003.t[-1] == pytest.approx(0.03, abs=0)
    angles = andrews.test_set_angles(model, run_003.x[-1])
    for name, ref in REF.items():
        assert angles[name] == pytest.approx(ref, rel=1e-8), name


def test_rates_match_test_set_at_t003(model, run_003):
    xd = run_003.xdot[-1]
    th_dot = {b: xd[3 * model.body_index(b) + 2] for b in ("crank", "rod")}
    assert th_dot["crank"] == pytest.approx(REF_RATES["beta"], rel=1e-6)
    assert th_dot["rod"] - th_dot["crank"] == pytest.approx(REF_RATES["Theta"], rel=1e-6)
    assert run_003.qdot[-1, 0] == pytest.approx(REF_RATES["beta"], rel=1e-6)


def test_kinetic_energy_matches_test_set_mass_matrix(model, run_003):
    """T from mechdyn's centre-of-mass velocities = 1/2 w^T M_testset(q) w with the
    seven angle rates, at several states of the run."""
    for k in range(0, run_003.t.size, max(1, run_003.t.size // 7)):
        x, xd = run_003.x[k], run_003.xdot[k]
        ang = andrews.test_set_angles(model, x)
        th = {b: 3 * model.body_index(b) + 2 for b in
              ("crank", "rod", "triangle", "link4", "link5", "link6", "link7")}
        w = np.array([xd[th["crank"]], xd[th["rod"]] - xd[th["crank"]], xd[th["triangle"]],
                      xd[th["link4"]] - xd[th["link5"]], xd[th["link5"]],
                      xd[th["link6"]] - xd[th["link7"]], xd[th["link7"]]])
        T_ref = 0.5 * w @ andrews.test_set_mass_matrix(ang) @ w
        assert kinetic_energy(model, x, xd) == pytest.approx(T_ref, rel=1e-11)


def test_energy_balance_with_drive_to_t005(model):
    """T + U - (work of the drive torque) stays constant: the torque's work is integrated
    with the motion."""
    tr = simulate(model, 0.05, integrator="dop853", rtol=1e-11, atol=1e-14)
    assert tr.success, tr.message
    e = tr.energy
    assert tr.energy_drift() < 1e-9  # J
    # the work of the constant torque is mom * (beta - beta0): an independent check of W_nc
    W = andrews.PARAMS["mom"] * (tr.q[:, 0] - tr.q[0, 0])
    np.testing.assert_allclose(e["work_nc"], W, atol=1e-10)
    assert np.max(e["residual"]) < 1e-12


def test_compiled_path_equals_numpy_path(model):
    fast = EquationsOfMotion(model, backend="auto")
    if fast.backend != "numba":
        pytest.skip(f"compiled backend not available: {fast.backend_note}")
    slow = EquationsOfMotion(model, backend="numpy")
    tr = simulate(model, 0.01, rtol=1e-8, backend="numpy")
    for k in range(0, tr.t.size, 3):
        fast.reset(tr.x[k])
        slow.reset(tr.x[k])
        a1, p1 = fast.rhs(tr.t[k], tr.q[k], tr.qdot[k])
        a2, p2 = slow.rhs(tr.t[k], tr.q[k], tr.qdot[k])
        np.testing.assert_allclose(a1, a2, rtol=1e-12, atol=1e-12 * (1 + abs(a2).max()))
        np.testing.assert_allclose(p1, p2, rtol=1e-12, atol=1e-12 * (1 + abs(p2).max()))
        np.testing.assert_allclose(fast.kernel.B, velocity_analogs(model, tr.x[k]), rtol=1e-12,
                                   atol=1e-14)


def test_fast_run_equals_numpy_run(model):
    t_eval = np.linspace(0.0, 0.005, 6)
    a = simulate(model, 0.005, rtol=1e-10, t_eval=t_eval, backend="numpy")
    b = simulate(model, 0.005, rtol=1e-10, t_eval=t_eval, backend="auto")
    np.testing.assert_allclose(a.q, b.q, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.qdot, b.qdot, rtol=1e-9, atol=1e-9)
