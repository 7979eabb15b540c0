"""A parallelogram four-bar through its flat (bifurcation) positions, against its 1-DOF
equation of motion.

The mechanism (``dynamics_models.parallelogram``): ground pivots O = (0, 0) and
C = (l, 0), crank, coupler and rocker of length l, uniform rods of mass m, gravity
-g along y, coordinate phi = the crank angle.  Twice per turn (phi = 0, pi) all
bars lie on the ground line: [Phi_x; g_x] is singular there, the parallelogram
branch crosses another assembly branch, but the motion stays determined.

The oracle.  Staying on the parallelogram branch, the rocker turns with the crank
(both by phi) and the coupler translates with the crank tip (velocity l phi').
Kinetic energy:

    T = 1/2 (m l^2 / 3) phi'^2          crank about O
      + 1/2 (m l^2 / 3) phi'^2          rocker about C
      + 1/2 m (l phi')^2                coupler, translating
      = 1/2 (2 m l^2 / 3 + m l^2) phi'^2 = 1/2 (5/3) phi'^2      (m = l = 1)

Potential energy (centres of mass of crank and rocker at height (l/2) sin phi, of
the coupler at l sin phi):

    U = m g (l/2) sin phi * 2 + m g l sin phi = 2 g sin phi      (m = l = 1)

The generalized mass is constant, so Lagrange's equation has no velocity term:

    (5/3) phi'' = -dU/dphi = -2 g cos phi,

a pendulum-like 1-DOF equation, integrated with SciPy at rtol 1e-13 for the
reference.  At constant crank speed phi'' = 0 and the drive must balance gravity
alone: by the power balance M phi' = dU/dt = 2 g cos(phi) phi', so the driving torque
(positive in the sense of phi, docs/kinetostatics.md) is M = 2 g cos phi.  With a
constant torque tau on the crank, (5/3) phi'' = -2 g cos phi + tau.

Wall times (2-core machine, shared) of the 10 s runs are printed with ``-s``, not
asserted.
"""

import numpy as np
import pytest
from dynamics_models import parallelogram
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from mechdyn.dynamics.lagrange import BranchEquations
from mechdyn.kinematics.sweep import sweep
from mechdyn.kinetostatics.inverse import KinetostaticsWarning, kinetostatics
from mechdyn.mechanism import Drive
from mechdyn.model import as_model
from mechdyn.simulate.run import simulate

G = 9.81
PHI0, W0 = np.pi / 2, -1.0  # started vertical, turning clockwise at 1 rad/s


def oracle(t_end=10.0, tau=0.0):
    """(5/3) phi'' = -2 g cos phi + tau from (PHI0, W0), rtol 1e-13, dense output."""
    return solve_ivp(lambda t, y: [y[1], (-2 * G * np.cos(y[0]) + tau) / (5 / 3)],
                     (0.0, t_end), [PHI0, W0], method="DOP853", rtol=1e-13, atol=1e-14,
                     dense_output=True)


def oracle_acceleration(phi, tau=0.0):
    return (-2 * G * np.cos(phi) + tau) / (5 / 3)


@pytest.fixture(scope="module")
def reference():
    return oracle()


def test_end_position_error_falls_with_the_tolerance(reference):
    phi_end = reference.y[0, -1]
    errors = []
    for rtol in (1e-8, 1e-10, 1e-12):
        tr = simulate(parallelogram(), 10.0, rtol=rtol, qdot0=[W0], progress=False)
        assert tr.status == "success", tr.message
        err = abs(tr.q[-1, 0] - phi_end)
        errors.append(err)
        print(f"rtol {rtol:.0e}: end-position error {err:.3e} rad, wall time "
              f"{tr.stats['wall_time_s']:.3f} s, {tr.stats['steps']} steps, "
              f"{len(tr.stats['bifurcations'])} flat positions charted")
        # about five turns, two flat positions each, all gone through on the branch
        assert len(tr.stats["bifurcations"]) >= 9
        assert {b["kind"] for b in tr.stats["bifurcations"]} == {"bifurcation"}
        # continuity kept the parallelogram: the rocker turns with the crank
        th = tr.x[:, 2::3]
        assert np.max(np.abs(th[:, 2] - th[:, 0])) < 1e-9
        assert np.max(np.abs(th[:, 1])) < 1e-9  # the coupler translates
    assert errors[0] > 10 * errors[1] > 100 * errors[2]
    assert errors[2] < 1e-9


