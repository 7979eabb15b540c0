"""``mechdyn kinematics`` end to end, through ``mechdyn.cli.main``."""

import re

import numpy as np
import pandas as pd
import pytest

from mechdyn import examples
from mechdyn.cli import main


def test_slider_crank_example_writes_table_and_plot_and_prints_the_summary(tmp_path, capsys):
    csv, png = tmp_path / "sc.csv", tmp_path / "sc.png"
    rc = main(["kinematics", "slider_crank", "--from", "0deg", "--to", "360 deg", "--steps",
               "361", "--speed", "1500rpm", "-o", str(csv), "--plot", str(png)])
    out = capsys.readouterr().out
    assert rc == 0
    # r = 50 mm: stroke 2 r, dead centres at 0 and 180 deg (in-line slider-crank)
    assert "stroke of slider 'cylinder': 100 mm" in out
    assert re.search(r"TDC of 'cylinder' at phi = (0\.0000|360\.0000) deg", out)
    assert "BDC of 'cylinder' at phi = 180.0000 deg" in out
    df = pd.read_csv(csv, comment="#")
    assert len(df) == 361
    omega = 1500 * 2 * np.pi / 60
    assert np.allclose(df["phi_dot_rad_s"], omega)
    # piston speed: closed form of the in-line slider-crank times omega
    r, l = 0.05, 0.16
    phi = np.deg2rad(df["phi_deg"].to_numpy())
    s = np.sqrt(l**2 - (r * np.sin(phi)) ** 2)
    v = omega * (-r * np.sin(phi) - r**2 * np.sin(phi) * np.cos(phi) / s)
    assert np.max(np.abs(df["vx_piston_com_m_s"] - v)) < 1e-9 * np.max(np.abs(v))
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_model_file_path_and_travel_summary(tmp_path, capsys):
    rc = main(["kinematics", str(examples.path("toggle_press")), "--steps", "73"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "transmission angle" in out and "stroke of slider 'slide'" in out


def test_bad_unit_is_one_clear_line_and_exit_code_2(capsys):
    rc = main(["kinematics", "four_bar", "--from", "10 mm"])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith("mechdyn kinematics: error:")
    assert "--from" in err and "Traceback" not in err


def test_unknown_model_lists_the_examples(capsys):
    rc = main(["kinematics", "no_such_machine"])
    err = capsys.readouterr().err
    assert rc == 2 and "slider_crank" in err and "Traceback" not in err


def test_unknown_coordinate_lists_the_valid_ones(capsys):
    rc = main(["kinematics", "four_bar", "--over", "theta"])
    err = capsys.readouterr().err
    assert rc == 2 and "'phi'" in err


@pytest.fixture()
def rocker_driven_four_bar(tmp_path):
    text = examples.path("four_bar").read_text()
    text = text.replace('[coordinates.phi]\nkind = "angle"\nbody = "crank"',
                        '[coordinates.psi]\nkind = "angle"\nbody = "rocker"')
    text = re.sub(r"\[initial\]\nphi = .*\n", "", text)
    text = re.sub(r"\[initial_speed\]\nphi = .*\n", "", text)
    path = tmp_path / "rocker.toml"
    path.write_text(text)
    return path


def test_a_dead_position_writes_what_was_computed_and_exits_1(rocker_driven_four_bar,
                                                             tmp_path, capsys):
    csv = tmp_path / "r.csv"
    rc = main(["kinematics", str(rocker_driven_four_bar), "-o", str(csv)])
    cap = capsys.readouterr()
    assert rc == 1
    assert "warning: dead position at psi = " in cap.err
    df = pd.read_csv(csv, comment="#")
    assert 1 <= len(df) < 361
    assert "status: singular-position" in csv.read_text()


def test_several_coordinates_need_over(capsys):
    rc = main(["kinematics", "clutchless_press"])
    err = capsys.readouterr().err
    assert rc == 2 and "choose one with --over: phi, psi" in err


@pytest.mark.parametrize("command", [["kinematics"], ["kinetostatics", "--speed", "1rpm"],
                                     ["animate", "-o", "x.gif"], ["report", "-o", "x.html"]])
def test_every_sweeping_command_reads_the_range_alike(command, capsys):
    rc = main([command[0], "slider_crank", *command[1:], "--steps", "0"])
    err = capsys.readouterr().err
    assert rc == 2 and f"mechdyn {command[0]}: error: --steps must be at least 1, got 0" in err


def test_negative_values_need_no_equals_sign(capsys):
    """--from -46deg is a value, not an option (issue: the press starts at -64.1 deg)."""
    assert main(["kinematics", "toggle_press", "--from", "-46deg", "--to", "30deg",
                 "--steps", "5"]) == 0
    assert "phi = -46.0000 deg" in capsys.readouterr().out


def test_a_bare_number_for_a_speed_says_how_it_was_read(capsys):
    assert main(["kinematics", "slider_crank", "--speed", "60", "--steps", "3"]) == 0
    err = capsys.readouterr().err
    assert "--speed 60 has no unit: taken as 60 rad/s (= 572.958 rpm)" in err
