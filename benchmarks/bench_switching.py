"""Benchmark of variable-structure runs against the same press without switches.

Run ``python -m benchmarks switching`` or ``python benchmarks/bench_switching.py``.

The bundled press cycle (``mechdyn.examples.load("press_cycle")``: stops, a
unilateral contact, a switched coordinate lock, impacts) and the same model with
its switches, stops, contacts and coordinate locks removed (a fixed-structure
run on the compiled path) are simulated over the same interval in one process,
alternately; the best of a few runs of each is reported with their ratio of
wall time per simulated second (the acceptance figure: at most 3), and the
lock/release event times of the switched run.  Without its stops the ram of the
fixed-structure press drifts into the change point (a singular position) at
0.119 s, so that run covers 0.11 s; both are normalized per simulated second.
"""

from __future__ import annotations

import time

import numpy as np

import mechdyn

T_END = 0.4  # the switched run: idle, engage, work stroke, release
T_FIXED = 0.11  # the fixed-structure run, inside its regular range


def _models():
    switched = mechdyn.examples.load("press_cycle").compile()
    bare = mechdyn.examples.load("press_cycle")
    for key in ("switches", "stops", "contacts", "coordinate_locks"):
        bare.extras.pop(key, None)
    return switched, bare.compile()


def compare(t_end: float = T_END, repeat: int = 3):
    """Best wall times per simulated second of the switched and the fixed-structure
    press, and their trajectories."""
    switched, fixed = _models()
    mechdyn.simulate(fixed, 1e-3, progress=False)  # compile / load the kernels first
    best = {"switched": np.inf, "fixed": np.inf}
    out = {}
    for _ in range(repeat):
        for name, model, te in (("switched", switched, t_end), ("fixed", fixed, T_FIXED)):
            t0 = time.perf_counter()
            tr = mechdyn.simulate(model, te, progress=False)
            best[name] = min(best[name], (time.perf_counter() - t0) / te)
            out[name] = tr
    return best, out


def run(quick: bool = False) -> list[dict]:
    """Rows for ``python -m benchmarks``: name, value, unit, note."""
    best, tr = compare(T_END, repeat=1 if quick else 3)
    sw, fx = tr["switched"], tr["fixed"]
    locks = [f"{e.kind} {e.t:.9f}" for e in sw.events if getattr(e, "kind", "") in
             ("engage", "release")]
    return [
        {"name": f"press_cycle {T_END:g} s wall per simulated s", "value": best["switched"],
         "unit": "s/s", "note": f"{sw.status}, {len(sw.events)} events, "
         f"{sw.stats['evaluations']} evaluations, backend {sw.stats['backend']}"},
        {"name": f"same press without switches, {T_FIXED:g} s", "value": best["fixed"],
         "unit": "s/s",
         "note": f"{fx.status}, {fx.stats['evaluations']} evaluations, "
         f"backend {fx.stats['backend']}"},
        {"name": "ratio switched / fixed", "value": best["switched"] / best["fixed"],
         "unit": "", "note": "acceptance: at most 3"},
        {"name": "lock events", "value": len(locks), "unit": "", "note": "; ".join(locks)},
    ]


def main() -> None:
    for row in run():
        print(f"{row['name']:<44} {row['value']:10.4g} {row['unit']:<4} {row.get('note', '')}")


if __name__ == "__main__":
    main()
