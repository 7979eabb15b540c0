"""The whole clutchless-press cycle and the bolt-buffer automaton run through every switch."""

import numpy as np
import pytest

from mechdyn.examples import bolt_buffer, press_cycle
from mechdyn.mechanism import Table
from mechdyn.simulate.segments import format_events

CYCLES = 4
# chosen values of press_cycle.toml (SI)
COMMAND_PERIOD = 6 * np.pi  # one command every third revolution
F_CYLINDER = 85e3
X_STOP_UP = 0.028
PISTON_STROKE = 0.0045


@pytest.fixture(scope="module")
def press():
    # four cycles to just after the fourth release (1.564 s; the ram is back on its stop
    # at 1.666 s, as in the three cycles before), output every 2 ms (events are located
    # on the dense output regardless): about 55 s of wall time
    return press_cycle.run(t_end=1.60, dt_out=2e-3, progress=False)


def test_cylinder_command_is_fired_by_crank_angle_every_third_revolution():
    mech = press_cycle.build()
    (cmd,) = [ld.magnitude for ld in mech.loads if ld.name == "cylinder_force"]
    assert isinstance(cmd, Table) and cmd.variable == "phi"
    assert cmd.period == pytest.approx(COMMAND_PERIOD) and cmd.outside == 0.0
    on, off = np.deg2rad([185.0, 487.0])
    for k in range(-1, 12):
        shift = k * cmd.period
        assert cmd(0.5 * (on + off) + shift) == F_CYLINDER
        assert cmd(on - 0.1 + shift) == 0.0 and cmd(off + 0.1 + shift) == 0.0


@pytest.mark.slow
def test_press_locks_and_releases_once_in_every_cycle(press):
    tr = press
    assert tr.status == "success", tr.message
    kinds = [(e.kind, e.element) for e in tr.events]
    assert kinds.count(("engage", "rocker_lock")) == CYCLES
    assert kinds.count(("release", "rocker_lock")) == CYCLES
    assert ("ignored", "lock_on") not in kinds  # the rocker never passes psi = 0 unlocked
    modes = tr.stats["variable_structure"]["modes"]
    assert frozenset({"piston_stops@upper", "ram_stop@upper"}) in modes  # idle
    assert any("rocker_lock" in m for m in modes)  # working stroke
    k = tr.coordinate_names.index("psi")
    kphi = tr.coordinate_names.index("phi")
    lock = [e for e in tr.events if e.element == "rocker_lock"]
    assert [e.kind for e in lock] == ["engage", "release"] * CYCLES
    per = COMMAND_PERIOD
    for c in range(CYCLES):
        eng, rel = lock[2 * c], lock[2 * c + 1]
        # the lock engages only with the ram pushed down, as the rocker reaches the ram axis
        assert abs(eng.q_after[k]) < 1e-12
        assert eng.energy_lost > 0
        # at the same crank phase in every cycle (the command follows the crank)
        for e, phase in ((eng, np.deg2rad(344.0)), (rel, np.deg2rad(337.9 + 360.0))):
            assert e.q_before[kphi] - c * per == pytest.approx(phase, abs=np.deg2rad(3.0))
    # and every cycle ends in idle: the ram lands on its upper stop after the release,
    # before the next command
    cmd = [e.t for e in tr.events if (e.kind, e.element) == ("separate", "piston_stops@upper")]
    assert len(cmd) == CYCLES
    for c in range(CYCLES - 1):
        assert any(lock[2 * c + 1].t < e.t < cmd[c + 1] for e in tr.events
                   if (e.kind, e.element) == ("impact", "ram_stop@upper"))
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
    assert np.max(x_ram) <= X_STOP_UP + gap_tol
    p = tr.coordinate("p")
    assert np.min(p) >= -PISTON_STROKE - gap_tol
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
    from mechdyn.simulate.segments import simulate_events

    mech = press_cycle.load_model_file()
    assert {len(mech.extras[k]) for k in ("stops", "contacts", "coordinate_locks",
                                          "switches")} <= {1, 2}
    tr = simulate_events(mech, 0.17, rtol=1e-9, dt_out=2e-3, progress=False)
    assert tr.status == "success", tr.message
    eng = [e for e in tr.events if e.kind == "engage"]
    assert len(eng) == 1 and 0.15 < eng[0].t < 0.17
    assert np.max(tr.energy["residual"]) < 1e-10
