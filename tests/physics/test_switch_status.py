"""Switches that cannot be carried out end the run cleanly, with the data kept."""

import numpy as np
import pytest

from mechdyn.errors import ModelError
from mechdyn.mechanism import Mechanism, Spring
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import CoordinateLock, Switch, add_element
from mechdyn.simulate import switching as switching
from mechdyn.simulate.gaps import ContactError
from mechdyn.simulate.segments import format_events, simulate_events


def _oscillator():
    m = Mechanism("mass on a spring", gravity=(0.0, 0.0))
    m.add_ground(points={"A": (-1.0, 0.0)})
    m.add_body("mass", mass=2.0, inertia=0.1)
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    m.add(Spring("k", "ground", "A", "mass", (0.0, 0.0), stiffness=800.0, free_length=1.0))
    return m


def test_a_lock_that_would_need_a_position_jump_stops_the_run_with_the_data_kept():
    m = _oscillator()
    add_element(m, CoordinateLock("hold", "s", value=0.5))  # far outside the motion
    add_element(m, Switch("go", "engage", "hold", times=(0.05,)))
    tr = simulate_events(m, 0.2, q0=[0.1], qdot0=[0.0], dt_out=0.01)
    assert tr.status == "assembly-failed"
    assert "hold" in tr.message and "position jump" in tr.message
    assert tr.t[-1] == pytest.approx(0.05, abs=1e-12)
    assert tr.t.size >= 6
    w = np.sqrt(400.0)
    np.testing.assert_allclose(tr.q[:, 0], 0.1 * np.cos(w * tr.t), atol=1e-9)


def test_a_contact_problem_without_solution_stops_the_run_with_the_data_kept(monkeypatch):
    m = _oscillator()
    add_element(m, Stop("stop", "s", lower=-0.05))
    real = switching.resolve_mode
    calls = {"n": 0}

    def failing(*args, **kw):
        calls["n"] += 1
        if calls["n"] > 1:  # the initial mode is fine; the impact's contact problem is not
            raise ContactError("the contact problem has no solution", t=args[1])
        return real(*args, **kw)

    monkeypatch.setattr(switching, "resolve_mode", failing)
    tr = simulate_events(m, 0.3, q0=[0.1], qdot0=[0.0], dt_out=0.01)
    assert tr.status == "no-contact-solution"
    assert "no solution" in tr.message
    t_hit = np.arccos(-0.5) / 20.0
    assert tr.t[-1] == pytest.approx(t_hit, abs=1e-10)


def test_guarded_crossing_switch_fires_only_when_the_guard_holds():
    m = _oscillator()
    add_element(m, CoordinateLock("hold", "s"))
    # s falls through 0 at t = pi/40 (velocity < 0) and again at 3 pi/40 rising
    add_element(m, Switch("catch", "engage", "hold", variable="s", value=0.0, direction=0,
                          guard=(("s_dot", ">", 0.0),)))
    tr = simulate_events(m, 0.3, q0=[0.1], qdot0=[0.0], dt_out=0.01)
    kinds = [(e.kind, round(e.t, 9)) for e in tr.events]
    assert kinds[0] == ("ignored", round(np.pi / 40, 9))
    assert kinds[1] == ("engage", round(3 * np.pi / 40, 9))
    assert abs(tr.events[1].t - 3 * np.pi / 40) < 1e-10
    assert "ignored" in format_events(tr.events)


def test_switch_with_an_unknown_target_is_reported_with_the_valid_names():
    m = _oscillator()
    add_element(m, CoordinateLock("hold", "s"))
    add_element(m, Switch("go", "engage", "hodl", times=(0.1,)))
    with pytest.raises(ModelError, match="valid lock names: 'hold'"):
        simulate_events(m, 0.2)
