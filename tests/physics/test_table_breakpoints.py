"""The compiled DOP853 loop holds a load table's piece through a step and ends its steps
at the table's points.

Oracles, all independent of the loop: the energy of a mass on a piecewise-linear
(hardening) spring given as a force table over its travel, ``T + V(s)`` with ``V`` the
exact integral of the table (a sum of trapezoids), through 120 crossings of the table's
knees; the closed form of a disc spun up by a torque-speed table with a knee against a
constant load torque (constant acceleration, then an exponential approach); the closed
form of a mass pushed by a force ramp over time; convergence of the end state as rtol
falls; and the regions of hand-worked tables.
"""

import math

import numpy as np
import pytest

from mechdyn.dynamics.compiled import numba_available
from mechdyn.kernels.table_regions import region_bounds, region_of, region_value, sharp_breakpoints
from mechdyn.mechanism import Drive, Force, Mechanism, Table, Torque, TorqueSpeedCurve
from mechdyn.simulate.run import simulate

needs_numba = pytest.mark.skipif(not numba_available(), reason="numba not installed")

MASS = 1.0
XS = np.array([-0.1, -0.02, 0.02, 0.1])  # m: soft inside +-20 mm, stiff outside
K1, K2 = 100.0, 1.0e4  # N/m
YS = np.array([K1 * 0.02 + K2 * 0.08, K1 * 0.02, -K1 * 0.02, -(K1 * 0.02 + K2 * 0.08)])


def _potential(s):
    """V(s) = -int_0^s F: the exact integral of the piecewise-linear table (trapezoids
    between its points), for |s| <= 0.1 m."""
    pts = np.unique(np.concatenate([[0.0, s], XS[(XS > min(0.0, s)) & (XS < max(0.0, s))]]))
    f = np.interp(pts, XS, YS)
    area = np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(pts))
    return -area if s >= 0 else area


def _slider(magnitude):
    m = Mechanism("mass on a table spring", gravity=(0.0, 0.0))
    m.add_body("mass", mass=MASS, inertia=0.1)
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    m.add(Force("spring", "mass", magnitude=magnitude, direction=(1.0, 0.0)))
    return m


def test_sharp_points_of_ramps_jumps_and_fine_tables():
    assert sharp_breakpoints([0.0, 1.0, 2.0], [0.0, 10.0, 10.0]).tolist() == [0.0, 1.0]
    # a table that ends with an outside value jumps at both ends
    assert sharp_breakpoints([0.0, 1.0], [5.0, 5.0], outside=0.0).tolist() == [0.0, 1.0]
    # periodic, held end value 0.25 on (3, 6) then 0.5 again at 6 (= 1 + period): a jump
    assert 1.0 in sharp_breakpoints([1.0, 2.0, 3.0], [0.5, 2.0, 0.25], period=5.0)
    # a sine tabulated at 400 points bends by about 2.5e-4 of its amplitude at each inner
    # point; at its ends the held value bends it by its slope times 1.6e-2
    xs = np.linspace(0.0, 2 * np.pi, 400)
    assert sharp_breakpoints(xs, np.sin(xs)).tolist() == [xs[0], xs[-1]]
    assert sharp_breakpoints([0.0, 1.0], [0.0, 0.0]).size == 0  # zero: nothing to cross


def test_regions_plain_and_periodic():
    xs, n = np.array([1.0, 2.0, 3.0]), 3
    ys = np.array([0.0, 2.0, 0.0])
    assert region_of(xs, n, 0.0, 0.5, 1.0) == (0, 0.0)
    assert region_of(xs, n, 0.0, 2.5, 1.0) == (2, 0.0)
    assert region_of(xs, n, 0.0, 2.0, 1.0) == (2, 0.0)  # at a point: the side moved to
    assert region_of(xs, n, 0.0, 2.0, -1.0) == (1, 0.0)
    assert region_of(xs, n, 0.0, 9.0, 1.0) == (3, 0.0)
    assert region_bounds(xs, n, 0.0, 2, 0.0) == (2.0, 3.0)
    assert region_bounds(xs, n, 0.0, 0, 0.0) == (-math.inf, 1.0)
    # a held piece is extended past its ends
    assert region_value(xs, ys, n, 0.0, 1, 0.0, 2.5, False, 0.0) == pytest.approx(3.0)
    assert region_value(xs, ys, n, 0.0, 3, 0.0, 2.5, True, -1.0) == -1.0
    # periodic (period 5): 12.5 = 2.5 + 2 periods; 11.0 is the start of a period
    assert region_of(xs, n, 5.0, 12.5, 1.0) == (2, 2.0)
    assert region_of(xs, n, 5.0, 11.0, 1.0) == (1, 2.0)
    assert region_of(xs, n, 5.0, 11.0, -1.0) == (3, 1.0)  # below it: the last piece before
    assert region_bounds(xs, n, 5.0, 3, 1.0) == (8.0, 11.0)
    assert region_value(xs, ys, n, 5.0, 1, 2.0, 11.5, False, 0.0) == pytest.approx(1.0)


@needs_numba
def test_energy_of_a_hardening_table_spring_through_its_knees():
    mech = _slider(Table(XS, YS, "s"))
    v0 = 2.0  # m/s: 10 swings to +-40 mm a second, through 4 knees each
    tr = simulate(mech, 3.0, q0=[0.0], qdot0=[v0], rtol=1e-12, dt_out=1e-3, progress=False)
    assert tr.success, tr.message
    s, v = tr.q[:, 0], tr.qdot[:, 0]
    assert np.max(np.abs(s)) > 0.035  # well into the stiff part (about 40 mm)
    assert np.sum(np.diff(np.sign(np.abs(s) - 0.02)) != 0) >= 110
    energy = 0.5 * MASS * v ** 2 + np.array([_potential(x) for x in s])
    e0 = 0.5 * MASS * v0 ** 2
    # (6.9e-10 with steps across the knees: the error estimate lets them pass)
    assert np.max(np.abs(energy - e0)) / e0 < 1e-10


