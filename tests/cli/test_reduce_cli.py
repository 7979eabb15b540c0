"""``mechdyn reduce`` and ``mechdyn flywheel`` end to end, through ``mechdyn.cli.main``."""

import re

import numpy as np
import pytest

from mechdyn.cli import main
from mechdyn.results.table import read_csv

PRESS = ["clutchless_press", "--engage", "rocker_lock=0mm,0mm,0deg", "--drop", "psi"]


def slider_crank_J(phi):
    """Closed-form J_red of the bundled slider_crank example (in-line, r = 50, l = 160 mm)."""
    r, l = 0.05, 0.16
    m1, J1c, c1 = 2.0, 0.010, 0.005
    m2, J2, c2 = 1.2, 0.004, 0.048
    m3 = 0.8
    beta = np.arcsin(-r * np.sin(phi) / l)
    db = -r * np.cos(phi) / (l * np.cos(beta))
    vc2 = np.stack([-r * np.sin(phi) - c2 * np.sin(beta) * db,
                    r * np.cos(phi) + c2 * np.cos(beta) * db], -1)
    vb = -r * np.sin(phi) - l * np.sin(beta) * db
    return J1c + m1 * c1**2 + m2 * np.sum(vc2**2, -1) + J2 * db**2 + m3 * vb**2


