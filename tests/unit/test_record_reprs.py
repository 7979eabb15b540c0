"""Every result record has a short repr (issue 29, item 15): class name, model, sizes,
status and a few figures in under 300 characters, its data still in its fields."""

import math

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.foundation import (
    AnchorBolt,
    Foundation,
    Isolator,
    mounted_response,
    natural_frequencies,
    support_loads,
)
from mechdyn.kinematics.sweep import analyze, initial_coordinates, sweep
from mechdyn.kinetostatics.inverse import kinetostatics
from mechdyn.modelfile.drives import drive_from_table
from mechdyn.reduction.flywheel import steady_state
from mechdyn.reduction.reduce import mode_mechanism, reduce_model, size_flywheel
from mechdyn.reduction.run import StartupSummary, run_reduced, startup
from mechdyn.simulate.run import simulate

LIMIT = 300


@pytest.fixture(scope="module")
def records():
    out = {}
    for name in ("slider_crank", "four_bar", "bolt_buffer"):
        model = examples.load(name).compile()
        over = model.coordinate_names[0]
        q0 = float(initial_coordinates(model)[0])
        sw = sweep(model, over, np.linspace(0.0, 2 * np.pi, 73) if model.coord_is_angle[0]
                   else q0 + np.linspace(0.0, 1e-3, 11))
        out[f"{name}: KinematicSweep"] = sw
        out[f"{name}: SweepSummary"] = sw.summary()
        out[f"{name}: KinematicPoint"] = analyze(model, sw.q[0], np.ones(model.n_q))
        out[f"{name}: Trajectory"] = simulate(model, 0.02, progress=False)
    crank = examples.load("slider_crank").compile()
    out["Kinetostatics"] = ks = kinetostatics(crank, over="phi", speed=100.0)
    mounts = Foundation([AnchorBolt("b1", -0.3, -0.1, 2e8, 1e8, preload=5e3),
                         Isolator("pad", 0.1, -0.1, 1e7, 5e7)])
    out["SupportLoads"] = support_loads(mounts, ks)
    iso = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5, 3e3, 3e3),
                      Isolator("R", 0.5, 0.0, 1e5, 1e5, 3e3, 3e3)], mass=490.0, inertia=40.0)
    out["Modes"] = natural_frequencies(iso)
    t = np.linspace(0.0, 0.1, 101)
    out["MountedResponse"] = mounted_response(iso, t, np.sin(100 * t), 0 * t, 0 * t)
    mech = mode_mechanism(examples.load("clutchless_press"), engage=["rocker_lock"],
                          offsets={"rocker_lock": (0, 0, 0)}, drop=["psi"])
    mech.drives[:] = [drive_from_table({"type": "induction_motor", "coordinate": "phi",
                                        "catalogue": "4A80B4U3", "gear_ratio": 3.4,
                                        "efficiency": 0.95}, "press")]
    press = mech.compile()
    out["Reduction"] = red = reduce_model(press, steps=181, omega=43.5)
    machine = red.machine(press)
    out["SteadyCycle"] = steady_state(machine)
    out["FlywheelSizing"] = size_flywheel(machine, 0.05)
    out["ReducedRun"] = run_reduced(machine, 0.05, omega0=40.0)
    out["StartupResult"] = st = startup(machine, 0.2)
    out["StartupSummary"] = st.summary()
    return out


def test_every_record_has_a_short_repr(records):
    for key, rec in records.items():
        text = repr(rec)
        assert len(text) < LIMIT, (key, len(text), text)
        assert text.startswith(type(rec).__name__ + "("), key
        assert "array(" not in text and "\n" not in text, key


def test_the_repr_names_the_model_sizes_status_and_figures(records):
    sw = records["slider_crank: KinematicSweep"]
    assert repr(sw).startswith("KinematicSweep('slider-crank', 73 positions over 'phi'")
    assert "status='success'" in repr(sw) and sw.x.shape == (73, 9)  # the data stay
    run = records["slider_crank: Trajectory"]
    assert f"{run.n_samples} samples, t = 0 .. 0.02 s" in repr(run)
    assert "energy drift" in repr(run) and run.to_dataframe().shape[0] == run.n_samples
    assert "peak M_drive_phi" in repr(records["Kinetostatics"])
    assert "J_fly" in repr(records["FlywheelSizing"])


def test_the_startup_summary_is_a_record_that_reads_as_its_dict(records):
    st, s = records["StartupResult"], records["StartupSummary"]
    assert isinstance(s, StartupSummary)
    assert {"peak_drive_torque_Nm", "omega_mean_rad_s", "speed_dip_rad_s"} <= set(s)
    assert s["omega_mean_rad_s"] == st.omega_mean
    assert math.isclose(s.phi_dip_deg, math.degrees(st.phi_dip))
    assert str(s).startswith("t_steady ")


def test_an_optimum_has_a_short_repr():
    from mechdyn.study.analyses import KinetostaticExtremes
    from mechdyn.study.designs import parse_range
    from mechdyn.study.optimise import optimise
    from mechdyn.study.parameters import BaseModel

    base = BaseModel("slider_crank")
    best = optimise(base, [parse_range(base, "bodies.crank.com.x=-40mm..20mm")],
                    KinetostaticExtremes("1000 rpm", steps=12), "M_drive_phi_peak_Nm",
                    maxiter=5)
    assert len(repr(best)) < LIMIT and repr(best).startswith("Optimum(objective ")
    assert "bodies.crank.com.x = " in repr(best) and len(best.table) == best.evaluations