def _spin_up(j, t):
    """Closed form of J w' = M(w) - 2 N m, M = 10 N m up to 10 rad/s, then falling to 0 at
    20 rad/s: w = 8 t / J up to t1 = 10 J / 8, then 18 - 8 exp(-(t - t1) / J)."""
    t1 = 10.0 * j / 8.0
    if t <= t1:
        return 4.0 * t * t / j, 8.0 * t / j
    tau = t - t1
    return 4.0 * t1 * t1 / j + 18.0 * tau - 8.0 * j * (1.0 - math.exp(-tau / j)), \
        18.0 - 8.0 * math.exp(-tau / j)


@needs_numba
def test_spin_up_through_the_knee_of_a_torque_speed_table():
    j = 0.1
    mech = Mechanism("disc", gravity=(0.0, 0.0))
    mech.add_body("disc", mass=1.0, inertia=j, com=(0.0, 0.0))
    mech.add_revolute("O", "ground", "disc")
    mech.add_coordinate("phi", kind="relative_angle", joint="O")
    mech.add(Drive("motor", "phi", TorqueSpeedCurve((0.0, 10.0, 20.0), (10.0, 10.0, 0.0))))
    mech.add(Torque("load", "disc", magnitude=-2.0))
    ends = {}
    for rtol in (1e-8, 1e-10, 1e-12):
        tr = simulate(mech, 0.6, q0=[0.0], qdot0=[0.0], rtol=rtol, t_eval=[0.6],
                      progress=False)
        ends[rtol] = (tr.q[-1, 0], tr.qdot[-1, 0])
    phi, w = _spin_up(j, 0.6)
    for rtol, (p, v) in ends.items():
        assert p == pytest.approx(phi, rel=100 * rtol) and v == pytest.approx(w, rel=100 * rtol)


@needs_numba
def test_a_force_ramp_over_time_against_its_closed_form():
    # F = 0 until 0.1 s, rises to 10 N at 0.15 s, then held: x(t) piecewise polynomial
    t1, t2, f0 = 0.1, 0.15, 10.0
    mech = _slider(Table([t1, t2], [0.0, f0], "t"))
    tr = simulate(mech, 0.3, q0=[0.0], qdot0=[0.0], rtol=1e-10, t_eval=[0.3],
                  progress=False)
    rate = f0 / (t2 - t1) / MASS  # jerk on the ramp
    a2 = f0 / MASS
    x2 = rate * (t2 - t1) ** 3 / 6.0
    v2 = rate * (t2 - t1) ** 2 / 2.0
    d = 0.3 - t2
    assert tr.q[-1, 0] == pytest.approx(x2 + v2 * d + 0.5 * a2 * d * d, rel=1e-10)
    assert tr.qdot[-1, 0] == pytest.approx(v2 + a2 * d, rel=1e-10)


@needs_numba
def test_press_cycle_events_converge_with_rtol():
    # the ram springs, the cylinder's ramps over phi (periodic), the punch, the return
    # cylinder and the motor curve are tables; with steps across their points an event
    # at 0.107 s of this run was 5e-9 s off at rtol 1e-10 (1e-11 at rtol 1e-11)
    from mechdyn.examples import load

    press = load("press_cycle").compile()
    runs = {r: simulate(press, 0.95, rtol=r, atol=1e-3 * r, progress=False)
            for r in (1e-10, 1e-12)}
    coarse, fine = runs[1e-10], runs[1e-12]
    assert [(e.kind, e.element) for e in coarse.events] == \
        [(e.kind, e.element) for e in fine.events]
    np.testing.assert_allclose([e.t for e in coarse.events], [e.t for e in fine.events],
                               rtol=0, atol=2e-10)


@needs_numba
def test_a_variable_held_at_a_point_stays_on_its_piece():
    # the ram of the press sits at its upper stop, 28 mm, which is also the last point of
    # its spring table: round-off around the point must not flip the held piece
    from mechdyn.dynamics.mode_equations import ModeEquations
    from mechdyn.dynamics.mode_system import ModeSystem
    from mechdyn.kernels.held_tables import hold, left
    from mechdyn.model.switchable import switched_model
    from mechdyn.model.workspace import Workspace

    model = _slider(Table([0.02, 0.022, 0.028], [0.0, 68.8e3, 70e3], "s")).compile()
    sm = switched_model(model)
    ms = ModeSystem(sm, frozenset(), {}, np.zeros(model.n_x), workspace=Workspace())
    ip, fp = ModeEquations(sm, ms, "numba").kernel._arrays[:2]
    locks = np.array([4.0, 0.0])  # above the last point (region 3 + 1)
    at = np.array([0.028])
    assert left(ip, fp, at, at - 4e-18, locks)[0] == 2.0  # still on it
    th, j, c = left(ip, fp, at, np.array([0.0279]), locks)  # down into the table
    assert (th, j, c) == (0.0, 0, 0.028)
    hold(ip, fp, at, np.array([0.0279]), locks, True, 0)
    assert locks.tolist() == [3.0, 0.0]  # the piece from 22 to 28 mm
    th, j, c = left(ip, fp, np.array([0.0279]), np.array([0.0215]), locks)
    assert j == 0 and c == 0.022 and th == pytest.approx(0.0059 / 0.0064)
