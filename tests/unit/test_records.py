"""The typed stats of the records (mechdyn.results.records) and their read-only mapping
access, kept for code written against the dicts they replaced."""

import dataclasses

import numpy as np
import pytest

import mechdyn
from mechdyn.fieldmap import FieldMapping
from mechdyn.integrate import SolveStats, solve
from mechdyn.results.records import RunStats, StreamedStats, SwitchedSamples


@pytest.fixture(scope="module")
def run():
    return mechdyn.simulate(mechdyn.examples.load("slider_crank"), 0.05, progress=False)


def test_a_run_s_stats_are_typed_and_read_as_the_dict_they_were(run):
    s = run.stats
    assert isinstance(s, RunStats) and dataclasses.is_dataclass(s)
    assert s.steps > 0 and s.evaluations > s.steps and s.segments == 1
    assert s.integrator == "dop853" and s.wall_time_s > 0
    for key in ("steps", "rejected", "evaluations", "integrator", "formulation", "backend",
                "rtol", "atol", "segments", "bifurcations", "wall_time_s", "penetration"):
        assert key in s and s[key] is getattr(s, key), key
    assert "streamed" not in s and s.get("streamed") is None
    with pytest.raises(KeyError):
        s["streamed"]
    with pytest.raises(KeyError):
        s["no such key"]
    assert list(s.keys()) == list(s) == list(dict(s)) and len(s) == len(s.keys())
    assert dict(s.items())["steps"] == s.steps
    assert isinstance(s["variable_structure"], SwitchedSamples)
    assert s.variable_structure is run.switching


def test_the_stats_of_a_record_are_read_only(run):
    with pytest.raises(TypeError):
        run.stats["steps"] = 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.stats.steps = 0


def test_a_streamed_run_counts_its_rows_in_typed_stats():
    model = mechdyn.examples.load("slider_crank").compile()
    parts = []
    tr = mechdyn.simulate(model, 0.05, dt_out=1e-3, progress=False, chunk=20, keep=False,
                          sink=lambda part, start: parts.append(len(part.t)))
    st = tr.stats.streamed
    assert isinstance(st, StreamedStats) and st.rows == sum(parts) == 51
    assert tr.stats["streamed"]["rows"] == st.rows and st.t_first == 0.0
    assert tr.energy_drift() == st.energy_drift


def test_a_solve_s_stats_are_typed():
    sol = solve("rk4", lambda t, q, v: -q, 0.0, [1.0], [0.0], 1.0, steps=10)
    assert isinstance(sol.stats, SolveStats)
    assert sol.stats.steps == sol.stats["steps"] == 10
    assert dict(sol.stats) == {"integrator": "rk4", "steps": 10, "rejected": 0,
                               "evaluations": sol.stats.evaluations}


def test_field_mapping_leaves_out_the_fields_that_are_none():
    @dataclasses.dataclass(frozen=True)
    class S(FieldMapping):
        a: int = 1
        b: float | None = None
        c: np.ndarray | None = None

    s = S(c=np.zeros(2))
    assert s.keys() == ("a", "c") and "b" not in s and 1 not in s
    assert {**s}.keys() == {"a", "c"}


def test_a_sweep_s_stats_are_typed():
    from mechdyn.kinematics.records import SweepStats

    sw = mechdyn.sweep(mechdyn.examples.load("slider_crank"), values=np.linspace(0, 1, 11))
    s = sw.stats
    assert isinstance(s, SweepStats) and s.n_points == s["n_points"] == 11
    assert s.n_requested == 11 and s.bifurcations == [] and "mode" in s
    assert s.time_s > 0 and s.positions_per_s == pytest.approx(11 / s.time_s)


def test_a_kinetostatic_analysis_s_stats_are_typed():
    from mechdyn.results.records import KinetostaticsStats

    res = mechdyn.kinetostatics(mechdyn.examples.load("slider_crank"), speed=10.0,
                                values=np.linspace(0, 1, 11))
    s = res.stats
    assert isinstance(s, KinetostaticsStats) and s.positions == s["positions"] == 11
    assert s.power_balance_rel < 1e-9 and s.seconds > 0
    assert s.redundant_equations == 0 and "redundant_shared_by" not in s
    assert s.segments is None and "segments" not in s and "friction_iterations" not in s


def test_the_reduction_records_stats_are_typed():
    from mechdyn.reduction.reduce import (
        ReducedMachine,
        reduce_model,
        run_reduced,
        size_flywheel,
        steady_state,
    )
    from mechdyn.results.records import (
        FlywheelStats,
        ReductionStats,
        SteadyCycleStats,
    )

    red = reduce_model(mechdyn.examples.load("slider_crank"), steps=37)
    assert isinstance(red.stats, ReductionStats) and red.stats.positions == 37
    assert red.stats["friction_ignored"] == red.stats.friction_ignored == ()
    machine = ReducedMachine.constant(0.05, lambda t, p, w: -4.0 * np.sin(2 * p))
    cycle = steady_state(machine, omega_mean=30.0)
    assert isinstance(cycle.stats, SteadyCycleStats) and cycle.stats.steps > 0
    assert cycle.stats["cycles_integrated"] == cycle.stats.cycles_integrated >= 1
    fs = size_flywheel(machine, 0.02, omega_mean=30.0, method="energy")
    assert isinstance(fs.stats, FlywheelStats)
    assert fs.stats["mean_torque_removed_Nm"] == fs.stats.mean_torque_removed_Nm
    run = run_reduced(machine, 0.1, omega0=30.0)
    assert isinstance(run.stats, SolveStats) and run.stats.steps == run.stats["steps"] > 0
