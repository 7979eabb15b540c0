"""The whole clutchless-press cycle and the bolt-buffer automaton run through every switch."""

import numpy as np
import pytest

from mechdyn.examples import bolt_buffer, press_cycle
from mechdyn.simulate_events import format_events


@pytest.fixture(scope="module")
def press():
    return press_cycle.run(2)


@pytest.mark.slow
def test_press_runs_idle_engage_lock_stroke_release_twice(press):
    tr = press
    assert tr.status == "success", tr.message
    kinds = [(e.kind, e.element) for e in tr.events]
    assert kinds.count(("engage", "rocker_lock")) == 2
    assert kinds.count(("release", "rocker_lock")) == 2
    modes = tr.stats["variable_structure"]["modes"]
    assert frozenset({"piston_stops@upper", "ram_stop@upper"}) in modes  # idle
    assert any("rocker_lock" in m for m in modes)  # working stroke
    # the lock engages only with the ram pushed down, as the rocker reaches the ram axis
    for e in tr.events:
        if e.kind == "engage":
            k = tr.coordinate_names.index("psi")
            assert abs(e.q_after[k]) < 1e-12
            assert e.energy_lost > 0
    text = format_events(tr.events, tr.coordinate_names)
    assert "engage" in text and "release" in text


@pytest.mark.slow
def test_press_constraints_hold_in_every_mode_without_penetration(press):
    tr = press
    assert np.max(tr.energy["residual"]) < 1e-10
    gap_tol = 1e-9 * tr.model.length_scale
    assert tr.stats["variable_structure"]["penetration"] <= gap_tol
    # the ram never rises above its upper stop, the piston never leaves its stroke
    x_ram = tr.x[:, 3 * tr.body_names.index("slider")]
    assert np.max(x_ram) <= press_cycle.PARAMETERS["x_stop_up"] + gap_tol
    p = tr.coordinate("p")
    assert np.min(p) >= -press_cycle.PARAMETERS["piston_stroke"] - gap_tol
    # energy: T + U - W_nc + impact losses stays constant (integration error only)
    assert tr.energy_drift() < 1e-3


@pytest.mark.slow
def test_press_records_crank_motion_and_frame_forces_through_the_switches(press):
    tr = press
    w = tr.rate("phi")
    assert 40.0 < np.min(w) and np.max(w) < 46.2  # motor near its synchronous speed
    ff = tr.stats["variable_structure"]["frame_force"]
    assert ff.shape == (tr.t.size, 2) and np.all(np.isfinite(ff))
    assert np.all(np.isfinite(tr.qddot))


def test_bolt_meets_the_buffer_separates_and_touches_again():
    tr = bolt_buffer.run(0.2)
    assert tr.status == "success", tr.message
    hits = [e for e in tr.events if e.element == "face_on_buffer@contact"]
    assert len(hits) >= 3
    assert np.max(tr.energy["residual"]) < 1e-12
    assert tr.stats["variable_structure"]["penetration"] < 1e-9
    assert tr.energy_drift() < 1e-6


@pytest.mark.slow
def test_press_model_file_runs_to_the_first_work_stroke():
    from mechdyn.simulate_events import simulate_events

    mech = press_cycle.load_model_file()
    assert {len(mech.extras[k]) for k in ("stops", "contacts", "coordinate_locks",
                                          "switches")} <= {1, 2}
    tr = simulate_events(mech, 0.25, rtol=1e-9, dt_out=1e-3)
    assert tr.status == "success", tr.message
    eng = [e for e in tr.events if e.kind == "engage"]
    assert len(eng) == 1 and 0.15 < eng[0].t < 0.17
    assert np.max(tr.energy["residual"]) < 1e-10
