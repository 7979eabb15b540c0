"""The compiled DOP853 loop against closed forms, energy balances and SciPy's DOP853.

Oracles: a torsion oscillator (a disc on a pin with a rotary spring, no gravity:
theta = theta0 + A cos(omega t), omega = sqrt(k / J)), its convergence order at fixed
steps (8 for DOP853), the energy balance of a free four-bar, and SciPy's own
implementation of the same method (``integrator="scipy-dop853"``), which must agree
to the tolerance.
"""

import numpy as np
import pytest
from dynamics_models import four_bar, pendulum

from mechdyn import Mechanism, examples
from mechdyn.dynamics.compiled import numba_available
from mechdyn.dynamics.mode_equations import PIVOT_CHECK
from mechdyn.mechanism import RotarySpring
from mechdyn.simulate import compiled_loop as compiled
from mechdyn.simulate.compiled_loop import PIVOT_FLAG
from mechdyn.simulate.run import simulate

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")

K, J, A0 = 3.0, 0.02, 0.4  # N m/rad, kg m^2, rad
OMEGA = np.sqrt(K / J)


def oscillator():
    mech = Mechanism("torsion oscillator", gravity=(0.0, 0.0))
    mech.add_body("disc", mass=1.0, inertia=J, com=(0.0, 0.0), pose=(0.0, 0.0, A0))
    mech.add_revolute("O", "ground", "disc")
    mech.add_coordinate("theta", kind="relative_angle", joint="O")
    mech.add(RotarySpring("torsion", "O", stiffness=K, free_angle=0.0))
    return mech


@pytest.fixture
def loop_calls(monkeypatch):
    """Counts the segments run in the compiled loop."""
    calls = []
    real = compiled.fast_forward

    def spy(*args, **kw):
        out = real(*args, **kw)
        calls.append(out[3])
        return out

    monkeypatch.setattr(compiled, "fast_forward", spy)
    return calls


def test_oscillator_matches_closed_form_at_the_tolerance(loop_calls):
    t_eval = np.linspace(0.0, 2.0, 201)
    tr = simulate(oscillator(), 2.0, rtol=1e-11, t_eval=t_eval, progress=False)
    assert tr.success, tr.message
    assert loop_calls == [True]  # the whole run in the compiled loop
    np.testing.assert_allclose(tr.t, t_eval)
    want = A0 * np.cos(OMEGA * t_eval)
    assert np.max(np.abs(tr.q[:, 0] - want)) < 1e-9 * A0
    assert np.max(np.abs(tr.qdot[:, 0] + A0 * OMEGA * np.sin(OMEGA * t_eval))) < 1e-8 * A0 * OMEGA
    assert np.max(np.abs(tr.qddot[:, 0] + OMEGA**2 * tr.q[:, 0])) < 1e-9 * A0 * OMEGA**2


def test_every_step_output_matches_closed_form(loop_calls):
    tr = simulate(oscillator(), 1.0, rtol=1e-10, progress=False)
    assert tr.success and loop_calls == [True]
    assert len(tr.t) == tr.stats["steps"] + 1
    assert np.max(np.abs(tr.q[:, 0] - A0 * np.cos(OMEGA * tr.t))) < 1e-8 * A0


def test_order_eight_at_fixed_steps(loop_calls):
    # tolerances so loose that every step is accepted: the step is max_step
    errors, hs = [], []
    for n in (16, 24, 32, 48):  # omega h from 0.77 to 0.26
        h = 1.0 / n
        tr = simulate(oscillator(), 1.0, rtol=1e6, atol=1e6, max_step=h, first_step=h,
                      t_eval=[1.0], progress=False)
        assert tr.stats["steps"] == n and tr.stats["rejected"] == 0
        errors.append(abs(tr.q[-1, 0] - A0 * np.cos(OMEGA)))
        hs.append(h)
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert slope == pytest.approx(8.0, abs=0.6)


def test_free_four_bar_energy_and_scipy_agree(loop_calls):
    t_eval = np.linspace(0.0, 5.0, 51)
    runs = {name: simulate(four_bar(phi0=0.3), 5.0, rtol=1e-11, integrator=name,
                           t_eval=t_eval, progress=False)
            for name in ("dop853", "scipy-dop853")}
    assert loop_calls == [True]  # only the default ran in the compiled loop
    ours, ref = runs["dop853"], runs["scipy-dop853"]
    assert ours.success and ref.success
    scale = np.max(ours.energy["kinetic"])
    assert ours.energy_drift() < 1e-9 * scale
    assert np.max(ours.energy["residual"]) < 1e-12
    assert np.max(np.abs(ours.q - ref.q)) < 1e-8
    assert np.max(np.abs(ours.qdot - ref.qdot)) < 1e-7 * np.max(np.abs(ref.qdot))
    # the reactions come from the same evaluation as in the Python loop
    for el in ("O", "C"):
        f_ours = ours.stats["variable_structure"].forces[el]
        f_ref = ref.stats["variable_structure"].forces[el]
        assert np.max(np.abs(f_ours - f_ref)) < 1e-6 * np.max(np.abs(f_ref))


def test_pendulum_turning_points_are_checked_and_passed(loop_calls):
    # a pendulum swinging: its rate changes sign every half period (flagged steps that
    # Python looks at), its energy stays
    tr = simulate(pendulum(theta0_from_down_deg=60.0), 4.0, rtol=1e-11, progress=False)
    assert tr.success and loop_calls == [True]
    assert np.sum(np.diff(np.sign(tr.qdot[:, 0])) != 0) >= 4
    assert tr.energy_drift() < 1e-9 * np.max(tr.energy["kinetic"])


def test_pivot_flag_is_the_singularity_check_threshold():
    assert PIVOT_FLAG == PIVOT_CHECK