def test_output_times_do_not_change_the_run(reference):
    a = simulate(parallelogram(), 10.0, rtol=1e-11, qdot0=[W0], progress=False)
    te = np.linspace(0.0, 10.0, 777)
    b = simulate(parallelogram(), 10.0, rtol=1e-11, qdot0=[W0], progress=False, t_eval=te)
    assert b.status == "success"
    # what is left is round-off of the Newton solves, below the integrator's error
    assert abs(a.q[-1, 0] - b.q[-1, 0]) < 1e-9
    assert np.max(np.abs(b.q[:, 0] - reference.sol(te)[0])) < 1e-8


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("tau", [0.0, 3.0], ids=["gravity", "crank-torque"])
def test_acceleration_near_the_flat_position(backend, tau):
    mech = parallelogram()
    if tau:
        mech.add(Drive("motor", "phi", tau))
    eom = BranchEquations(as_model(mech), backend=backend)
    eom.qddot(0.0, [0.6], [W0])  # coming from the vertical side
    for d in (1e-7, -1e-7, 1e-5, 0.0, 0.05):
        a = eom.qddot(0.0, [d], [W0])[0]
        assert abs(a - oracle_acceleration(d, tau)) < 1e-11 * abs(a), (d, a)
    # the other flat position, reached across the first one
    for q in (-1.0, -2.0, -np.pi + 1e-7, -np.pi):
        a = eom.qddot(0.0, [q], [W0])[0]
        assert abs(a - oracle_acceleration(q, tau)) < 1e-11 * 2 * G, (q, a)


def test_recorded_acceleration_at_1e_7_rad_from_the_flat_position(reference):
    # the first flat position: phi = 0 while turning clockwise
    t_star = brentq(lambda t: reference.sol(t)[0], 0.0, 1.0, xtol=1e-15)
    t_d = t_star - 1e-7 / abs(reference.sol(t_star)[1])  # phi = +1e-7 there
    tr = simulate(parallelogram(), t_d + 0.05, rtol=1e-12, qdot0=[W0], progress=False,
                  t_eval=[t_d])
    assert tr.status == "success"
    phi, acc = tr.q[0, 0], tr.qddot[0, 0]
    assert abs(phi - 1e-7) < 1e-10
    print(f"phi = {phi:.6e} rad: crank acceleration error "
          f"{abs(acc - oracle_acceleration(phi)):.2e} rad/s^2")
    assert abs(acc - oracle_acceleration(phi)) < 1e-11 * abs(acc)


def test_sweep_over_a_full_turn_stays_on_the_parallelogram():
    values = np.linspace(0.0, 2 * np.pi, 361)  # both flat positions, hit exactly
    sw = sweep(parallelogram(), values=values)
    assert sw.status == "success" and len(sw) == 361
    crank, coupler, rocker = sw.angular("crank")[0], sw.angular("coupler")[0], \
        sw.angular("rocker")[0]
    assert np.max(np.abs(rocker - crank)) < 1e-9
    assert np.max(np.abs(coupler)) < 1e-9
    # analogs at the flat positions: the limit from the sides
    assert np.max(np.abs(sw.B[:, 8, 0] - 1.0)) < 1e-9
    assert np.max(np.abs(sw.xddot[:, 8])) < 1e-9
    assert {b["kind"] for b in sw.stats["bifurcations"]} == {"bifurcation"}


@pytest.mark.parametrize("speed", [2.0, -1.5])
def test_kinetostatics_driving_torque_balances_gravity(speed):
    values = np.linspace(0.0, 2 * np.pi, 361) * np.sign(speed)
    with pytest.warns(KinetostaticsWarning, match="bifurcation position"):
        res = kinetostatics(parallelogram(), over="phi", speed=speed, values=values)
    th = res.x[:, 2::3]
    assert np.max(np.abs(th[:, 2] - th[:, 0])) < 1e-9
    M = res.driving["phi"]
    assert np.max(np.abs(M - 2 * G * np.cos(values))) < 1e-9
    assert res.stats["power_balance_rel"] < 1e-9
    assert "bifurcation" in res.message


@pytest.mark.parametrize(("start_deg", "stop_deg", "step_deg"), [(90.0, 450.0, 1.0),
                                                                 (170.0, 190.0, 0.01)])
def test_a_sweep_never_leaves_the_parallelogram_branch_silently(start_deg, stop_deg, step_deg):
    """The reproducers of the fuzzing campaign: a full turn in 1 deg steps used to leave the
    parallelogram branch at 181 deg, and 0.01 deg steps near 180 deg at 180.7 deg with
    status success. Continuity keeps the branch: the rocker turns with the crank."""
    from mechdyn.kinematics.sweep import sweep

    values = np.deg2rad(np.arange(start_deg, stop_deg + step_deg / 2, step_deg))
    sw = sweep(parallelogram().compile(), values=values)
    assert sw.status == "success" and len(sw) == values.size
    th = sw.x[:, 2::3]
    assert np.max(np.abs(np.angle(np.exp(1j * (th[:, 2] - th[:, 0]))))) < 1e-9
    assert {b["kind"] for b in sw.stats["bifurcations"]} == {"bifurcation"}
