"""Forward and inverse dynamics agree: a motion computed under a known torque, fed
back into kinetostatics, gives that torque back."""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mechdyn as md
from mechdyn.kinetostatics.inverse import kinetostatics
from mechdyn.mechanism import Drive

M, JC, S = 2.0, 0.01, np.array([0.10, 0.03])  # kg, kg m^2, COM in the crank frame (m)
G = np.array([0.0, -9.81])


def applied_torque(t):
    return 3.0 * np.sin(5.0 * t) + 0.5


def pendulum() -> md.Mechanism:
    m = md.Mechanism("compound pendulum", gravity=tuple(G))
    m.add_body("crank", mass=M, inertia=JC, com=tuple(S), pose=(0.0, 0.0, 0.4))
    m.add_revolute("O", "ground", "crank")
    m.add_coordinate("phi", "angle", body="crank")
    m.add(Drive("motor", "phi", lambda ctx: applied_torque(ctx.t)))
    return m


def pendulum_rhs(t, y):
    """Independent forward model: J_O phi'' = T(t) + (r_c x m g), J_O = J_c + m |s|^2."""
    phi, w = y
    c, s = np.cos(phi), np.sin(phi)
    rc = np.array([c * S[0] - s * S[1], s * S[0] + c * S[1]])
    jo = JC + M * (S @ S)
    return [w, (applied_torque(t) + M * (rc[0] * G[1] - rc[1] * G[0])) / jo]


def test_inverse_of_an_independently_integrated_pendulum_recovers_the_torque():
    t = np.linspace(0.0, 2.0, 401)
    sol = solve_ivp(pendulum_rhs, (0.0, 2.0), [0.4, 0.0], t_eval=t, rtol=1e-12, atol=1e-12,
                    method="DOP853")
    qdd = np.array([pendulum_rhs(tk, yk)[1] for tk, yk in zip(t, sol.y.T, strict=True)])
    traj = SimpleNamespace(t=t, q=sol.y[0][:, None], qdot=sol.y[1][:, None],
                           qddot=qdd[:, None])
    res = kinetostatics(pendulum(), trajectory=traj)
    np.testing.assert_allclose(res.driving["phi"], applied_torque(t), rtol=0, atol=1e-10)
    # the model's own drive as a known load: nothing else is needed
    res2 = kinetostatics(pendulum(), trajectory=traj, model_drives="load")
    np.testing.assert_allclose(res2.driving["phi"], 0.0, atol=1e-10)
    assert "replaced" in res.message


def test_accelerations_from_differentiated_samples_agree_to_integration_accuracy():
    """With qddot taken by finite differences of the integrated rates, the torque agrees
    to the accuracy of the differences (second order in the sample step)."""
    errs = []
    for n in (201, 401):
        t = np.linspace(0.0, 1.0, n)
        sol = solve_ivp(pendulum_rhs, (0.0, 1.0), [0.4, 0.0], t_eval=t, rtol=1e-12,
                        atol=1e-12, method="DOP853")
        qdd = np.gradient(sol.y[1], t, edge_order=2)
        traj = SimpleNamespace(t=t, q=sol.y[0][:, None], qdot=sol.y[1][:, None],
                               qddot=qdd[:, None])
        res = kinetostatics(pendulum(), trajectory=traj)
        errs.append(np.max(np.abs(res.driving["phi"] - applied_torque(t))))
    assert errs[1] < 1e-3 * 3.5  # 0.1 % of the peak torque
    assert 3.0 < errs[0] / errs[1] < 5.0  # halving the step divides the error by ~4


def test_speed_law_and_angle_law_give_the_same_torque():
    def law(t):
        return 0.4 + 2.0 * t + t**2, 2.0 + 2.0 * t, 2.0

    t = np.linspace(0.0, 1.0, 51)
    exact = kinetostatics(pendulum(), over="phi", t=t, law=law)
    by_speed = kinetostatics(pendulum(), over="phi", t=t, speed=lambda s: 2.0 + 2.0 * s,
                             start=0.4)
    by_angle = kinetostatics(pendulum(), over="phi", t=t,
                             law=lambda s: 0.4 + 2.0 * s + s**2)
    np.testing.assert_allclose(by_speed.q, exact.q, atol=1e-12)
    np.testing.assert_allclose(by_speed.qddot, exact.qddot, atol=1e-7)
    np.testing.assert_allclose(by_speed.driving["phi"], exact.driving["phi"], atol=1e-8)
    np.testing.assert_allclose(by_angle.driving["phi"], exact.driving["phi"], atol=1e-8)


def test_mechdyn_simulate_trajectory_fed_back_recovers_the_motor_torque():
    simulate = pytest.importorskip("mechdyn.simulate").simulate
    examples = pytest.importorskip("mechdyn.examples")
    from mechdyn.modelfile import load

    mech = load(examples.path("slider_crank"))
    model = mech.compile()
    traj = simulate(model, 0.03, rtol=1e-10, t_eval=np.linspace(0.0, 0.03, 61))
    assert traj.success, traj.message
    res = kinetostatics(model, trajectory=traj)
    motor = mech.drives[0].torque
    expected = np.array([motor(w) for w in traj.qdot[:, 0]])
    np.testing.assert_allclose(res.driving["phi"], expected, rtol=0,
                               atol=1e-8 * np.max(np.abs(expected)))
    # positions agree with the simulation's own poses
    np.testing.assert_allclose(res.x, traj.x, atol=1e-9)


def test_free_two_dof_motion_needs_no_driving_torques():
    """The clutchless press (2 DOF, no drives) swinging freely under gravity: inverse
    dynamics of the simulated motion finds zero torque on both coordinates."""
    simulate = pytest.importorskip("mechdyn.simulate").simulate
    examples = pytest.importorskip("mechdyn.examples")

    model = examples.load("clutchless_press").compile()
    traj = simulate(model, 0.02, rtol=1e-10, t_eval=np.linspace(0.0, 0.02, 41))
    assert traj.success, traj.message
    res = kinetostatics(model, trajectory=traj)
    assert res.driven == ("phi", "psi")
    # reference scale: the inertia forces involved (crank torque of a few hundred N m)
    scale = np.max(np.abs(res.reactions["O"])) * 0.015
    for c in ("phi", "psi"):
        assert np.max(np.abs(res.driving[c])) < 1e-9 * scale
