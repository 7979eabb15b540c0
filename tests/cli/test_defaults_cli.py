"""One set of command-line defaults (docs/notation.md, "The command line: one vocabulary"):
every command sweeps from the coordinate's initial value at the model's own speed and says
which speed it used; old spellings still work; every status word is a ``mechdyn.Status``."""

import math
import re

import numpy as np
import pytest

from mechdyn import Status, examples
from mechdyn.cli import main
from mechdyn.results.table import read_csv

RPM = math.pi / 30
# the bundled examples' [initial] and [initial_speed], as their files state them
SLIDER_CRANK = {"phi_deg": 30.0, "speed": 1500 * RPM}
TOGGLE_PRESS = {"phi_deg": 90.0, "speed": 40 * RPM}
MODEL_SPEED = "the initial speed of phi in the model"


def _model(tmp_path, name: str, drop: tuple = (), replace=None):
    """A copy of a bundled example without the tables named in ``drop``."""
    text = examples.path(name).read_text()
    for table in drop:
        text = re.sub(rf"\[{table}\]\n(\w+ = .*\n)+", "", text)
    if replace:
        text = text.replace(*replace)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return str(path)


def _statuses(text: str) -> list[str]:
    """Every status word printed (``status X``, ``(X)``) or written (``# status: X``)."""
    return re.findall(r"status:? ([\w-]+)", text)


def _run(argv, tmp_path, capsys, speed: str, start_deg: float):
    """Run ``argv -o CSV``: its output says ``speed`` is the model's, its table starts at
    ``start_deg``; every status word printed or written is ``success``."""
    csv = tmp_path / "out.csv"
    assert main([*argv, "-o", str(csv)]) == 0
    out = capsys.readouterr().out
    assert f"speed {speed}: {MODEL_SPEED}" in out
    assert {Status(w) for w in _statuses(out + csv.read_text())} == {Status.SUCCESS}
    df = read_csv(csv)
    assert df["phi_deg"].iloc[0] == pytest.approx(start_deg)
    return df


def test_kinematics_defaults_are_the_models(tmp_path, capsys):
    df = _run(["kinematics", "slider_crank", "--steps", "5"], tmp_path, capsys,
              "157.08 rad/s (1500 rpm)", SLIDER_CRANK["phi_deg"])
    assert df["phi_deg"].iloc[-1] == pytest.approx(SLIDER_CRANK["phi_deg"] + 360)
    np.testing.assert_allclose(df["phi_dot_rad_s"], SLIDER_CRANK["speed"], rtol=1e-11)
    # velocity = analog * speed (the table's own analog, the speed the model states)
    np.testing.assert_allclose(df["vx_rod_B_m_s"], df["dx_rod_B_dphi_m"]
                               * SLIDER_CRANK["speed"], rtol=1e-9, atol=1e-12)


def test_kinetostatics_defaults_are_the_models(tmp_path, capsys):
    df = _run(["kinetostatics", "toggle_press", "--steps", "7", "--harmonics", "0"],
              tmp_path, capsys, "4.18879 rad/s (40 rpm)", TOGGLE_PRESS["phi_deg"])
    np.testing.assert_allclose(df["phi_dot_rad_s"], TOGGLE_PRESS["speed"], rtol=1e-11)


def test_reduce_defaults_are_the_models(tmp_path, capsys):
    df = _run(["reduce", "slider_crank", "--steps", "5"], tmp_path, capsys,
              "157.08 rad/s (1500 rpm)", SLIDER_CRANK["phi_deg"])
    # the drive falls linearly from 30 N m at rest to 0 at 3000 rpm: 15 N m at 1500 rpm,
    # not its stall torque
    np.testing.assert_allclose(df["M_drive_Nm"], 15.0, rtol=1e-11)


@pytest.mark.parametrize("command", ["animate", "report"])
def test_animate_and_report_sweep_from_the_initial_value(command, tmp_path, monkeypatch,
                                                         capsys):
    import mechdyn.cli.animate as animate_cli
    import mechdyn.cli.report as report_cli

    seen = {}
    module, name = (animate_cli, "sweep") if command == "animate" else (report_cli,
                                                                         "run_sweep")
    real = getattr(module, name)

    def spy(model, over, values, **kw):
        seen.update(values=np.asarray(values), speed=kw.get("speed", 1.0))
        return real(model, over, values, **kw)

    monkeypatch.setattr(module, name, spy)
    out = tmp_path / ("a.gif" if command == "animate" else "r.html")
    assert main([command, "slider_crank", "--steps", "3", "-o", str(out)]) == 0
    assert np.degrees(seen["values"][0]) == pytest.approx(SLIDER_CRANK["phi_deg"])
    if command == "report":
        assert seen["speed"] == pytest.approx(SLIDER_CRANK["speed"])
    assert all(Status(w) for w in re.findall(r"\((\w[\w-]*)\)", capsys.readouterr().out))


