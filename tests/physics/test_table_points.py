"""Steps of the compiled DOP853 loop that end at the sharp points of load tables
(mechdyn.kernels.table_regions, docs/dynamics.md "Table loads: one piece per step").

The press cycle's ram slows down as it runs into its spring table's end, which is also its
upper stop (28 mm): a step shortened to end at the point by linear interpolation lands
short of it.  The loop then aims at the point by regula falsi over the bracket of its time
(Illinois' rule); it used to start the next step from past the point again, which landed
short by about the same part each time, the steps falling geometrically (runs of 26 steps
below 0.1 us before the ram's impacts).  The motion itself must not change: the run is
checked against a converged one.
"""

import numpy as np
import pytest

import mechdyn
from mechdyn.dynamics.compiled import numba_available

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")


def longest_run_of_short_steps(t, short=1e-7) -> int:
    """The most steps in a row shorter than ``short`` (s); the repeated samples of an
    event (zero steps) neither count nor break a run."""
    run = best = 0
    for h in np.diff(t):
        run = run + 1 if 0.0 < h < short else (run if h == 0.0 else 0)
        best = max(best, run)
    return best


def test_press_cycle_reaches_its_table_points_without_runs_of_short_steps():
    press = mechdyn.examples.load("press_cycle")
    tr = mechdyn.simulate(press, 1.0, progress=False)  # every step is a sample
    assert tr.success
    assert longest_run_of_short_steps(tr.t) <= 4
    grid = np.linspace(0.0, 1.0, 201)
    ours = mechdyn.simulate(press, 1.0, progress=False, t_eval=grid)
    ref = mechdyn.simulate(press, 1.0, progress=False, t_eval=grid, rtol=1e-12)
    assert [(e.kind, e.element) for e in ours.events] == [(e.kind, e.element)
                                                         for e in ref.events]
    np.testing.assert_allclose([e.t for e in ours.events], [e.t for e in ref.events],
                               rtol=0, atol=1e-9)
    on_grid = [run.q[np.isin(run.t, grid)] for run in (ours, ref)]
    assert on_grid[0].shape == on_grid[1].shape == (grid.size, 3)
    assert np.max(np.abs(on_grid[0] - on_grid[1])) < 1e-7  # 2e-9 rad measured


def test_a_block_braked_up_to_the_end_of_a_force_table():
    """A block braked by 10 N up to s = 0.1 m, where the table ends (outside it, 0 N): it
    crosses at 0.2 m/s and runs on uniformly.  The path curves towards the point, so the
    first steps cut back to it land past it again by a few per cent of the step; halving
    the start's distance each time (Illinois) gets there in a few attempts, where the
    eight attempts used to run out with the step 3 % past the point (1.5e-3 m off at
    0.3 s)."""
    m = mechdyn.Mechanism("braked block", gravity=(0.0, 0.0))
    m.add_body("block", mass=1.0, inertia=0.1, pose=(0.0, 0.0, 0.0))
    m.add_prismatic("guide", "ground", "block", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="guide")
    brake = mechdyn.Table((0.0, 0.1), (-10.0, -10.0), "s", outside=0.0)
    m.add(mechdyn.Force("brake", "block", "com", brake, (1.0, 0.0)))
    vc = 0.2
    v0 = np.sqrt(vc**2 + 2 * 10.0 * 0.05)
    tc = (v0 - vc) / 10.0  # the crossing
    t = np.linspace(0.0, 0.3, 301)
    exact = np.where(t < tc, 0.05 + v0 * t - 5.0 * t**2, 0.1 + vc * (t - tc))
    tr = mechdyn.simulate(m, 0.3, q0={"s": 0.05}, qdot0={"s": v0}, t_eval=t,
                          progress=False)
    assert tr.success
    assert np.max(np.abs(tr.coordinate("s") - exact)) < 1e-9  # 1e-11 measured