def test_reduce_writes_a_table_with_units_and_a_plot(tmp_path, capsys):
    csv, png = tmp_path / "reduced.csv", tmp_path / "reduced.png"
    rc = main(["reduce", "slider_crank", "--steps", "73", "--mass-at", "crank.A",
               "-o", str(csv), "--plot", str(png)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "reduction to coordinate 'phi', 73 positions" in out and "J_red" in out
    df = read_csv(csv)
    assert len(df) == 73
    for col in ("phi_deg", "J_red_kgm2", "dJ_red_dphi_kgm2", "M_red_Nm", "M_drive_Nm",
                "M_forces_Nm", "m_red_kg"):
        assert col in df.columns
    phi = np.deg2rad(df["phi_deg"].to_numpy())
    np.testing.assert_allclose(df["J_red_kgm2"], slider_crank_J(phi), rtol=1e-9)
    np.testing.assert_allclose(df["m_red_kg"] * 0.05**2, df["J_red_kgm2"], rtol=1e-9)
    # the example's drive falls from 30 N m at rest to 0 at 3000 rpm; evaluated at the
    # model's own speed, its initial 1500 rpm
    np.testing.assert_allclose(df["M_drive_Nm"], 30.0 * (1 - 1500 / 3000))
    assert "speed 157.08 rad/s (1500 rpm): the initial speed of phi in the model" in out
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_reduce_to_a_link(tmp_path, capsys):
    csv = tmp_path / "rod.csv"
    rc = main(["reduce", "slider_crank", "--steps", "361", "--link", "rod", "-o", str(csv)])
    err = capsys.readouterr().err
    assert rc == 1  # the rod stops at phi = 90 and 270 deg: J_red infinite there
    assert "vanishes" in err
    df = read_csv(csv)
    assert {"theta_rod_deg", "ratio"} <= set(df.columns)


def test_reduce_press_working_mode_with_catalogue_motor(capsys):
    rc = main(["reduce", *PRESS, "--motor", "4A80B4U3", "--gear-ratio", "3.4",
               "--efficiency", "95%", "--speed", "43.5rad/s", "--steps", "37"])
    out = capsys.readouterr().out
    assert rc == 0
    # rotor 0.0033 kg m^2 through 3.4 : 1
    assert "J_extra   0.038148 kg m^2" in out
    assert "at 43.5 rad/s" in out


def test_flywheel_for_the_press(tmp_path, capsys):
    png, csv = tmp_path / "cycle.png", tmp_path / "cycle.csv"
    rc = main(["flywheel", *PRESS, "--motor", "4A80B4U3", "--characteristic", "extended",
               "--gear-ratio", "3.4", "--efficiency", "0.95", "--delta", "5%",
               "--method", "simulation", "--steps", "361", "--plot", str(png), "-o", str(csv)])
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "J_fly on the crank" in out and "J_fly on the motor" in out
    sim = float(out.split("delta simulated")[1].split()[0])
    assert sim == pytest.approx(0.05, rel=2e-3)
    j_crank = float(out.split("J_fly on the crank")[1].split()[0])
    j_motor = float(out.split("J_fly on the motor")[1].split()[0])
    assert j_motor == pytest.approx(j_crank / 3.4**2, rel=1e-5)
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert "omega_rad_s" in read_csv(csv).columns


def test_flywheel_with_constant_torque_needs_a_speed(tmp_path, capsys):
    """A constant driving torque does not set the mean speed: the model's initial speed
    does (docs/notation.md), and without one the command asks for --speed."""
    model = tmp_path / "m.toml"
    from mechdyn import examples

    text = examples.path("slider_crank").read_text()
    text = text.replace('torque = { omega = ["0 rpm", "3000 rpm"], torque = ["30 N*m", "0 N*m"] }',
                        'torque = "0 N*m"')
    model.write_text(text)
    rc = main(["flywheel", str(model), "--delta", "0.01", "--steps", "73"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "mean speed            157.08 rad/s (1500 rpm) (the initial speed of phi" in out
    model.write_text(re.sub(r"\[initial_speed\]\nphi = .*\n", "", text))
    rc = main(["flywheel", str(model), "--delta", "0.01"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "the model gives phi no speed" in err and "--speed" in err
    rc = main(["flywheel", str(model), "--delta", "0.01", "--speed", "300rpm"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "mean speed            31.4159 rad/s" in out


@pytest.mark.parametrize("argv, msg", [
    (["reduce", "slider_crank", "--speed", "43.5 mm"], "--speed"),
    (["reduce", "slider_crank", "--link", "piston_rod"], "unknown body 'piston_rod'"),
    (["reduce", "clutchless_press"], "one degree of freedom"),
    (["reduce", "slider_crank", "--gear-ratio", "3"], "need --motor"),
    (["flywheel", "slider_crank", "--delta", "3"], "delta"),
    (["reduce", *PRESS, "--motor", "4A99"], "unknown catalogue motor"),
])
def test_bad_input_exits_2_with_one_line(argv, msg, capsys):
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2
    assert msg in err


def _flywheel(delta: str, capsys):
    code = main(["flywheel", "slider_crank", "--delta", delta, "--motor", "4A80B4U3",
                 "--gear-ratio", "3.4"])
    out = capsys.readouterr().out
    values = {m[1]: float(m[2]) for m in re.finditer(
        r"^\s*(J_fly on the crank|delta simulated|delta without flywheel)\s+([-0-9.e+]+)",
        out, re.M)}
    return code, out, values


def test_the_default_flywheel_agrees_with_the_simulated_steady_cycle(capsys):
    """With a motor the default method is consistent with the simulated steady cycle: the
    recommended flywheel gives the target delta within 2 %, and none is recommended when
    the machine meets the target as it is (the energy estimate is shown beside)."""
    code, out, v = _flywheel("0.5%", capsys)
    assert code == 0 and "(simulation method)" in out
    assert v["J_fly on the crank"] > 0
    assert abs(v["delta simulated"] / 0.005 - 1) < 0.02
    code, out, v = _flywheel("2%", capsys)
    assert code == 0 and v["delta without flywheel"] <= 0.02
    assert v["J_fly on the crank"] == 0.0 and "no flywheel is needed" in out
    assert "J_fly energy method" in out


def test_a_textbook_flywheel_on_a_model_without_a_drive(capsys):
    """No drive: a constant driving torque equal to the mean load torque keeps the mean
    speed (the classic energy method), and the flywheel it gives meets the target."""
    code = main(["flywheel", "toggle_press", "--delta", "5%", "--speed", "40rpm"])
    out = capsys.readouterr().out
    assert code == 0 and "the model has no drive" in out and "(refined method)" in out
    delta = float(re.search(r"delta simulated\s+([-0-9.e+]+)", out)[1])
    assert abs(delta / 0.05 - 1) < 0.02
