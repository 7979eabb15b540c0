"""The default integrator never calls SciPy's solvers: with every ``OdeSolver`` and
``solve_ivp`` made to raise, each bundled example runs to its end on the defaults of
``simulate`` (DOP853: the compiled loop where it can run, the same method and step
control stepped from Python elsewhere -- friction in the joints, the NumPy path)."""

import numpy as np
import pytest
import scipy.integrate

import mechdyn
from mechdyn import examples
from mechdyn.reduction.reduce import (
    ReducedMachine,
    energy_speed,
    reduce_model,
    run_reduced,
    size_flywheel,
    startup,
)

pytestmark = pytest.mark.timeout(120)

#: the examples' own run lengths (their files' ``mechdyn simulate`` lines), shortened to
#: 0.05 s where longer (press_cycle: 1.7 s, bolt_buffer: 0.2 s is short enough)
T_END = {"bolt_buffer": 0.2}


class SciPySolverCalled(AssertionError):
    """A SciPy solver was called by a run on the defaults."""


@pytest.fixture
def no_scipy_solvers(monkeypatch):
    """Every SciPy ODE solver (their base ``OdeSolver``, ``solve_ivp``, ``odeint``,
    ``ode``) raises when called."""

    def boom(*args, **kwargs):
        raise SciPySolverCalled("a SciPy ODE solver was called")

    monkeypatch.setattr(scipy.integrate.OdeSolver, "__init__", boom)
    for name in ("solve_ivp", "odeint", "ode", "DOP853", "RK45", "RK23", "Radau", "BDF",
                 "LSODA"):
        monkeypatch.setattr(scipy.integrate, name, boom)


def test_the_fixture_catches_a_named_scipy_solver(no_scipy_solvers):
    with pytest.raises(SciPySolverCalled):
        mechdyn.simulate(examples.load("slider_crank"), 0.01, integrator="scipy-dop853",
                         progress=False)


@pytest.mark.parametrize("name", examples.names())
def test_every_example_runs_to_its_end_without_scipy(name, no_scipy_solvers):
    t_end = T_END.get(name, 0.05)
    traj = mechdyn.simulate(examples.load(name), t_end, progress=False)
    assert traj.success, (traj.status, traj.message)
    assert traj.t[-1] == pytest.approx(t_end, rel=1e-12)
    assert traj.stats["integrator"] == "dop853"


def test_solve_on_dop853_without_scipy(no_scipy_solvers):
    sol = mechdyn.integrate.solve("dop853", lambda t, q, v: -q, 0.0, [1.0], [0.0], np.pi,
                                  rtol=1e-10)
    assert sol.status == "success" and sol.t[-1] == np.pi
    assert sol.q[-1, 0] == pytest.approx(-1.0, abs=1e-8)


def test_reduction_runs_without_scipy(no_scipy_solvers):
    """The reduced slider-crank example on the defaults: its start-up from rest by the
    motor, the steady cycle it approaches and a flywheel for it, and its run-down with
    the motor off against a 2 N m brake, whose speeds the energy form (the work of the
    reduced torque integrated along phi) gives again."""
    model = examples.load("slider_crank").compile()
    red = reduce_model(model, steps=181)
    machine = red.machine(model)
    res = startup(machine, 0.3, samples_per_second=200.0)
    assert res.run.stats["integrator"] == "dop853"
    assert res.run.t[-1] == pytest.approx(0.3, rel=1e-12)
    assert np.all(np.diff(res.run.phi) > 0) and res.run.omega[-1] > 100.0
    assert res.steady.omega_min < res.steady.omega_mean < res.steady.omega_max
    fs = size_flywheel(machine, 0.5 * res.steady.delta, method="simulation", rtol=1e-3)
    assert fs.J_fly > 0 and fs.delta_simulated == pytest.approx(0.5 * res.steady.delta,
                                                                rel=1e-3)
    coast = ReducedMachine.from_reduction(red).with_driving_torque(-2.0)
    w0 = res.steady.omega_mean
    run = run_reduced(coast, 0.1, omega0=w0, t_eval=np.linspace(0.0, 0.1, 11), rtol=1e-11,
                      atol=1e-12)
    assert run.status == "success" and run.omega[-1] < w0
    np.testing.assert_allclose(energy_speed(coast, run.phi, omega0=w0), run.omega, rtol=1e-7)


@pytest.mark.parametrize("name", ["slider_crank", "four_bar", "clutchless_press"])
def test_numpy_path_takes_the_steps_of_the_compiled_loop(name):
    """One method and one step control: the Python stepper on the NumPy path takes the
    compiled loop's steps (the same numbers of steps, rejections and evaluations; the
    step sizes agree to 1e-3, the error estimates at rtol 1e-10 seeing the two paths'
    position solves differ at their tolerance: 2e-8 on slider_crank, 3e-4 on
    clutchless_press)."""
    a = mechdyn.simulate(examples.load(name), 0.05, progress=False)
    b = mechdyn.simulate(examples.load(name), 0.05, progress=False, backend="numpy")
    assert a.stats["steps"] == b.stats["steps"]
    assert a.stats["rejected"] == b.stats["rejected"]
    assert a.stats["evaluations"] == b.stats["evaluations"]
    assert np.allclose(a.t, b.t, rtol=1e-3, atol=0.0)
    assert np.allclose(a.q[-1], b.q[-1], rtol=1e-8, atol=1e-9)
