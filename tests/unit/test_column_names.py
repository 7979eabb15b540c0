"""Options that name a result column are checked before the run (issue 29, item 16):
the error names the option and the value and lists the valid names; exit 2."""

import time

import pytest

from mechdyn.cli import main
from mechdyn.errors import ModelError
from mechdyn.examples import load
from mechdyn.study.analyses import KinematicSummary, KinetostaticExtremes
from mechdyn.study.designs import parse_range
from mechdyn.study.optimise import optimise
from mechdyn.study.parameters import BaseModel


def _fails_fast(argv, capsys, flag, bad, valid, seconds=60.0):
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < seconds
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "error" in line]  # not the first compile
    assert len(lines) == 1 and "Traceback" not in err
    assert f"{flag}: unknown column {bad!r}; valid column names:" in lines[0]
    assert repr(valid) in lines[0]


STUDY = ["study", "slider_crank", "--vary", "bodies.crank.com.x=-40mm..20mm",
         "--speed", "1000rpm", "--steps", "24"]


@pytest.mark.parametrize("extra, flag, bad, valid", [
    (["--minimise", "M_peak"], "--minimise", "M_peak", "M_drive_phi_peak_Nm"),
    (["--figure", "F_peak_N"], "--figure", "F_peak_N", "F_frame_peak_N"),
    (["--minimise", "M_drive_phi_peak_Nm", "--constraint", "stroke_m=0.1"],
     "--constraint stroke_m", "stroke_m", "F_frame_rms_N"),
    (["--analysis", "kinematics", "--figure", "stroke_m"], "--figure", "stroke_m",
     "stroke_cylinder_m"),
])
def test_study_columns_are_checked_before_the_first_variant(tmp_path, capsys, extra, flag,
                                                            bad, valid):
    out = tmp_path / "s.csv"
    _fails_fast([*STUDY, *extra, "--samples", "4", "-o", str(out)], capsys, flag, bad, valid)
    assert not out.exists()


def test_a_study_column_that_exists_still_runs(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main([*STUDY, "--analysis", "kinematics", "--figure", "stroke_cylinder_m",
                 "--samples", "3", "--workers", "1", "-o", str(out)]) == 0
    assert "stroke_cylinder [mm]" in capsys.readouterr().out and out.exists()


def test_optimise_checks_its_objective_before_evaluating(tmp_path):
    base = BaseModel("slider_crank")
    r = [parse_range(base, "bodies.crank.com.x=-40mm..20mm")]
    with pytest.raises(ModelError, match="objective: unknown column 'M_peak'"):
        optimise(base, r, KinetostaticExtremes("1000 rpm", steps=12), "M_peak",
                 output=tmp_path / "o.csv")
    assert not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize("name", ["slider_crank", "four_bar"])
def test_the_analyses_name_the_figures_they_give(name):
    model = load(name).compile()
    for analysis in (KinematicSummary(steps=72), KinetostaticExtremes("100 rpm", steps=36)):
        assert set(analysis(model).figures) <= set(analysis.columns(model))
    kin = KinematicSummary(steps=72)
    assert {c for c in kin.columns(model) if "DC_" not in c} <= set(kin(model).figures)


@pytest.mark.parametrize("argv, flag, bad, valid", [
    (["kinematics", "slider_crank", "--steps", "20000", "--plot-columns", "phi_dg"],
     "--plot-columns", "phi_dg", "phi_deg"),
    (["kinetostatics", "slider_crank", "--speed", "100rpm", "--steps", "20000",
      "--plot-columns", "M_drive_Nm"], "--plot-columns", "M_drive_Nm", "M_drive_phi_Nm"),
    (["simulate", "andrews_squeezer", "--t-end", "0.03", "--plot-columns", "T"],
     "--plot-columns", "T", "T_J"),
    (["simulate", "andrews_squeezer", "--t-end", "0.03", "--spectrum", "Fy_N"],
     "--spectrum", "Fy_N", "E_balance_J"),
])
def test_plot_columns_and_spectrum_are_checked_before_the_run(tmp_path, capsys, argv, flag,
                                                             bad, valid):
    out, png = tmp_path / "out.csv", tmp_path / "p.png"
    _fails_fast([*argv, "-o", str(out), "--plot", str(png)], capsys, flag, bad, valid)
    assert not out.exists() and not png.exists()
