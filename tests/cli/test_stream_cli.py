"""Long runs stream to disk: ``simulate(sink=...)`` hands the table over in chunks whose
numbers are those of the end-of-run table, and ``mechdyn simulate -o`` appends them to
``NAME.csv.partial``, renamed ``NAME.csv`` at the end (issue 15, "Also build")."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

import mechdyn
from mechdyn import examples
from mechdyn.cli import main
from mechdyn.results.table import CsvStream, read_csv


def _run(name, t_end, n, backend="numpy", **kw):
    model = mechdyn.load(examples.path(name)).compile()
    return mechdyn.simulate(model, t_end, t_eval=np.linspace(0, t_end, n), backend=backend,
                            **kw)


class _Parts:
    def __init__(self):
        self.parts, self.starts = [], []

    def __call__(self, part, start):
        self.parts.append(part.to_dataframe(points=True))
        self.starts.append(start)


@pytest.mark.parametrize(("name", "t_end", "n"), [("four_bar", 0.2, 301),
                                                  ("press_cycle", 0.25, 401)])
def test_the_chunks_are_the_end_of_run_table(name, t_end, n):
    """Chunks of 37 samples, evaluated as they come, give the numbers of the table
    evaluated at the end (1e-12), the work W_nc and the impact losses running on across
    chunks, and the same columns in every chunk."""
    whole = _run(name, t_end, n)
    sink = _Parts()
    streamed = _run(name, t_end, n, sink=sink, chunk=37, keep=False)
    assert whole.success and streamed.success
    assert sink.starts == list(range(0, whole.n_samples, 37))
    assert all(list(p.columns) == list(sink.parts[0].columns) for p in sink.parts)
    table = pd.concat(sink.parts, ignore_index=True)
    ref = whole.to_dataframe(points=True)
    assert len(table) == len(ref) == streamed.stats["streamed"]["rows"]
    assert set(ref.columns) <= set(table.columns)
    for col in ref.columns:
        if col == "mode":
            assert (table[col] == ref[col]).all()
            continue
        np.testing.assert_allclose(table[col], ref[col], rtol=1e-12, atol=1e-12 * max(
            1.0, float(np.max(np.abs(ref[col])))), err_msg=col)
    for col in set(table.columns) - set(ref.columns):  # elements never engaged
        assert np.all(table[col] == 0.0), col
    # what the run says of itself is the whole run's
    assert streamed.energy_drift() == pytest.approx(whole.energy_drift(), rel=1e-9, abs=1e-15)
    assert "(streamed)" in streamed.summary()
    assert streamed.t.size <= 37 and streamed.t[-1] == whole.t[-1]


def test_keep_returns_the_whole_run():
    whole = _run("press_cycle", 0.1, 101)
    kept = _run("press_cycle", 0.1, 101, sink=lambda part, start: None, chunk=10)
    np.testing.assert_allclose(kept.energy["balance"], whole.energy["balance"], rtol=1e-12)
    np.testing.assert_array_equal(kept.switching.mode_index, whole.switching.mode_index)
    assert len(kept.events) == len(whole.events)


@pytest.mark.parametrize("chunk", [0, -3, 2.5, True])
def test_a_bad_chunk_is_a_named_error(chunk):
    with pytest.raises(mechdyn.ModelError, match="chunk"):
        _run("four_bar", 0.01, 3, sink=lambda part, start: None, chunk=chunk)


def test_the_cli_streams_into_partial_and_renames_at_the_end(tmp_path, capsys):
    out = tmp_path / "fb.csv"
    assert main(["simulate", "four_bar", "--t-end", "0.1 s", "--samples", "501",
                 "--chunk", "64", "--points", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "wrote" in printed and "(501 rows)" in printed and "samples: 501 (streamed)" in printed
    assert not (tmp_path / "fb.csv.partial").exists()
    text = out.read_text()
    assert text.rstrip().splitlines()[-1] == "# status: success"
    df = read_csv(out)
    # the CLI's backend and integrator (the compiled loop where Numba is installed)
    ref = _run("four_bar", 0.1, 501, backend="auto").to_dataframe(points=True)
    assert list(df.columns) == list(ref.columns)
    np.testing.assert_allclose(df.to_numpy(float), ref.to_numpy(float), rtol=1e-11,
                               atol=1e-9)
    assert main(["simulate", "four_bar", "--t-end", "1 ms", "--chunk", "0", "-o",
                 str(out)]) == 2


def test_ctrl_c_writes_every_sample_computed(tmp_path, capsys, monkeypatch):
    """Ctrl-C while a chunk is handed over: NAME.csv holds every sample computed once
    (those of that chunk and of the last one too), marked interrupted."""
    calls = {"n": 0}
    append = CsvStream.__call__

    def interrupted_on_third_chunk(self, part, start):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return append(self, part, start)

    monkeypatch.setattr(CsvStream, "__call__", interrupted_on_third_chunk)
    out = tmp_path / "press.csv"
    code = main(["simulate", "clutchless_press", "--t-end", "1 s", "--backend", "numpy",
                 "--chunk", "7", "-o", str(out)])
    printed = capsys.readouterr().out
    assert code == 130
    rows = int(printed.split("samples: ")[1].split()[0])
    df = read_csv(out)
    assert len(df) == rows > 7 and df["t_s"].is_monotonic_increasing
    assert "# status: interrupted" in out.read_text()
    assert not (tmp_path / "press.csv.partial").exists()


def test_a_killed_run_leaves_a_readable_partial_file(tmp_path):
    """kill -9 in the middle of a long run: NAME.csv.partial holds whole chunks, readable
    with pandas; no NAME.csv is claimed."""
    out = tmp_path / "long.csv"
    partial = tmp_path / "long.csv.partial"
    proc = subprocess.Popen(
        [sys.executable, "-c", "import sys; from mechdyn.cli import main; sys.exit(main())",
         "simulate", "four_bar", "--t-end", "1000 s", "--samples", "2000001", "--chunk", "100",
         "--backend", "numpy", "--no-progress", "-o", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120.0
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if partial.exists() and partial.stat().st_size > 100_000:
                break
            time.sleep(0.2)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()
    df = pd.read_csv(partial, comment="#")
    assert len(df) >= 100 and len(df) % 100 == 0
    assert df["t_s"].iloc[0] == 0.0 and np.all(np.diff(df["t_s"]) > 0)
    assert not df.isna().any().any()
    assert "status:" not in partial.read_text()  # the outcome is not claimed


def test_a_stream_to_a_device_is_written_directly(tmp_path):
    if not os.path.exists("/dev/null"):
        pytest.skip("needs /dev/null")
    stream = CsvStream("/dev/null")
    traj = _run("four_bar", 0.01, 5, sink=stream, chunk=2, keep=False)
    assert str(stream.close(traj)) == "/dev/null" and stream.rows == 5
