"""Benchmark of the start-up: ``import mechdyn`` and ``mechdyn --help``.

Run ``python -m benchmarks start`` or ``python benchmarks/bench_start.py``.

Each is timed as a fresh Python process (``subprocess``, wall time from launch to
exit, the interpreter's own start included), best of 5; the acceptance figure is
under 0.3 s for both.  A bare interpreter (``python -c pass``) is timed the same way
for reference, and ``mechdyn warmup`` once: in a process of its own, the time to load
every compiled kernel from the user's cache folder (or, on a fresh machine, to compile
them -- its note says which).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import mechdyn

#: the folder that holds the package, put first on the children's PYTHONPATH
SRC = str(Path(mechdyn.__file__).resolve().parents[1])
REPEAT = 5
LIMIT = 0.3  # s, the acceptance figure

CASES = {
    "python -c pass (interpreter alone)": "pass",
    "import mechdyn": "import mechdyn",
    "mechdyn --help": "import sys; from mechdyn.cli import main; sys.exit(main(['--help']))",
}


def _env() -> dict[str, str]:
    path = os.environ.get("PYTHONPATH")
    return {**os.environ, "PYTHONPATH": SRC if not path else os.pathsep.join((SRC, path))}


def wall_time(code: str, repeat: int = REPEAT) -> float:
    """Best wall time (s) of ``repeat`` fresh processes running ``python -c code``."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], env=_env(), check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t0)
    return best


def run(quick: bool = False) -> list[dict]:
    rows = []
    for name, code in CASES.items():
        best = wall_time(code, REPEAT)
        note = f"best of {REPEAT} processes"
        if code != "pass":
            note += f"; acceptance: under {LIMIT:g} s ({'met' if best < LIMIT else 'NOT met'})"
        rows.append({"name": name, "value": best, "unit": "s", "note": note})
    if not quick:
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", "import sys; from mechdyn.cli import "
                               "main; sys.exit(main(['warmup']))"], env=_env(), check=True,
                              capture_output=True, text=True)
        fresh = "compiling" in done.stderr
        rows.append({"name": "mechdyn warmup", "value": time.perf_counter() - t0, "unit": "s",
                     "note": "compiled the kernels (first use on this machine)" if fresh
                     else "kernels loaded from the user's cache folder"})
    return rows


def main() -> None:
    for row in run():
        print(f"{row['name']:<40} {row['value']:8.3f} {row['unit']:<2} {row.get('note', '')}")


if __name__ == "__main__":
    main()