def test_the_drive_gives_the_speed_when_the_model_has_no_initial_speed(tmp_path, capsys):
    """The lumped press's motor 4A80B4U3: 1500 rpm synchronous, rated slip 0.058 (the
    catalogue), through a gear of ratio 3.4: the crank's rated speed 43.52 rad/s."""
    path = _model(tmp_path, "clutchless_press_lumped", drop=("initial_speed",))
    csv = tmp_path / "k.csv"
    assert main(["kinematics", path, "--over", "phi", "--steps", "3", "-o", str(csv)]) == 0
    out = capsys.readouterr().out
    rated = 1500 * RPM * (1 - 0.058) / 3.4
    np.testing.assert_allclose(read_csv(csv)["phi_dot_rad_s"], rated, rtol=1e-11)
    assert "the rated speed of drive 'motor' on phi through a gear of ratio 3.4" in out


def test_without_any_speed_one_rad_per_second_and_a_note(tmp_path, capsys):
    path = _model(tmp_path, "slider_crank", drop=("initial_speed",))
    csv = tmp_path / "k.csv"
    assert main(["kinematics", path, "--steps", "5", "-o", str(csv)]) == 0
    out = capsys.readouterr().out
    assert "speed 1 rad/s (9.5493 rpm): the model gives phi no speed" in out
    assert "give --speed" in out
    df = read_csv(csv)
    np.testing.assert_allclose(df["vx_rod_B_m_s"], df["dx_rod_B_dphi_m"], atol=1e-12)


@pytest.mark.parametrize("argv", [
    ["kinematics", "slider_crank", "--steps", "3"],
    ["kinetostatics", "toggle_press", "--steps", "3", "--harmonics", "0"],
    ["reduce", "slider_crank", "--steps", "3"],
    ["animate", "slider_crank", "--steps", "3", "-o", "{tmp}/a.gif"],
])
def test_start_is_a_silent_alias_of_from(argv, tmp_path, capsys):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main([*argv, "--start", "-20deg"]) == 0
    by_start = capsys.readouterr().out
    assert main([*argv, "--from", "-20deg"]) == 0
    assert capsys.readouterr().out == by_start
    with pytest.raises(SystemExit):
        main([argv[0], "--help"])
    helptext = capsys.readouterr().out
    assert "--from" in helptext and "--start" not in helptext


def test_given_speed_says_so(capsys):
    assert main(["kinetostatics", "toggle_press", "--steps", "3", "--harmonics", "0",
                 "--speed", "20rpm"]) == 0
    assert "speed 2.0944 rad/s (20 rpm): given with --speed" in capsys.readouterr().out


def test_points_lists_points_or_all_of_them(tmp_path, capsys):
    """``--points`` means the same in kinematics and simulate: the named points listed, or
    every named point when given alone (the older flag form of simulate)."""
    some, every = tmp_path / "some.csv", tmp_path / "every.csv"
    run = ["simulate", "slider_crank", "--t-end", "2ms", "--samples", "3"]
    assert main([*run, "--points", "crank.A", "rod.com", "-o", str(some)]) == 0
    assert main([*run, "--points", "-o", str(every)]) == 0
    capsys.readouterr()
    cols = set(read_csv(some).columns)
    assert {"x_crank_A_m", "vy_rod_com_m_s", "ax_rod_com_m_s2"} <= cols
    assert not any(c.endswith(("_crank_com_m", "_piston_com_m")) for c in cols)
    every_cols = set(read_csv(every).columns)
    assert {"x_crank_com_m", "x_piston_com_m"} <= every_cols and cols < every_cols
    assert "status: success" in some.read_text()
    assert main([*run, "--points", "crank.Z"]) == 2
    assert "valid point names" in capsys.readouterr().err
    png = tmp_path / "k.png"
    assert main(["kinematics", "slider_crank", "--steps", "9", "--points", "--plot",
                 str(png)]) == 0
    assert main(["kinematics", "slider_crank", "--steps", "9", "--points", "rod.com",
                 "crank.A", "--plot", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
