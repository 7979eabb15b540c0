"""The test session: the Numba kernels are compiled (or loaded from the disk cache) once,
before the first test, so that no test's time limit counts their first compile (1-3
minutes on a fresh machine, see docs/dynamics.md); the subprocesses of the CLI tests then
load them from the same cache."""

from __future__ import annotations

import sys
import time


def pytest_sessionstart(session) -> None:
    from mechdyn.compiler import warmup

    t0 = time.perf_counter()
    times = warmup()
    spent = time.perf_counter() - t0
    if spent > 5.0:
        groups = ", ".join(f"{k} {v:.0f} s" for k, v in times.items() if k != "total")
        print(f"\nmechdyn kernels compiled for the tests in {spent:.0f} s ({groups})",
              file=sys.stderr)
