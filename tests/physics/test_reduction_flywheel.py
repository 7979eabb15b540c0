"""Steady cycle, coefficient of speed fluctuation, flywheel sizing and start-up.

Oracles:
* a machine of constant inertia J driven by a constant torque T0 against the load
  T0 + a sin(2 phi) has the closed-form steady motion
  J omega^2 / 2 = J omega_0^2 / 2 + a (cos 2phi - 1) / 2, so delta = a / (J omega_m^2)
  exactly with omega_m = (omega_max + omega_min) / 2 - the energy method; with the
  true average speed the estimate is off by O(delta^2), its known approximation;
* the sized flywheel is checked by integrating the equation of motion in time;
* the shooting solution is the limit of a long time-domain run;
* during a direct-on-line start the motor passes through its critical slip, so the
  peak motor torque is the catalogue breakdown torque M_k = 2.2 M_n.
"""

import math

import numpy as np
import pytest

from mechdyn.errors import IntegrationError, LockupError, ModelError
from mechdyn.mechanism.catalogue import induction_motor
from mechdyn.mechanism.motors import GearStage
from mechdyn.modelfile.drives import drive_from_table
from mechdyn.reduction.reduce import (
    ReducedMachine,
    mode_mechanism,
    reduce_model,
    run_reduced,
    size_flywheel,
    startup,
    steady_state,
)

J0, T0, A = 0.05, 10.0, 4.0  # kg m^2, N m, N m


def sine_machine(extra=0.0):
    """Constant driving torque T0 against the load T0 + A sin(2 phi)."""
    m = ReducedMachine.constant(J0, lambda t, p, w: T0 - (T0 + A * math.sin(2 * p)))
    return m.with_extra_inertia(extra)


def time_domain_delta(machine, omega0, cycles=3):
    """delta measured on a time-domain run started at phi = 0 with omega0."""
    period_t = machine.period / omega0
    run = run_reduced(machine, cycles * period_t, phi0=0.0, omega0=omega0, rtol=1e-11,
                      atol=1e-12, t_eval=np.linspace(0, cycles * period_t, 4000 * cycles))
    wmax, wmin = run.omega.max(), run.omega.min()
    return (wmax - wmin) / (0.5 * (wmax + wmin)), run


def test_steady_cycle_of_constant_inertia_matches_closed_form():
    wm = 30.0
    c = steady_state(sine_machine(), omega_mean=wm)
    assert c.omega_mean == pytest.approx(wm, rel=1e-12)
    # closed form: omega_max^2 - omega_min^2 = 2 A / J, at phi = 0 (pi) and pi/2 (3 pi/2)
    assert c.omega_max**2 - c.omega_min**2 == pytest.approx(2 * A / J0, rel=1e-9)
    assert c.delta == pytest.approx(A / (J0 * wm**2), rel=1e-9)
    assert math.sin(2 * c.phi_at_min) == pytest.approx(0.0, abs=1e-6)
    assert math.cos(2 * c.phi_at_min) == pytest.approx(-1.0, abs=1e-9)
    # the cycle time is the integral of dphi / omega
    om = np.sqrt(c.omega_max**2 + A * (np.cos(2 * c.phi) - 1) / J0)
    assert c.cycle_time == pytest.approx(np.trapezoid(1 / om, c.phi), rel=1e-5)
    assert np.all(np.diff(c.t) > 0)


def test_energy_method_estimate_with_true_average_speed_is_off_by_delta_squared():
    wm = 30.0
    c = steady_state(sine_machine(), omega_mean=wm)
    estimate = A / (J0 * c.omega_avg**2)  # the energy method fed with the average speed
    assert abs(c.delta_avg - estimate) <= c.delta**2
    assert abs(c.delta - estimate) > 1e-4 * c.delta  # ... which is not the exact mean


def test_flywheel_for_target_delta_is_confirmed_by_simulation():
    wm, delta = 30.0, 0.02
    fs = size_flywheel(sine_machine(), delta, omega_mean=wm, method="energy")
    assert fs.J_fly == pytest.approx(A / (delta * wm**2) - J0, rel=1e-6)
    assert fs.delta_E_max == pytest.approx(A, rel=1e-8)
    assert fs.delta_simulated == pytest.approx(delta, rel=1e-6)
    assert fs.delta_without == pytest.approx(A / (J0 * wm**2), rel=1e-8)
    # independent check: integrate the equation of motion in time with the flywheel
    with_fly = sine_machine(fs.J_fly)
    d_sim, _ = time_domain_delta(with_fly, fs.cycle.omega[0])
    assert d_sim == pytest.approx(delta, rel=0.02)
    assert d_sim == pytest.approx(delta, rel=1e-6)  # in fact exact for constant J


def test_flywheel_on_motor_shaft_through_gear():
    fs = size_flywheel(sine_machine(), 0.02, omega_mean=30.0, gear_ratio=4.0, confirm=False)
    assert fs.J_fly_motor == pytest.approx(fs.J_fly / 16.0, rel=1e-15)
    assert fs.delta_simulated is None


def test_no_flywheel_needed_when_the_machine_is_smooth_enough():
    fs = size_flywheel(sine_machine(), 0.5, omega_mean=30.0)
    assert fs.J_fly == 0.0 and "no flywheel is needed" in fs.message


