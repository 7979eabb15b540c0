"""``mechdyn study`` through its own parser (the subcommand is registered in the CLI
separately)."""

import argparse

import pytest

from mechdyn.cli import check_outputs, negative_values
from mechdyn.cli import study as study_cli
from mechdyn.errors import ModelError
from mechdyn.study.output import read_table


def run(argv):
    parser = argparse.ArgumentParser(prog="mechdyn")
    sub = parser.add_subparsers(dest="command")
    study_cli.register(sub)
    args = parser.parse_args(negative_values(argv))
    check_outputs(args)
    return study_cli.run(args)


VARY = ["--vary", "bodies.crank.points.A.x=40mm..60mm",
        "--vary", "bodies.rod.points.B.x=140mm..200mm"]


def test_a_kinetostatic_study_writes_the_table_and_prints_a_summary(tmp_path, capsys):
    out = tmp_path / "s.csv"
    code = run(["study", "slider_crank", *VARY, "--samples", "6", "--design", "lhs",
                "--seed", "1", "--analysis", "kinetostatics", "--speed", "1000rpm",
                "--steps", "36", "-o", str(out), "--workers", "1",
                "--plot", str(tmp_path / "s.png"), "--report", str(tmp_path / "s.html")])
    assert code == 0
    df = read_table(out)
    assert len(df) == 6 and (df["status"] == "success").all()
    assert {"bodies.crank.points.A.x_m", "bodies.rod.points.B.x_m",
            "M_drive_phi_peak_Nm"} <= set(df.columns)
    text = capsys.readouterr().out
    assert "6 variants" in text and "6 success" in text
    assert "evaluated: 6 as batches of variants, 0 one by one" in text
    assert (df["evaluated"] == "batch").all()
    assert "smallest M_drive_phi_peak [N m]" in text and "bodies.crank.points.A.x [mm]" in text
    assert (tmp_path / "s.png").is_file()
    assert "Design study: 6 variants" in (tmp_path / "s.html").read_text(encoding="utf-8")
    # resumed with more samples of the same seed: a Latin hypercube of another size is
    # another design, and is refused
    with pytest.raises(ModelError, match="another study"):
        run(["study", "slider_crank", *VARY, "--samples", "8", "--seed", "1", "--speed",
             "1000rpm", "--steps", "36", "-o", str(out), "--workers", "1", "--resume"])


def test_an_optimisation_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "opt.parquet"
    code = run(["study", "slider_crank", "--vary", "bodies.crank.com.x=-40mm..20mm",
                "--speed", "1000rpm", "--steps", "24", "--minimise", "M_drive_phi_peak_Nm",
                "-o", str(out)])
    assert code == 0
    assert "optimum (cobyqa" in capsys.readouterr().out
    assert len(read_table(out)) > 3


@pytest.mark.parametrize("extra, match", [
    (["--analysis", "flywheel"], "needs --delta"),
    (["--analysis", "dynamics", "--speed", "1rpm"], "use one of"),
])
def test_bad_options_are_named(tmp_path, extra, match):
    with pytest.raises(ModelError, match=match):
        run(["study", "slider_crank", *VARY, "-o", str(tmp_path / "s.csv"), *extra])


def test_the_default_speed_is_the_model_s_own(tmp_path, capsys):
    """Without --speed the kinetostatic analysis runs at the model's speed, as every
    command does, and says which: slider_crank's crank starts at 1500 rpm (its file)."""
    out = tmp_path / "s.csv"
    assert run(["study", "slider_crank", *VARY, "--samples", "2", "--steps", "12",
                "-o", str(out)]) == 0
    assert "speed 157.08 rad/s (1500 rpm): the initial speed of phi" in capsys.readouterr().out
