"""Impacts on stops and plastic locking, against closed forms and momentum balance."""

import numpy as np
import pytest

from mechdyn.mechanism import Mechanism, Spring
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import CoordinateLock, Switch, add_element
from mechdyn.simulate.segments import format_events, simulate_events

K, M, D, X0 = 800.0, 2.0, 0.05, 0.1


def _oscillator(e):
    m = Mechanism("mass on a spring", gravity=(0.0, 0.0))
    m.add_ground(points={"A": (-1.0, 0.0)})
    m.add_body("mass", mass=M, inertia=0.1)
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    m.add(Spring("k", "ground", "A", "mass", (0.0, 0.0), stiffness=K, free_length=1.0))
    add_element(m, Stop("stop", "s", lower=-D, restitution=e))
    return m


def _closed_form(e, n):
    """Impact times, approach speeds and losses of x'' = -w^2 x bouncing on x = -D."""
    w = np.sqrt(K / M)
    t = np.arccos(-D / X0) / w
    v = -X0 * w * np.sin(w * t)
    times, losses, rebounds = [t], [0.5 * M * v ** 2 * (1 - e ** 2)], [-e * v]
    for _ in range(n - 1):
        vp = -e * v
        # x(tau) = -D cos(w tau) + vp/w sin(w tau) is back at -D when
        # tan(w tau / 2) = -vp / (w D)
        tau = (2 * np.pi - 2 * np.arctan(vp / (w * D))) / w
        t += tau
        v = -vp  # symmetric free flight: it comes back with the opposite speed
        times.append(t)
        losses.append(0.5 * M * v ** 2 * (1 - e ** 2))
        rebounds.append(-e * v)
    return np.array(times), np.array(losses), np.array(rebounds)


@pytest.mark.parametrize("e", [0.6, 0.3])
def test_restitution_rebound_times_and_losses_match_closed_form(e):
    tr = simulate_events(_oscillator(e), 0.55, q0=[X0], qdot0=[0.0], dt_out=0.01, rtol=1e-12)
    assert tr.status == "success", tr.message
    impacts = [ev for ev in tr.events if ev.kind == "impact"]
    times, losses, rebounds = _closed_form(e, len(impacts))
    assert len(impacts) >= 2
    np.testing.assert_allclose([ev.t for ev in impacts], times, rtol=0, atol=1e-10)
    np.testing.assert_allclose([ev.energy_lost for ev in impacts], losses, rtol=1e-9)
    np.testing.assert_allclose([ev.qdot_after[0] for ev in impacts], rebounds, rtol=1e-9)
    np.testing.assert_allclose([ev.q_after[0] for ev in impacts], -D, atol=1e-12)


def test_event_time_located_to_1e_10_against_analytic_crossing():
    m = _oscillator(0.5)
    add_element(m, CoordinateLock("hold", "s"))
    add_element(m, Switch("at_zero", "engage", "hold", variable="s", value=0.02, direction=-1))
    tr = simulate_events(m, 0.2, q0=[X0], qdot0=[0.0], dt_out=0.05)
    w = np.sqrt(K / M)
    t_cross = np.arccos(0.02 / X0) / w
    ev = [e for e in tr.events if e.kind == "engage"][0]
    assert abs(ev.t - t_cross) < 1e-10
    # the lock holds s = 0.02 with a plastic stop of all motion: all energy left is potential
    assert ev.energy_lost == pytest.approx(0.5 * M * (X0 * w * np.sin(w * t_cross)) ** 2,
                                           rel=1e-9)
    assert np.allclose(tr.q[tr.t > ev.t + 1e-9, 0], 0.02, atol=1e-12)
    assert "engage" in format_events(tr.events)


def _discs(offset=(0.0, 0.0), weld=True):
    m = Mechanism("two coaxial discs", gravity=(0.0, 0.0))
    m.add_body("d1", mass=3.0, inertia=0.2, com=offset)
    m.add_body("d2", mass=1.0, inertia=0.05)
    m.add_revolute("O1", "ground", "d1")
    m.add_coordinate("th1", kind="angle", body="d1")
    m.add_coordinate("th2", kind="angle", body="d2")
    if weld:
        m.add_revolute("O2", "ground", "d2")
        m.add_lock("clutch", "d1", "d2", engaged=False)
    else:
        m.add_revolute("R", "d1", "d2")
        add_element(m, CoordinateLock("clutch", "joint:R"))
    add_element(m, Switch("on", "engage", "clutch", times=(0.1,)))
    add_element(m, Switch("off", "release", "clutch", times=(0.2,)))
    return m


