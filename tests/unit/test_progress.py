"""mechdyn.progress: a stage line on stderr, shown after PROGRESS_AFTER only."""

import time

from mechdyn import progress
from mechdyn.progress import stage


def test_a_stage_longer_than_the_delay_says_so_and_how_long(monkeypatch, capsys):
    monkeypatch.setattr(progress, "PROGRESS_AFTER", 0.05)
    with stage("work: slow"):
        time.sleep(0.3)
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "work: slow ..."
    took = float(err[1].removeprefix("work: slow: done in ").removesuffix(" s"))
    assert 0.2 <= took < 5.0


def test_a_quick_stage_and_a_silenced_one_say_nothing(monkeypatch, capsys):
    with stage("work: quick"):
        pass
    monkeypatch.setattr(progress, "PROGRESS_AFTER", 0.0)
    with stage("work: silenced", False):
        time.sleep(0.01)
    assert capsys.readouterr().err == ""


def test_a_stage_forced_on_and_its_own_closing_line(capsys):
    with stage("compiling", True, done="compiled in {:.1f} s", after=100.0):
        pass
    assert capsys.readouterr().err.splitlines() == ["compiling ...", "compiled in 0.0 s"]


def test_stages_of_one_run_count_the_delay_from_its_start(monkeypatch, capsys):
    monkeypatch.setattr(progress, "PROGRESS_AFTER", 0.2)
    t0 = time.perf_counter()
    with stage("run: first", since=t0):
        time.sleep(0.1)
    with stage("run: second", since=t0):  # 0.1 s left of the delay: named
        time.sleep(0.3)
    with stage("run: third"):  # its own delay: quick, silent
        pass
    err = capsys.readouterr().err
    assert "run: first" not in err and "run: third" not in err
    assert err.startswith("run: second ...\n")
