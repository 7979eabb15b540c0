"""``mechdyn kinetostatics`` on the command line."""

import numpy as np
import pandas as pd
import pytest

from mechdyn.cli import main

PENDULUM_TOML = """
[model]
name = "crank under gravity"
gravity = ["0 m/s^2", "-9.81 m/s^2"]

[bodies.crank]
mass = "2 kg"
inertia = "0.01 kg*m^2"
com = ["100 mm", "0 mm"]
pose = ["0 mm", "0 mm", "0 deg"]

[joints.O]
type = "revolute"
parent = "ground"
child = "crank"

[coordinates.phi]
kind = "angle"
body = "crank"
"""


def test_toggle_press_cycle_writes_table_and_plot(tmp_path, capsys):
    csv, png = tmp_path / "forces.csv", tmp_path / "forces.png"
    rc = main(["kinetostatics", "toggle_press", "--speed", "40rpm", "--from", "0deg",
               "--to", "360deg", "--steps", "73", "--moment-point", "0,0", "-o", str(csv),
               "--plot", str(png), "--joints", "B", "C", "F"])
    assert rc == 0
    out = capsys.readouterr().out
    assert "drive phi: peak" in out and "RMS" in out and "harmonics" in out
    df = pd.read_csv(csv)
    assert len(df) == 73
    for col in ("phi_deg", "M_drive_phi_Nm", "P_drive_phi_W", "Fx_B_N", "Fy_B_N", "F_B_N",
                "angle_F_B_deg", "Fn_slide_N", "M_slide_Nm", "Fx_frame_N", "M_frame_Nm"):
        assert col in df.columns
    np.testing.assert_allclose(df["phi_deg"].iloc[[0, -1]], [0.0, 360.0])
    assert png.stat().st_size > 10_000


def test_statics_from_a_model_file_with_units(tmp_path, capsys):
    model = tmp_path / "crank.toml"
    model.write_text(PENDULUM_TOML)
    csv = tmp_path / "static.csv"
    rc = main(["kinetostatics", str(model), "--speed", "0 rpm", "--from", "0 deg", "--to",
               "90 deg", "--steps", "3", "--moment-point", "100mm,0mm", "-o", str(csv)])
    assert rc == 0
    df = pd.read_csv(csv)
    # holding torque m g r cos(phi)
    np.testing.assert_allclose(df["M_drive_phi_Nm"], 2 * 9.81 * 0.1 * np.cos(
        np.deg2rad([0, 45, 90])), atol=1e-12)
    # frame moment about (100 mm, 0): the weight acts there at phi = 0
    np.testing.assert_allclose(df["M_frame_Nm"].iloc[0], 0.0, atol=1e-12)


def test_bad_input_exits_2_with_one_line(capsys):
    rc = main(["kinetostatics", "toggle_press", "--speed", "40 m"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "--speed" in err and "angular velocity" in err
    rc = main(["kinetostatics", "toggle_press", "--speed", "40rpm", "--moment-point", "1,2,3"])
    assert rc == 2
    rc = main(["kinetostatics", "toggle_press", "--speed", "40rpm", "--over", "psi"])
    assert rc == 2
    assert "valid coordinate names" in capsys.readouterr().err


@pytest.mark.parametrize("mode", ["rocker_lock", "none"])
def test_clutchless_press_modes(mode, capsys):
    rc = main(["kinetostatics", "clutchless_press", "--speed", "43.5rad/s", "--steps", "13",
               "--engage", mode, "--harmonics", "0"])
    assert rc == 0
    out = capsys.readouterr().out
    assert ("redundant" in out) == (mode == "rocker_lock")
