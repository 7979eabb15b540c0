"""Benchmark of forward dynamics: Andrews' squeezer work-precision and the press.

Run ``python -m benchmarks`` (all benchmarks) or ``python benchmarks/bench_dynamics.py``.

* Andrews' squeezer to t = 0.03 s against the Test Set reference (Mazzia &
  Magherini, release 2.4): largest relative error of the seven angles, wall time
  and right-hand-side evaluations for DOP853, Radau, RK4 and Wilson at several
  tolerances / step counts (a work-precision table), with the compiled kernel
  and, for comparison, the NumPy reference path.  Target: 8 significant digits
  in <= 50 ms, position solves included.
* The clutchless press (paper case, ``mechdyn.examples.paper_case``) over 1 s.
"""

from __future__ import annotations

import time

import numpy as np

from mechdyn.dynamics.compiled import numba_available
from mechdyn.examples import andrews
from mechdyn.examples.paper_case import motor_curve, press_idle
from mechdyn.simulate.run import simulate


def _andrews_error(model, tr, andrews):
    ang = andrews.test_set_angles(model, tr.x[-1])
    ref = andrews.REFERENCE_T003
    return max(abs(ang[k] - ref[k]) / abs(ref[k]) for k in ref)


def _best_of(fn, repeat=3):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def andrews_table(backend="auto", repeat=3):
    model = andrews.build().compile()
    t0 = time.perf_counter()
    first = simulate(model, 0.001, backend=backend)  # compile / load the kernel
    setup = time.perf_counter() - t0
    rows = []
    cases = [("dop853", {"rtol": r, "atol": r * 1e-3}) for r in (1e-8, 1e-9, 1e-10, 1e-11)]
    cases += [("radau", {"rtol": r, "atol": r * 1e-3}) for r in (1e-8, 1e-10)]
    cases += [("rk4", {"steps": n}) for n in (2000, 8000)]
    cases += [("wilson", {"steps": n}) for n in (8000, 32000)]
    if backend == "numpy":
        cases = [c for c in cases if c[0] == "dop853" and c[1]["rtol"] in (1e-8, 1e-10)]
    for name, opts in cases:
        wall, tr = _best_of(lambda name=name, opts=opts: simulate(
            model, 0.03, integrator=name, backend=backend, progress=False, **opts),
            repeat=repeat if name in ("dop853", "radau") else 1)
        setting = ", ".join(f"{k}={v:g}" for k, v in opts.items())
        rows.append((name, setting, _andrews_error(model, tr, andrews), wall,
                     tr.stats["evaluations"], tr.stats["steps"], tr.status))
    return rows, setup, first.stats.get("compile_time_s", float("nan"))


def press_run(seconds=1.0):
    # over 1 s a constant torque would run the unloaded press away: a motor-like curve
    model = press_idle(drive_torque=motor_curve()).compile()
    out = []
    for name, opts in (("dop853", {"rtol": 1e-9}), ("rk4", {"steps": 4000}),
                       ("wilson", {"steps": 4000})):
        wall, tr = _best_of(lambda name=name, opts=opts: simulate(
            model, seconds, integrator=name, progress=False, **opts), repeat=1)
        out.append((name, opts, wall, tr))
    return out


def run(quick: bool = False) -> list[dict]:
    """Rows for ``python -m benchmarks``: name, value, unit, note."""
    model = andrews.build().compile()
    t0 = time.perf_counter()
    first = simulate(model, 0.001)
    rows = [{"name": "andrews kernel compile/load", "value": time.perf_counter() - t0,
             "unit": "s", "note": f"backend {first.stats['backend']}"}]
    for rtol in (1e-9, 1e-10):
        wall, tr = _best_of(lambda rtol=rtol: simulate(model, 0.03, rtol=rtol, atol=rtol * 1e-3,
                                                       progress=False),
                            repeat=1 if quick else 5)
        err = _andrews_error(model, tr, andrews)
        note = f"max rel err {err:.2e}, {tr.stats['evaluations']} evaluations (target 50 ms)"
        rows.append({"name": f"andrews dop853 rtol={rtol:g} wall", "value": wall * 1e3,
                     "unit": "ms", "note": note})
    if not quick:
        for name, _opts, wall, tr in press_run():
            rows.append({"name": f"press 1 s {name}", "value": wall, "unit": "s",
                         "note": f"{tr.status}, {tr.stats['evaluations']} evaluations"})
    return rows


def main() -> None:
    print("== bench_dynamics: Andrews' squeezer to t = 0.03 s (Test Set reference) ==")
    print(f"numba available: {numba_available()}")
    for backend in ("auto", "numpy"):
        rows, setup, compile_time = andrews_table(backend)
        print(f"\nbackend {backend}: first call (compile or load the kernel, assemble) "
              f"{setup:.2f} s; kernel compile/load time {compile_time:.2f} s")
        print(f"{'integrator':<10} {'setting':<24} {'max rel err':>12} {'wall ms':>9} "
              f"{'evals':>7} {'steps':>6}  status")
        for name, setting, err, wall, ev, st, status in rows:
            print(f"{name:<10} {setting:<24} {err:12.3e} {wall * 1e3:9.1f} {ev:7d} {st:6d}  "
                  f"{status}")
    print("\n== the clutchless press (paper case with a motor-like curve, ram support), 1 s ==")
    for name, opts, wall, tr in press_run():
        print(f"{name:<8} {opts}: {tr.status}, {tr.stats['steps']} steps, "
              f"{tr.stats['evaluations']} evaluations, wall {wall:.3f} s, energy balance drift "
              f"{tr.energy_drift():.2e} J, phi(1 s) = {np.rad2deg(tr.q[-1, 0]):.6g} deg")


if __name__ == "__main__":
    main()
