"""How close a run is to its limit: wall time against evaluations x the kernel's cost.

For four fixed-structure runs on the compiled (Numba) backend -- Andrews' squeezer to
0.03 s at rtol 1e-9, the clutchless press (paper case) over 0.05 s at rtol 1e-9, the
bundled slider-crank spun up by its motor from 1500 rpm for 2 s at rtol 1e-11 and the
bundled four-bar over 3 s at rtol 1e-11 -- one run reports, for the compiled loop
(``dop853``, the default) and SciPy's DOP853 stepped from Python (``scipy-dop853``, the
loop of the releases before):

* the wall time of ``mechdyn.simulate`` (best of a few, model compiled beforehand, the
  runs of a case given one :class:`~mechdyn.model.workspace.Workspace`, the warm start
  of repeated runs: the compiled model keeps none);
* the number of right-hand-side evaluations of the integrator;
* the kernel's own cost per evaluation, timed in a compiled loop over the states of the
  run (in order, so that every Newton solve starts from the previous pose as in a run),
  without allocating (:func:`mechdyn.kernels.dop853_numba.evaluate_states`);
* the ratio wall / (evaluations x cost): 1 is the limit, the overhead above it is the
  integration loop, the per-step work in Python and the fixed cost per run;
* the accuracy: Andrews against the Test Set reference (significant digits), the others
  against a run of the compiled DOP853 loop at rtol 1e-13 (digits in the coordinate and
  its rate) and the energy drift (J, conservative runs).  The reference is the compiled
  loop's because it ends its steps at the knees of the load tables (the slider-crank's
  motor curve): SciPy's DOP853 at rtol 1e-13 steps across them and is 8e-10 off in the
  slider-crank's end angle, where the compiled loop at 1e-13 agrees with RK4 at 10^6 steps
  to 6e-12.

The fixed-step integrators (RK4, Wilson's method: the paper's press with N = 40 and 320,
the slider-crank spin-up with RK4) report their compiled loop against their Python
stepper over the same kernel (:func:`fixed_step_table`): wall times, the speed-up, the
ratio wall / (evaluations x cost) of the compiled run and how far apart the two runs are.

A fifth case, the variable-structure press (``press_cycle`` over 0.4 s: stops, impacts,
the lock; its segments have event functions) against the same press without switches
(0.11 s, fixed structure; :mod:`benchmarks.bench_switching`), reports the wall time per
simulated second of each on both integrators and the ratios switched / fixed (issue 9's
figure, at most 3) and ``dop853`` / ``scipy-dop853``, all measured in one run.

``python -m benchmarks loop`` runs it (``python -m benchmarks.bench_loop`` prints one line
per run).
"""

from __future__ import annotations

import time

import numpy as np

from mechdyn.dynamics.mode_equations import ModeEquations
from mechdyn.dynamics.mode_system import ModeSystem
from mechdyn.examples import andrews, load
from mechdyn.examples.paper_case import press_idle
from mechdyn.kernels.rows_numba import NUMBA
from mechdyn.model.switchable import switched_model
from mechdyn.model.workspace import Workspace
from mechdyn.simulate.run import simulate

from .bench_dynamics import _best_of
from .bench_switching import T_END, T_FIXED, _models

#: (name, model factory, t_end s, simulate keywords)
CASES = (
    ("andrews 0.03 s rtol 1e-9", lambda: andrews.build(), 0.03, {"rtol": 1e-9, "atol": 1e-12}),
    ("press 0.05 s rtol 1e-9", lambda: press_idle(), 0.05, {"rtol": 1e-9}),
    ("slider-crank spin-up 2 s rtol 1e-11", lambda: load("slider_crank"), 2.0,
     {"rtol": 1e-11}),
    ("four-bar 3 s rtol 1e-11", lambda: load("four_bar"), 3.0, {"rtol": 1e-11}),
)


