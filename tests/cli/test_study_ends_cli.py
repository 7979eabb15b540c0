"""``mechdyn study`` on local worker processes always ends (issue 29, item 9): 50 small
studies in a row each end with exit 0 and no traceback, and a study stopped by Ctrl-C
(SIGINT to its process group) or SIGTERM exits 130 / 143 with one line of message, the
finished variants in its output and no traceback."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pandas as pd
import pytest

STUDY = ["study", "slider_crank", "--vary", "bodies.rod.mass=1kg..2kg", "--design", "grid",
         "--analysis", "kinetostatics", "--speed", "1000rpm", "--batch", "1",
         "--no-progress"]
#: the command line's own entry point, as the ``mechdyn`` script calls it
MAIN = "import sys; from mechdyn.cli import main; sys.exit(main())"


@pytest.mark.timeout(240)
def test_fifty_small_studies_in_a_row_each_end_without_a_traceback(tmp_path):
    """Before the fix, about one study in three printed a worker's KeyboardInterrupt
    traceback and one in 25 hung in the pool's shutdown.  The 50 studies run in one
    process (one start of Python and of the compiled kernels, which its workers inherit),
    each through the command line's ``main`` with its SIGTERM handler, each with a pool
    of two workers started and stopped."""
    script = textwrap.dedent(f"""
        import sys
        from mechdyn.cli import main
        args = {STUDY!r} + ["--samples", "4", "--steps", "24", "-o", sys.argv[1]]
        main(args + ["--workers", "1"])  # the kernels loaded once, before the forks
        codes = [main(args + ["--workers", "2"]) for _ in range(50)]
        print("codes", *codes)
    """)
    out = tmp_path / "s.csv"
    proc = subprocess.run([sys.executable, "-c", script, str(out)], capture_output=True,
                          text=True, timeout=220)
    assert proc.returncode == 0, proc.stderr[-3000:]
    codes = proc.stdout.split("codes", 1)[1].split()
    assert codes == ["0"] * 50
    assert "Traceback" not in proc.stderr and "KeyboardInterrupt" not in proc.stderr, \
        proc.stderr[-3000:]
    df = pd.read_csv(out)
    assert len(df) == 4 and (df["status"] == "success").all()
    assert not (tmp_path / "s.csv.parts").exists()


def _parts(path) -> int:
    parts = path.with_name(path.name + ".parts")
    return len(list(parts.glob("part-*.csv"))) if parts.is_dir() else 0


@pytest.mark.timeout(180)
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["ctrl-c", "sigterm"])
def test_a_stopped_study_keeps_its_finished_variants_and_says_so_in_one_line(
        tmp_path, signum, code):
    """The signal goes to the study's whole process group, as Ctrl-C in a terminal (or a
    supervisor's SIGTERM) does, once a few variants are written."""
    out = tmp_path / "s.csv"
    proc = subprocess.Popen([sys.executable, "-c", MAIN, *STUDY, "--samples", "400",
                             "--steps", "360", "--workers", "2", "-o", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 120.0
        while _parts(out) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert proc.poll() is None, "the study ended before it was stopped"
        written = _parts(out)
        assert written >= 3
        os.killpg(proc.pid, signum)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert proc.returncode == code, (stdout, stderr)
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    said = [line for line in stderr.splitlines() if "interrupted" in line]
    assert len(said) == 1 and str(out) in said[0], stderr
    df = pd.read_csv(out)  # the finished variants, gathered into the output
    assert written <= len(df) < 400 and (df["status"] == "success").all()
    assert df["variant"].is_unique
    assert not out.with_name(out.name + ".parts").exists()
