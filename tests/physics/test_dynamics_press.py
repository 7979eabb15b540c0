"""The source paper's case: the clutchless press in idle mode, 2 DOF (phi, psi), 0.05 s.

Set-up (``mechdyn.dynamics.paper_case``): the bundled ``clutchless_press``
model (the paper's lengths, masses, inertias and initial state phi = -64.1 deg,
psi = -46.34 deg, omega1 = 43.5 rad/s, rocker at rest), a constant drive
torque of 34.5 N m on the crank and a stiff elastic support of the ram.
Oracles: a converged adaptive run (DOP853, rtol 1e-13), measured convergence
orders, and the exact formulation against the paper's finite-difference one.
"""

import numpy as np
import pytest

from mechdyn.examples.paper_case import T_END, WILSON_STEPS, press_idle
from mechdyn.simulate.run import simulate

GRID = np.linspace(0.0, T_END, WILSON_STEPS + 1)


@pytest.fixture(scope="module")
def model():
    return press_idle().compile()


@pytest.fixture(scope="module")
def reference(model):
    tr = simulate(model, T_END, rtol=1e-13, atol=1e-15, t_eval=GRID)
    assert tr.success, tr.message
    return tr


def at_grid(tr):
    idx = np.searchsorted(tr.t, GRID - 1e-12)
    return tr.q[idx], tr.qdot[idx], tr.qddot[idx]


def test_initial_state_is_the_papers(model, reference):
    assert np.rad2deg(reference.q[0]) == pytest.approx([-64.1, -46.34], abs=1e-12)
    assert reference.qdot[0] == pytest.approx([43.5, 0.0], abs=1e-12)


def test_wilson_40_steps_error_of_the_papers_setup(model, reference):
    """The paper's own set-up: 40 steps of the linear-acceleration method over 0.05 s.
    Its error against the converged solution (printed for the report): phi about
    4e-3 rad, omega1 about 0.5 rad/s (1 %), epsilon1 a few % of its range."""
    w = simulate(model, T_END, integrator="wilson", steps=WILSON_STEPS)
    assert w.success, w.message
    q, qd, qdd = at_grid(w)
    e_phi = np.max(np.abs(q[:, 0] - reference.q[:, 0]))
    e_om = np.max(np.abs(qd[:, 0] - reference.qdot[:, 0]))
    e_eps = np.max(np.abs(qdd[:, 0] - reference.qddot[:, 0]))
    print(f"\npress, Wilson 40 steps: max error phi {e_phi:.3e} rad, omega1 {e_om:.3e} rad/s, "
          f"epsilon1 {e_eps:.3e} rad/s^2 (range {np.ptp(reference.qddot[:, 0]):.4g})")
    assert e_phi < 1e-2
    assert e_om < 0.02 * np.max(np.abs(reference.qdot[:, 0]))
    assert e_eps < 0.1 * np.ptp(reference.qddot[:, 0])


@pytest.mark.parametrize("integrator, ns, order", [("rk4", (80, 160, 320, 640), 4),
                                                   ("wilson", (40, 80, 160, 320), 2)])
def test_measured_order_on_press(model, reference, integrator, ns, order):
    errs = []
    for n in ns:
        tr = simulate(model, T_END, integrator=integrator, steps=n)
        assert tr.success, tr.message
        errs.append(np.max(np.abs(at_grid(tr)[0] - reference.q)))
    slope = np.polyfit(np.log(T_END / np.array(ns)), np.log(errs), 1)[0]
    assert slope == pytest.approx(order, abs=0.15)


def test_analogs_and_exact_give_the_same_motion(model):
    """phi(t), omega1(t), epsilon1(t) of the paper's formulation (finite-difference analogs,
    its eq. 35) and of the exact one differ by the finite-difference error, O(d^2)."""
    exact = simulate(model, T_END, integrator="wilson", steps=WILSON_STEPS)
    diffs = []
    for d_deg in (0.2, 0.1):
        fd = simulate(model, T_END, integrator="wilson", steps=WILSON_STEPS,
                      formulation="analogs", d=np.deg2rad(d_deg))
        assert fd.success, fd.message
        diffs.append([np.max(np.abs(fd.q[:, 0] - exact.q[:, 0])),
                      np.max(np.abs(fd.qdot[:, 0] - exact.qdot[:, 0])),
                      np.max(np.abs(fd.qddot[:, 0] - exact.qddot[:, 0]))])
    diffs = np.array(diffs)
    ratio = diffs[0] / diffs[1]
    assert np.all((ratio > 3.5) & (ratio < 4.5)), ratio  # halving d divides them by 4
    # at the paper's d = 0.1 deg: far below the integration error of the 40 steps
    assert diffs[1, 0] < 1e-5  # rad
    assert diffs[1, 1] < 1e-3  # rad/s
    assert diffs[1, 2] < 0.1  # rad/s^2


def test_wilson_40_steps_compiled_loop_gives_the_python_steppers_numbers(model):
    """The paper's set-up on the compiled fixed-step loop and on the Python stepper over
    the same kernel: the same samples, to round-off."""
    from mechdyn.integrate import Wilson

    fast = simulate(model, T_END, integrator="wilson", steps=WILSON_STEPS, progress=False)
    ref = simulate(model, T_END, integrator=Wilson(steps=WILSON_STEPS, compiled=False),
                   progress=False)
    assert fast.success and ref.success
    assert fast.stats["evaluations"] == ref.stats["evaluations"]
    np.testing.assert_array_equal(fast.t, ref.t)
    for a, b in ((fast.q, ref.q), (fast.qdot, ref.qdot), (fast.qddot, ref.qddot)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.max(np.abs(b)))
