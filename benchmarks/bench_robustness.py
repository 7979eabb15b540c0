"""Robustness budgets: the memory of long runs and the time to load large model files.

Run ``python -m benchmarks robustness``.

* Peak resident memory of ``mechdyn simulate four_bar -o out.csv`` over 10 s and over
  100 s of motion, each in a fresh process, with 1000 rows per second of motion (10 001
  and 100 001 rows): ``-o`` streams the rows to disk in chunks, so memory must not grow
  with the length of the run (acceptance: the two peaks within 10 %).
* Time to load a model file whose crank carries 20 000 named points (every unit is read
  by pint once).
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _peak_rss_mb(seconds: int, out: Path) -> float:
    """Peak RSS (MB) of one ``mechdyn simulate`` of ``seconds`` s (1000 rows per s) in a
    child process."""
    code = ("import resource, sys; from mechdyn.cli import main; "
            f"code = main(['simulate', 'four_bar', '--t-end', '{seconds} s', '--samples', "
            f"'{1000 * seconds + 1}', '-o', r'{out}', '--no-progress']); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(code)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return int(res.stdout.strip().splitlines()[-1]) / 1024.0


def _load_seconds(n_points: int) -> float:
    from mechdyn import examples
    from mechdyn.modelfile import loads

    text = examples.path("slider_crank").read_text(encoding="utf-8")
    pts = "\n".join(f'P{k} = ["{k * 0.001:.3f} mm", "0 mm"]' for k in range(n_points))
    text = text.replace("[bodies.crank.points]", "[bodies.crank.points]\n" + pts, 1)
    start = time.perf_counter()
    loads(text, name="big.toml")
    return time.perf_counter() - start


def run(quick: bool = False) -> list[dict]:
    """Rows of the benchmark table."""
    with tempfile.TemporaryDirectory() as tmp:
        short = _peak_rss_mb(10, Path(tmp) / "a.csv")
        long = _peak_rss_mb(10 if quick else 100, Path(tmp) / "b.csv")
    n = 5000 if quick else 20000
    seconds = _load_seconds(n)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return [
        {"name": "four-bar 10 s, peak RSS", "value": short, "unit": "MB"},
        {"name": f"four-bar {'10' if quick else '100'} s, peak RSS", "value": long,
         "unit": "MB"},
        {"name": "peak RSS ratio long / short", "value": long / short, "unit": "",
         "note": "acceptance: within 10 %"},
        {"name": f"load a model file with {n} points", "value": seconds, "unit": "s",
         "note": f"peak RSS of this process {rss:.0f} MB"},
    ]


if __name__ == "__main__":
    for row in run(quick="--quick" in sys.argv):
        print(row)
