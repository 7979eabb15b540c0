"""Kinetostatic cycle of the six-bar toggle press: vectorized over positions vs a loop.

The vectorized analysis solves the positions by the sweep's continuation (anchors
every 5 deg, then one batched Newton solve), then the velocities, accelerations, loads and the
inverse-dynamics systems of all positions in single batched calls.  The loop
does the same work position by position (continuation from the previous pose,
one inverse solve per position), as a scalar implementation would.

``python -m benchmarks kinetostatics`` or ``python benchmarks/bench_kinetostatics.py``.
"""

from __future__ import annotations

import time

import numpy as np

from mechdyn import examples
from mechdyn.dynamics.reactions import batched_inverse
from mechdyn.kinematics.sweep import analyze
from mechdyn.kinetostatics.inverse import kinetostatics

N_POSITIONS = 3600
OMEGA = 40 * 2 * np.pi / 60  # rad/s, 40 strokes per minute


def _model():
    return examples.load("toggle_press").compile()


def vectorized(model, values):
    return kinetostatics(model, over="phi", speed=OMEGA, values=values)


def per_position_loop(model, values):
    """The same analysis, one position at a time; returns the driving torques (n,)."""
    lay = model.layout()
    didx = np.array([model.coordinate_index("phi")])
    x = model.x0
    tau = np.empty(values.size)
    for k in range(values.size):
        pt = analyze(model, [values[k]], [OMEGA], x_guess=x)  # from the previous pose
        x, q = pt.x, pt.q[None, :]
        t = np.array([(values[k] - values[0]) / OMEGA])
        tau[k] = batched_inverse(model, lay, didx, t, x[None], pt.xdot[None], pt.xddot[None], q,
                          q * 0 + OMEGA, skip=didx, reacting=(), point=np.zeros(2))["tau"][0, 0]
    return tau


def run(quick: bool = False) -> list[dict]:
    """Benchmark rows for ``python -m benchmarks``."""
    model = _model()
    n = 720 if quick else N_POSITIONS
    values = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    vectorized(model, values[:10])  # warm up
    reps = 1 if quick else 3
    t_vec = []
    for _ in range(reps):
        t0 = time.perf_counter()
        res = vectorized(model, values)
        t_vec.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    tau = per_position_loop(model, values)
    t_loop = time.perf_counter() - t0
    diff = float(np.max(np.abs(tau - res.driving["phi"])))
    tv = min(t_vec)
    return [
        {"name": f"toggle press cycle, {n} positions, vectorized", "value": tv, "unit": "s"},
        {"name": f"toggle press cycle, {n} positions, per-position loop", "value": t_loop,
         "unit": "s"},
        {"name": "loop / vectorized", "value": t_loop / tv, "unit": "x"},
        {"name": "max |torque difference| loop vs vectorized", "value": diff, "unit": "N m"},
        {"name": "power balance residual (relative)",
         "value": res.stats["power_balance_rel"], "unit": "-"},
    ]


def main(quick: bool = False) -> None:
    """Print the benchmark rows."""
    for row in run(quick=quick):
        print(f"{row['name']:<55s} {row['value']:>12.4g} {row['unit']}")


if __name__ == "__main__":
    import sys

    main(quick="--quick" in sys.argv)
