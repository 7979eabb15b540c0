"""Kinematic sweep of the six-bar toggle press: vectorized sweep vs a per-point loop.

3600 positions over one crank turn.  The vectorized :func:`mechdyn.kinematics.sweep.sweep`
computes positions, velocity analogs, velocities and accelerations of every body;
the loop calls ``solve_position`` once per position, starting Newton from the
previous solution (positions only, so the ratio is conservative), and, on a
tenth of the points, also the analogs and accelerations per point.
"""

from __future__ import annotations

import time

import numpy as np

from mechdyn import examples
from mechdyn.kinematics import accelerations, solve_position, velocity_analogs
from mechdyn.kinematics.sweep import initial_coordinates, sweep

N_POINTS = 3600


def toggle_press_model():
    """The bundled toggle press (``examples/toggle_press.toml``), compiled."""
    return examples.load("toggle_press").compile()


def _best(fn, repeats: int) -> tuple[float, float]:
    """Shortest wall time and shortest process CPU time of ``repeats`` calls, s.

    The CPU time is the steadier figure on a shared machine (other processes stretch
    the wall time, not the CPU time of this one)."""
    wall = cpu = np.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    return wall, cpu


def run(quick: bool = False) -> list[dict]:
    model = toggle_press_model()
    k = 0
    phi0 = float(initial_coordinates(model)[k])
    values = phi0 + np.linspace(0.0, 2 * np.pi, N_POINTS)
    sweep(model, values=values)  # warm-up: kernel set-up, caches
    t_vec, c_vec = _best(lambda: sweep(model, values=values), 3 if quick else 20)
    sw = sweep(model, values=values)

    def loop(vals, full=False):
        x = model.x0.copy()
        xs = np.empty((vals.size, model.n_x))
        for i, v in enumerate(vals):
            x = solve_position(model, np.array([v]), x)
            if full:
                B = velocity_analogs(model, x)
                xdot = B[:, 0]
                accelerations(model, x, xdot, np.zeros(1), B=B)
            xs[i] = x
        return xs

    t0, c0 = time.perf_counter(), time.process_time()
    xs = loop(values)
    t_loop, c_loop = time.perf_counter() - t0, time.process_time() - c0
    sub = values[::10]
    t_full, c_full = _best(lambda: loop(sub, full=True), 1 if quick else 2)
    err = float(np.max(np.abs(xs - sw.x)))
    return [
        {"name": "sweep 3600 positions, vectorized (CPU)", "value": N_POINTS / c_vec,
         "unit": "positions/s",
         "note": f"{c_vec * 1e3:.1f} ms CPU, with velocities+accelerations; target >= 100000"},
        {"name": "sweep 3600 positions, vectorized (wall)", "value": N_POINTS / t_vec,
         "unit": "positions/s", "note": f"{t_vec * 1e3:.1f} ms wall, best of the runs"},
        {"name": "loop of solve_position (CPU)", "value": N_POINTS / c_loop,
         "unit": "positions/s",
         "note": f"{c_loop:.2f} s CPU ({t_loop:.2f} s wall), positions only"},
        {"name": "loop solve+analogs+accelerations (CPU)", "value": sub.size / c_full,
         "unit": "positions/s", "note": f"{sub.size} positions"},
        {"name": "ratio vectorized / loop (CPU)", "value": c_loop / c_vec, "unit": "x",
         "note": f"vs the positions-only loop; {(c_full / sub.size) / (c_vec / N_POINTS):.0f}x "
                 "vs the full loop"},
        {"name": "max |x_sweep - x_loop|", "value": err, "unit": "m or rad",
         "note": "the same positions"},
        {"name": "coarse continuation steps", "value": sw.stats["coarse_steps"], "unit": "",
         "note": f"{sw.stats['anchors']} anchors"},
    ]