@pytest.mark.parametrize("weld", [True, False])
def test_plastic_locking_conserves_angular_momentum_and_loses_the_analytic_energy(weld):
    w1, w2 = 10.0, -4.0
    tr = simulate_events(_discs(weld=weld), 0.3, q0=[0.0, 0.0], qdot0=[w1, w2], dt_out=0.01)
    assert tr.status == "success", tr.message
    J1, J2 = 0.2, 0.05
    H = J1 * w1 + J2 * w2
    w = H / (J1 + J2)
    eng = [e for e in tr.events if e.kind == "engage"][0]
    rel = [e for e in tr.events if e.kind == "release"][0]
    assert eng.t == pytest.approx(0.1, abs=1e-12)
    np.testing.assert_allclose(eng.qdot_after, [w, w], rtol=1e-12)
    assert J1 * eng.qdot_after[0] + J2 * eng.qdot_after[1] == pytest.approx(H, rel=1e-12)
    # 1/2 dq^T A dq of the momentum balance
    dq = np.array([w1 - w, w2 - w])
    assert eng.energy_lost == pytest.approx(0.5 * (J1 * dq[0] ** 2 + J2 * dq[1] ** 2),
                                            rel=1e-12)
    # the impulse on disc 2 is its momentum change
    imp = eng.impulses["clutch"]
    imp = imp[2] if np.ndim(imp) else imp  # weld: (Px, Py, L); coordinate lock: L
    assert imp == pytest.approx(J2 * (w - w2), rel=1e-9)
    # releasing causes no jump
    np.testing.assert_allclose(rel.qdot_after, rel.qdot_before, rtol=0, atol=1e-12)
    assert rel.energy_lost == 0.0
    assert np.max(tr.energy["residual"]) < 1e-10


def test_locking_with_offset_centre_of_mass_uses_inertia_about_the_axis():
    tr = simulate_events(_discs(offset=(0.02, 0.0), weld=False), 0.15, q0=[0.0, 0.0],
                         qdot0=[10.0, -4.0], dt_out=0.01)
    J1 = 0.2 + 3.0 * 0.02 ** 2
    J2 = 0.05
    w = (J1 * 10.0 - J2 * 4.0) / (J1 + J2)
    eng = [e for e in tr.events if e.kind == "engage"][0]
    np.testing.assert_allclose(eng.qdot_after, [w, w], rtol=1e-12)
    assert eng.energy_lost == pytest.approx(0.5 * J1 * J2 / (J1 + J2) * 14.0 ** 2, rel=1e-12)


def test_table_of_a_switched_run_has_the_mode_and_the_load_on_the_frame():
    # free flight: the frame carries only the spring's end at A, a tension K s pulling A
    # towards the mass (+x); in contact the stop's reaction is added
    tr = simulate_events(_oscillator(0.0), 0.5, q0=[X0], qdot0=[0.0], dt_out=0.01, rtol=1e-10)
    df = tr.to_dataframe()
    vs = tr.stats["variable_structure"]
    assert list(df["mode_index"]) == list(vs["mode_index"])
    free = (df["mode"] == "-").to_numpy()
    assert free.sum() > 10
    s_m = df["s_m"].to_numpy()
    np.testing.assert_allclose(df["Fx_frame_N"].to_numpy()[free], K * s_m[free], rtol=0,
                               atol=1e-9 * K * X0)
    np.testing.assert_allclose(df["Fy_frame_N"].to_numpy(), 0.0, atol=1e-9 * K * X0)


def test_plot_of_a_switched_run_is_written(tmp_path):
    from mechdyn.results.plot_dynamics import plot_trajectory

    tr = simulate_events(_oscillator(0.5), 0.3, q0=[X0], qdot0=[0.0], dt_out=0.01)
    out = plot_trajectory(tr, tmp_path / "run.png")
    assert out.stat().st_size > 10_000
