"""Benchmark of the variable-structure event loop (``simulate_events``).

Run ``python -m benchmarks switching`` or ``python benchmarks/bench_switching.py``.

The bundled press cycle (``mechdyn.examples.load("press_cycle")``: stops, a
unilateral contact, a switched coordinate lock, impacts) simulated over
0.3 s (``quick``) or 0.8 s: wall time, wall time per simulated second,
right-hand-side evaluations and switching events.  The best of a few runs is
reported (the machine may be shared).
"""

from __future__ import annotations

import time

import numpy as np


def press_events(t_end: float, repeat: int = 3):
    """(best wall time in s, trajectory) of the press cycle to ``t_end``."""
    import mechdyn

    model = mechdyn.examples.load("press_cycle")
    best, tr = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        tr = mechdyn.simulate(model, t_end, progress=False)
        best = min(best, time.perf_counter() - t0)
    return best, tr


def run(quick: bool = False) -> list[dict]:
    """Rows for ``python -m benchmarks``: name, value, unit, note."""
    t_end = 0.3 if quick else 0.8
    wall, tr = press_events(t_end, repeat=1 if quick else 3)
    note = (f"{tr.status}, {len(tr.events)} events, {tr.stats['evaluations']} evaluations, "
            f"{tr.stats['steps']} steps")
    return [
        {"name": f"press_cycle {t_end:g} s wall", "value": wall, "unit": "s", "note": note},
        {"name": "press_cycle wall per simulated s", "value": wall / t_end, "unit": "s/s"},
        {"name": "press_cycle time per evaluation",
         "value": wall / max(tr.stats["evaluations"], 1) * 1e6, "unit": "us"},
    ]


def main() -> None:
    for row in run():
        print(f"{row['name']:<36} {row['value']:10.4g} {row['unit']:<4} {row.get('note', '')}")


if __name__ == "__main__":
    main()
