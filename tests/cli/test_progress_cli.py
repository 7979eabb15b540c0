"""Every long-running kind of command shows progress on stderr once it has run longer than
PROGRESS_AFTER (patched to 0 here, so even a short run shows it), and ``--no-progress``
silences it."""

import pytest

from mechdyn import progress
from mechdyn.cli import main

FOUR_BAR_ANIMATION = ["animate", "four_bar", "--steps", "9", "--frames", "3", "--no-labels"]

# (command line without outputs, an output file name or None, what stderr must name)
CASES = [
    (["kinematics", "four_bar", "--steps", "19"], None, "kinematics: sweeping phi over 19"),
    (["kinetostatics", "four_bar", "--steps", "19"], None, "kinetostatics: 19 positions"),
    (["reduce", "four_bar", "--steps", "19"], None, "reduce: 19 positions"),
    (["flywheel", "slider_crank", "--delta", "0.05", "--steps", "37"], None,
     "flywheel: reduction table and steady cycle"),
    (FOUR_BAR_ANIMATION, "a.gif", "animate: drawing 3 frames"),
    (FOUR_BAR_ANIMATION, "a.gif", "animate: sweeping phi over 9 positions"),
    (["animate", "four_bar", "--simulate", "--t-end", "2ms", "--frames", "3"], "s.gif",
     "simulate:"),
    (["animate", "four_bar", "--simulate", "--t-end", "2ms", "--no-labels"], "d.gif",
     "animate: drawing 200 frames"),  # the default number of frames of a run
    (["report", "four_bar", "--steps", "13", "--no-animation"], "r.html",
     "report: kinetostatics, 13 positions of phi"),
    (["report", "four_bar", "--steps", "13", "--no-animation"], "r.html", "report: writing"),
    (["simulate", "four_bar", "--t-end", "2ms"], None, "simulate:"),
    (["foundation", "press_cycle", "--t-end", "1ms", "--samples", "5"], None, "simulate:"),
]


@pytest.mark.parametrize(("argv", "output", "shown"), CASES,
                         ids=[f"{c[0][0]}-{c[2].split()[-1]}" for c in CASES])
def test_a_long_run_shows_progress_and_no_progress_silences_it(argv, output, shown, tmp_path,
                                                               monkeypatch, capsys):
    monkeypatch.setattr(progress, "PROGRESS_AFTER", 0.0)
    argv = argv + (["-o", str(tmp_path / output)] if output else [])
    assert main(argv) in (0, 1)
    captured = capsys.readouterr()
    assert shown in captured.err
    assert shown not in captured.out  # progress never mixes with the results
    assert main(argv + ["--no-progress"]) in (0, 1)
    assert capsys.readouterr().err == ""


def test_the_study_bar_follows_the_flag(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(progress, "PROGRESS_AFTER", 0.0)
    argv = ["study", "slider_crank", "--vary", "bodies.crank.points.A.x=40mm..60mm",
            "--samples", "2", "--steps", "12", "--workers", "1"]
    assert main(argv + ["-o", str(tmp_path / "a.csv")]) == 0
    assert "study" in capsys.readouterr().err
    assert main(argv + ["-o", str(tmp_path / "b.csv"), "--no-progress"]) == 0
    assert capsys.readouterr().err == ""


def test_without_the_patch_a_quick_run_says_nothing(capsys):
    assert main(["kinematics", "four_bar", "--steps", "19"]) == 0
    assert capsys.readouterr().err == ""