@pytest.mark.parametrize("name", [n for n in examples.names()
                                  if not examples.load(n).compile().has_switching])
def test_bundled_fixed_structure_examples_agree_with_scipy(name, loop_calls):
    model = examples.load(name).compile()
    t_eval = np.linspace(0.0, 0.05, 11)
    ours, ref = (simulate(model, 0.05, rtol=1e-12, t_eval=t_eval, integrator=i, progress=False)
                 for i in ("dop853", "scipy-dop853"))
    assert ours.status == ref.status and np.array_equal(ours.t, ref.t)
    if ours.stats["backend"] == "numba":
        assert loop_calls == [True]
    scale = np.where(model.coord_is_angle, 1.0, model.length_scale)
    assert np.max(np.abs(ours.q - ref.q) / scale) < 1e-9
    assert np.max(np.abs(ours.qdot - ref.qdot)) < 1e-8 * max(1.0, np.max(np.abs(ref.qdot)))


# ---------------------------------------------------------------- the fixed-step loops
def _fixed(name, compiled, **opts):
    from mechdyn.integrate import RungeKutta4, Wilson

    return (Wilson if name == "wilson" else RungeKutta4)(compiled=compiled, **opts)


FIXED = [("rk4", {}), ("wilson", {}), ("wilson", {"theta": 1.4, "iterations": 3}),
         ("wilson", {"tol": None, "iterations": 2})]


def _agree(a, b, tol=1e-12, evaluations=True):
    """Two runs agree sample by sample to ``tol`` (relative to each column's largest
    value), with as many evaluations."""
    assert a.status == b.status and np.array_equal(a.t, b.t)
    assert a.stats["evaluations"] == b.stats["evaluations"] or not evaluations
    for u, v in ((a.q, b.q), (a.qdot, b.qdot), (a.qddot, b.qddot), (a.x, b.x)):
        assert np.max(np.abs(u - v)) <= tol * max(1.0, np.max(np.abs(v)))


@pytest.mark.parametrize("name", [n for n in examples.names()
                                  if not examples.load(n).compile().has_switching])
@pytest.mark.parametrize("integ, opts", FIXED[:2])
def test_bundled_examples_fixed_step_compiled_as_python(name, integ, opts, loop_calls):
    """The compiled RK4 / Wilson loops and the Python steppers over the same kernel: the
    same numbers (to 1e-12) on every bundled fixed-structure example, the output times
    between the steps interpolated alike."""
    model = examples.load(name).compile()
    t_eval = np.linspace(0.0, 0.05, 13)  # not on the grid of 100 steps
    ours, ref = (simulate(model, 0.05, integrator=_fixed(integ, c, **opts),
                          t_eval=t_eval, progress=False) for c in (True, False))
    if ours.stats["backend"] == "numba":
        assert loop_calls == [True]
    _agree(ours, ref)


@pytest.mark.parametrize("integ, opts", FIXED)
def test_fixed_step_loop_on_a_swinging_pendulum_as_python(integ, opts, loop_calls):
    # rates changing sign (flagged steps), every step sampled, Wilson-theta, no early stop
    runs = [simulate(pendulum(theta0_from_down_deg=60.0), 3.0,
                     integrator=_fixed(integ, c, dt=1e-2, **opts), progress=False)
            for c in (True, False)]
    assert loop_calls == [True]
    assert np.sum(np.diff(np.sign(runs[0].qdot[:, 0])) != 0) >= 3
    _agree(*runs)
    assert runs[0].stats["steps"] == 300


def test_fixed_step_more_samples_in_a_step_than_the_buffers(loop_calls):
    # 3000 output times in 2 steps: a step cannot be shortened, the Python stepper goes on
    te = np.linspace(0.0, 0.2, 3000)
    runs = [simulate(oscillator(), 0.2, integrator=_fixed("rk4", c, steps=2), t_eval=te,
                     progress=False) for c in (True, False)]
    assert loop_calls == [False]
    _agree(*runs, evaluations=False)  # the loop's first evaluation is counted too


@pytest.mark.parametrize("integ, order", [("rk4", 4), ("wilson", 2)])
def test_fixed_step_orders_in_the_compiled_loop(integ, order, loop_calls):
    """Measured orders against the closed form of the torsion oscillator."""
    errors, hs = [], []
    for n in (100, 200, 400, 800):  # omega h from 0.12 to 0.015
        tr = simulate(oscillator(), 1.0, integrator=integ, steps=n, t_eval=[1.0],
                      progress=False)
        errors.append(abs(tr.q[-1, 0] - A0 * np.cos(OMEGA)))
        hs.append(1.0 / n)
    assert loop_calls == [True] * 4
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert slope == pytest.approx(order, abs=0.15)



@pytest.mark.parametrize("integ, opts", FIXED[:3])
def test_switched_press_fixed_step_compiled_as_python(integ, opts, monkeypatch):
    """A variable-structure run (the bundled press cycle: stops, impacts, the lock): its
    segments with event functions take their steps from the compiled fixed-step loop,
    one by one, each checked in Python; the events fall at the same times and the
    samples agree with the Python stepper's to round-off."""
    calls = []
    real = compiled.kept_steps

    def spy(*args, **kw):
        out = real(*args, **kw)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(compiled, "kept_steps", spy)
    model = examples.load("press_cycle").compile()
    runs = [simulate(model, 0.1, integrator=_fixed(integ, c, dt=1e-4, **opts), progress=False)
            for c in (True, False)]
    assert calls and all(calls)
    assert len(runs[0].events) >= 3
    assert [(e.t, e.kind, e.element) for e in runs[0].events] == \
        [(e.t, e.kind, e.element) for e in runs[1].events]
    _agree(*runs)