def test_unbalanced_constant_torque_has_no_steady_motion():
    m = ReducedMachine.constant(J0, lambda t, p, w: 0.5 - A * math.sin(2 * p))
    with pytest.raises(IntegrationError, match="no steady motion"):
        steady_state(m, omega_mean=30.0)


def test_machine_that_cannot_pass_its_load_stalls():
    m = ReducedMachine.constant(J0, lambda t, p, w: -40.0 * max(math.sin(p), 0.0))
    with pytest.raises(LockupError, match="stalls"):
        steady_state(m, omega_mean=5.0)


def test_flywheel_arguments_are_checked():
    with pytest.raises(ModelError, match="delta"):
        size_flywheel(sine_machine(), 0.0, omega_mean=30.0)
    with pytest.raises(ModelError, match="method"):
        size_flywheel(sine_machine(), 0.05, omega_mean=30.0, method="guess")
    with pytest.raises(ModelError, match="omega_mean"):
        size_flywheel(sine_machine(), 0.05)


# ------------------------------------------------------------------ motor-driven machines
@pytest.fixture(scope="module")
def motor_machine():
    gear = GearStage(induction_motor("4A80B4U3", "extended"), 3.4, 0.95)
    load = lambda t, p, w: -(8.0 * 3.4 * 0.95 + 20.0 * math.sin(p) ** 8)  # noqa: E731
    return ReducedMachine.constant(0.2, load, drive=gear)


def test_shooting_finds_the_limit_cycle_of_a_long_run(motor_machine):
    c = steady_state(motor_machine)
    # independent: integrate in time from a different speed until the transient dies out
    run = run_reduced(motor_machine, 2.0, phi0=0.0, omega0=30.0, rtol=1e-10, atol=1e-10,
                      t_eval=np.linspace(1.5, 2.0, 2001), integrator="dop853")
    ref = np.interp(run.phi % (2 * np.pi), c.phi, c.omega)
    np.testing.assert_allclose(run.omega, ref, rtol=2e-6)
    # the mean driving power balances the load over the cycle
    assert np.trapezoid(c.M, c.phi) == pytest.approx(0.0, abs=1e-6 * np.max(np.abs(c.M)))


def test_motor_machine_flywheel_simulation_method_meets_target(motor_machine):
    fs = size_flywheel(motor_machine, 0.01, method="simulation", rtol=1e-4)
    assert fs.delta_simulated == pytest.approx(0.01, rel=1e-4)
    assert fs.delta_without > 0.01
    assert fs.J_fly_motor == pytest.approx(fs.J_fly / 3.4**2)
    # the energy estimate is of the right size (the motor's slope smooths the speed)
    assert 0.8 < fs.J_fly_refined / fs.J_fly < 1.3


# ------------------------------------------------------------------ the press
def press(load=None):
    from mechdyn import examples
    from mechdyn.mechanism.process import punch_load

    mech = mode_mechanism(examples.load("clutchless_press"), engage=["rocker_lock"],
                          offsets={"rocker_lock": (0.0, 0.0, 0.0)}, drop=["psi"])
    mech.drives[:] = [drive_from_table(
        {"type": "induction_motor", "coordinate": "phi", "catalogue": "4A80B4U3",
         "characteristic": "extended", "gear_ratio": 3.4, "efficiency": 0.95}, "press test")]
    if load:
        # 10 kN over the last 3 mm of the ram's stroke towards -x (BDC: x_C = -5 mm)
        mech.add(punch_load("punch", "slider", (0.0, 0.0), 10e3, end=-0.005, travel=0.003,
                            coordinate="x", towards=-1, ramp=0.0005))
    return mech.compile()


@pytest.fixture(scope="module")
def press_machine():
    model = press(load=True)
    return reduce_model(model, steps=1441, omega=43.5).machine(model)


def test_press_refined_energy_method_beats_basic_for_variable_inertia(press_machine):
    sim = size_flywheel(press_machine, 0.05, method="simulation", rtol=1e-4)
    assert sim.delta_simulated == pytest.approx(0.05, rel=1e-4)
    # J_red of the press varies by ~40 % over a turn: the refined form accounts for it
    assert abs(sim.J_fly_refined / sim.J_fly - 1) < 0.05
    assert abs(sim.J_fly_refined - sim.J_fly) < abs(sim.J_fly_energy - sim.J_fly)


def test_press_startup_peak_motor_torque_is_breakdown_torque(press_machine):
    res = startup(press_machine, 0.6, load_window=(math.radians(134.75), math.pi))
    motor = press_machine.drive.motor
    assert res.status == "success"
    assert res.peak_motor_torque == pytest.approx(motor.breakdown_torque, rel=1e-3)
    assert res.peak_motor_torque <= motor.breakdown_torque * (1 + 1e-12)
    assert res.peak_drive_torque == pytest.approx(0.95 * 3.4 * res.peak_motor_torque, rel=1e-9)
    # the run settles on the steady cycle, within about 0.1 s (J ~ 0.1 kg m^2, M ~ 60 N m)
    assert 0.02 < res.t_steady < 0.3
    assert res.speed_dip > 0
    assert res.omega_mean < motor.synchronous_speed / 3.4
    summary = res.summary()
    assert set(summary) >= {"t_steady_s", "peak_motor_torque_Nm", "speed_dip_rad_s"}