def kernel_cost(model, tr, passes: int = 40) -> float:
    """Seconds per evaluation of the mode's compiled kernel, timed in a compiled loop over
    the states of the run ``tr`` (in order): the best of many short passes (the machine
    is shared; a pass is about 2000 evaluations)."""
    from mechdyn.dynamics.loop_buffers import buffers
    from mechdyn.kernels.dop853_numba import evaluate_states

    sm = switched_model(model)
    ms = ModeSystem(sm, frozenset(), {}, tr.x[0], workspace=Workspace())
    k = ModeEquations(sm, ms, "numba").kernel
    b = buffers(k)
    Y = np.ascontiguousarray(np.hstack([tr.q[:, ms.coords], tr.qdot[:, ms.coords]]))
    best = np.inf
    for start in range(passes):
        a = (start * 2000) % max(1, len(Y) - 2000) if len(Y) > 2000 else 0
        chunk = slice(a, a + 2000)
        reps = max(1, 2000 // len(Y[chunk]))
        k.reset(tr.x[chunk.start])
        t0 = time.perf_counter()
        evaluate_states(tr.t[chunk], Y[chunk], reps, *k.arrays, k.ws, b.sc, b.piv)
        best = min(best, (time.perf_counter() - t0) / (reps * len(Y[chunk])))
    return best


def _digits(model, name, tr, t_end, opts):
    if name.startswith("andrews"):
        ang = andrews.test_set_angles(model, tr.x[-1])
        ref = andrews.REFERENCE_T003
        return -np.log10(max(abs(ang[k] - ref[k]) / abs(ref[k]) for k in ref)), np.nan
    ref = simulate(model, t_end, progress=False, t_eval=[t_end],
                   **{**opts, "rtol": 1e-13, "atol": 1e-16, "integrator": "dop853"})
    eq = abs(tr.q[-1, 0] - ref.q[-1, 0]) / max(abs(ref.q[-1, 0]), 1e-300)
    ed = abs(tr.qdot[-1, 0] - ref.qdot[-1, 0]) / max(abs(ref.qdot[-1, 0]), 1e-300)
    return -np.log10(max(eq, 1e-17)), -np.log10(max(ed, 1e-17))


def table(integrators=("dop853", "scipy-dop853"), repeat: int = 7) -> list[dict]:
    """One row per (case, integrator): wall, evaluations, cost, ratio, accuracy (the runs
    of the integrators interleaved, the best wall time of each)."""
    out = []
    for name, build, t_end, opts in CASES:
        model = build().compile()
        ws = Workspace()  # the repeated runs' warm start (the model keeps none)
        simulate(model, min(t_end, 1e-3), progress=False, **opts)  # compile / load kernels
        best = dict.fromkeys(integrators, np.inf)
        runs = {}
        for _ in range(repeat):
            for integ in integrators:
                wall, runs[integ] = _best_of(
                    lambda m=model, te=t_end, o=opts, i=integ, w=ws: simulate(
                        m, te, progress=False, integrator=i, workspace=w, **o), 1)
                best[integ] = min(best[integ], wall)
        cost = None
        for integ in integrators:
            tr = runs[integ]
            assert tr.success, tr.message
            if cost is None:
                cost = kernel_cost(model, tr)
            evals = tr.stats["evaluations"]
            d_q, d_v = _digits(model, name, tr, t_end, opts)
            drift = tr.energy_drift() if np.all(tr.energy["work_nc"] == 0.0) else np.nan
            out.append(dict(case=name, integrator=integ, wall=best[integ], evals=evals,
                            cost=cost, ratio=best[integ] / (evals * cost),
                            steps=tr.stats["steps"],
                            # SciPy's solver classes do not report their rejected steps
                            rejected=tr.stats["rejected"] if integ == "dop853" else "?",
                            digits_q=d_q, digits_v=d_v, drift=drift))
    return out


def press_cycle_table(integrators=("dop853", "scipy-dop853"), repeat: int = 3) -> dict:
    """Best wall time per simulated second (s/s) of the switched press (``T_END``) and the
    fixed-structure press (``T_FIXED``) on each integrator, runs interleaved:
    ``{(press, integrator): (s/s, trajectory)}``."""
    switched, fixed = _models()
    for m in (switched, fixed):
        simulate(m, 1e-3, progress=False)  # compile / load the kernels first
    out = {}
    for _ in range(repeat):
        for press, model, te in (("switched", switched, T_END), ("fixed", fixed, T_FIXED)):
            for integ in integrators:
                t0 = time.perf_counter()
                tr = simulate(model, te, progress=False, integrator=integ)
                wall = (time.perf_counter() - t0) / te
                if wall < out.get((press, integ), (np.inf,))[0]:
                    out[press, integ] = (wall, tr)
    return out


def press_cycle_rows(repeat: int = 3) -> list[dict]:
    """The rows of :func:`press_cycle_table` with the ratios switched / fixed and
    dop853 / scipy-dop853."""
    res = press_cycle_table(repeat=repeat)
    rows = []
    for (press, integ), (wall, tr) in res.items():
        rows.append({"name": f"press {press} {integ} wall per simulated s", "value": wall,
                     "unit": "s/s", "note": f"{tr.status}, {len(tr.events)} events, "
                     f"{tr.stats['steps']} steps, {tr.stats['evaluations']} evals"})
    for integ in ("dop853", "scipy-dop853"):
        rows.append({"name": f"press switched / fixed, {integ}",
                     "value": res["switched", integ][0] / res["fixed", integ][0], "unit": "",
                     "note": "issue 9: at most 3"})
    for press in ("switched", "fixed"):
        rows.append({"name": f"press {press}: dop853 / scipy-dop853",
                     "value": res[press, "dop853"][0] / res[press, "scipy-dop853"][0],
                     "unit": ""})
    return rows


#: (name, model factory, t_end s, integrator, steps): the fixed-step runs compared
FIXED_CASES = (
    ("press 0.05 s wilson N = 40", lambda: press_idle(), 0.05, "wilson", 40),
    ("press 0.05 s rk4 N = 320", lambda: press_idle(), 0.05, "rk4", 320),
    ("slider-crank spin-up 2 s rk4 N = 20000", lambda: load("slider_crank"), 2.0, "rk4", 20000),
)


def fixed_step_table(repeat: int = 5) -> list[dict]:
    """The compiled RK4 / Wilson loops against their Python steppers over the same kernel
    (``RungeKutta4(compiled=False)``, ``Wilson(compiled=False)``), runs interleaved: the
    best wall time of each, the speed-up, the compiled run's ratio wall / (evaluations x
    kernel cost) and the largest difference of q and q' between the two (relative to
    their largest values)."""
    from mechdyn.integrate import RungeKutta4, Wilson

    out = []
    for name, build, t_end, integ, steps in FIXED_CASES:
        model = build().compile()
        cls = Wilson if integ == "wilson" else RungeKutta4
        best, runs = {True: np.inf, False: np.inf}, {}
        ws = Workspace()  # the repeated runs' warm start (the model keeps none)
        simulate(model, t_end, progress=False, integrator=cls(steps=steps))  # load kernels
        for _ in range(repeat):
            for compiled in (True, False):
                wall, runs[compiled] = _best_of(
                    lambda m=model, te=t_end, k=cls, n=steps, c=compiled, w=ws: simulate(
                        m, te, progress=False, integrator=k(steps=n, compiled=c),
                        workspace=w), 1)
                best[compiled] = min(best[compiled], wall)
        ours, ref = runs[True], runs[False]
        assert ours.success and ref.success, (ours.message, ref.message)
        diff = max(np.max(np.abs(ours.q - ref.q)) / np.max(np.abs(ref.q)),
                   np.max(np.abs(ours.qdot - ref.qdot)) / np.max(np.abs(ref.qdot)))
        cost = kernel_cost(model, ours)
        out.append(dict(case=name, compiled=best[True], python=best[False],
                        speedup=best[False] / best[True], evals=ours.stats["evaluations"],
                        ratio=best[True] / (ours.stats["evaluations"] * cost), diff=diff))
    return out


def fixed_step_rows(repeat: int = 5) -> list[dict]:
    """The rows of :func:`fixed_step_table`."""
    rows = []
    for r in fixed_step_table(repeat):
        rows.append({"name": f"{r['case']} compiled wall", "value": r["compiled"] * 1e3,
                     "unit": "ms", "note": f"{r['evals']} evals, wall/(evals x cost) "
                     f"{r['ratio']:.2f}, differs from the Python stepper by {r['diff']:.1e}"})
        rows.append({"name": f"{r['case']} Python stepper wall", "value": r["python"] * 1e3,
                     "unit": "ms"})
        rows.append({"name": f"{r['case']} Python / compiled", "value": r["speedup"],
                     "unit": ""})
    return rows


def run(quick: bool = False) -> list[dict]:
    if not NUMBA:
        return [{"name": "compiled loop", "value": "skipped", "note": "numba not installed"}]
    rows = []
    for r in table(repeat=2 if quick else 7):
        head = f"{r['case']} {r['integrator']}"
        rows.append({"name": f"{head} wall", "value": r["wall"] * 1e3, "unit": "ms",
                     "note": f"{r['evals']} evals ({r['steps']} steps, {r['rejected']} "
                             f"rejected), {r['digits_q']:.1f}/{r['digits_v']:.1f} digits, "
                             f"drift {r['drift']:.1e} J"})
        rows.append({"name": f"{head} kernel cost", "value": r["cost"] * 1e6, "unit": "us"})
        rows.append({"name": f"{head} wall/(evals x cost)", "value": r["ratio"], "unit": ""})
    return rows + fixed_step_rows(repeat=1 if quick else 5) + press_cycle_rows(
        repeat=1 if quick else 3)


if __name__ == "__main__":
    for r in fixed_step_table():
        print(f"{r['case']:40s} compiled {r['compiled'] * 1e3:8.2f} ms  Python "
              f"{r['python'] * 1e3:8.2f} ms  x{r['speedup']:5.1f}  evals {r['evals']:6d}  "
              f"ratio {r['ratio']:5.2f}  differs {r['diff']:.1e}")
    for r in press_cycle_rows():
        print(f"{r['name']:44s} {r['value']:9.4g} {r['unit']:4s} {r.get('note', '')}")
    for r in table():
        print(f"{r['case']:38s} {r['integrator']:13s} wall {r['wall'] * 1e3:8.2f} ms  "
              f"evals {r['evals']:6d}  cost {r['cost'] * 1e6:6.2f} us  ratio {r['ratio']:5.2f}  "
              f"steps {r['steps']:5d}/{r['rejected']:>4}  digits {r['digits_q']:4.1f}/"
              f"{r['digits_v']:4.1f}  drift {r['drift']:.1e}")
