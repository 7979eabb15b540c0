"""The analyses of a study: flywheel, simulation metrics, combined figures."""

import numpy as np
import pytest

from mechdyn.study.analyses import (
    Combined,
    FlywheelSize,
    KinematicSummary,
    KinetostaticExtremes,
    SimulationMetrics,
)
from mechdyn.study.execute import run_study

MASSES = {"bodies.rod.mass": [1.0, 2.0]}


def top_speed(traj):
    """A simulation metric: the largest crank speed, rad/s."""
    return {"omega_max_rad_s": float(np.max(traj.qdot[:, 0]))}


def test_a_heavier_rod_needs_a_larger_flywheel():
    df = run_study("slider_crank", MASSES, FlywheelSize(0.05, steps=73), workers=1,
                   progress=False)
    assert (df["status"] == "success").all()
    assert df.loc[1, "J_fly_kg_m2"] > df.loc[0, "J_fly_kg_m2"] > 0
    assert {"delta_E_max_J", "omega_mean_rpm", "J_red_mean_kg_m2"} <= set(df.columns)


def test_simulation_metrics_are_a_function_of_the_trajectory():
    df = run_study("slider_crank", MASSES, SimulationMetrics(top_speed, "5 ms"), workers=1,
                   progress=False)
    assert (df["status"] == "success").all()
    assert (df["omega_max_rad_s"] > 150.0).all()  # it starts at 1500 rpm (157 rad/s)


def test_combined_figures_and_the_first_failure_as_the_status():
    both = Combined((KinetostaticExtremes("1000 rpm", steps=36), KinematicSummary(steps=36)))
    df = run_study("slider_crank", {"bodies.rod.points.B.x": [0.16, 0.045]}, both,
                   workers=1, progress=False, order=False)
    assert df.loc[0, "stroke_cylinder_m"] == pytest.approx(0.1)
    assert np.isfinite(df.loc[0, "M_drive_phi_peak_Nm"])
    assert df.loc[1, "status"] != "success" and df.loc[1, "message"]
