"""Kinetostatics checked by balances that do not use its own formulation:

* power: driving power = dT/dt - power of the applied loads, with T from the
  centre-of-mass velocities and the loads evaluated by ``ForceModel.applied``
  (the scalar evaluator of the forward dynamics);
* Newton-Euler for every body with the reported reactions (+R on the child,
  -R on the parent, moments about the centre of mass);
* the whole machine: what the frame receives = external loads - sum of m a_c,
  and the same for moments about the chosen point.
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.kinetostatics.inverse import applied_forces, kinetostatics
from mechdyn.mechanism import Force, RotarySpring, Spring, Table, Torque
from mechdyn.mechanism.process import punch_load
from mechdyn.model.constraints import point_acceleration, point_position, point_velocity
from mechdyn.model.forces import force_model


def _circle(P, rP, Q, rQ, sign):
    d = Q - P
    L = np.hypot(*d)
    a = (rP**2 - rQ**2 + L**2) / (2 * L)
    h = np.sqrt(rP**2 - a**2)
    e = d / L
    return P + a * e + sign * h * np.array([-e[1], e[0]])


def six_bar(loads: bool = True) -> md.Mechanism:
    """A triangular-toggle six-bar press (crank AB, toggle BDE, link CD on the frame,
    link EF, slider F on a vertical guide), dimensions in m, kg, kg m^2."""
    C = np.array([0.30, 0.05])
    x_f, r1, l_bd, l_cd, l_ef, s_e = 0.22, 0.06, 0.30, 0.16, 0.28, (0.22, -0.10)
    phi0 = np.deg2rad(30.0)
    B = r1 * np.array([np.cos(phi0), np.sin(phi0)])
    D = _circle(B, l_bd, C, l_cd, -1)
    u = (D - B) / l_bd
    E = B + s_e[0] * u + s_e[1] * np.array([-u[1], u[0]])
    F = np.array([x_f, E[1] - np.sqrt(l_ef**2 - (x_f - E[0]) ** 2)])
    m = md.Mechanism("six-bar toggle press", gravity=(0.0, -9.81))
    m.add_ground({"A": (0.0, 0.0), "C": tuple(C), "slide": (x_f, 0.0), "S": (0.40, 0.20)})
    m.add_body("crank", mass=3.0, inertia=0.004, com=(0.02, 0.005), points={"B": (r1, 0.0)},
               pose=(0.0, 0.0, phi0))
    m.add_body("toggle", mass=8.0, inertia=0.06, com=(0.15, -0.03),
               points={"B": (0.0, 0.0), "D": (l_bd, 0.0), "E": s_e},
               pose=(*B, np.arctan2(u[1], u[0])))
    m.add_body("link_cd", mass=2.5, inertia=0.006, com=(l_cd / 2, 0.01), points={"D": (l_cd, 0.0)},
               pose=(*C, np.arctan2(*(D - C)[::-1])))
    m.add_body("link_ef", mass=3.0, inertia=0.02, com=(l_ef / 2, 0.0), points={"F": (l_ef, 0.0)},
               pose=(*E, np.arctan2(*(F - E)[::-1])))
    m.add_body("slider", mass=20.0, inertia=0.1, com=(0.01, -0.05), points={"F": (0.0, 0.0)},
               pose=(*F, 0.0))
    m.add_revolute("A", "ground", "crank", "A", (0.0, 0.0))
    m.add_revolute("B", "crank", "toggle", "B", "B")
    m.add_revolute("C", "ground", "link_cd", "C", (0.0, 0.0))
    m.add_revolute("D", "link_cd", "toggle", "D", "D")
    m.add_revolute("E", "toggle", "link_ef", "E", (0.0, 0.0))
    m.add_revolute("F", "link_ef", "slider", "F", "F")
    m.add_prismatic("guide", "ground", "slider", "slide", (0.0, 1.0), "F")
    m.add_coordinate("phi", "angle", body="crank")
    if loads:
        m.add(Spring("balancer", "ground", "S", "slider", "F", stiffness=2000.0,
                     free_length=0.5, damping=15.0, preload=50.0))
        m.add(Spring("tie", "toggle", "E", "link_cd", (0.05, 0.0), stiffness=800.0,
                     free_length=0.1, damping=3.0))
        m.add(RotarySpring("c_spring", "C", stiffness=20.0, free_angle=-1.0, damping=0.5))
        m.add(Torque("friction", "toggle", Table((0.0, 0.5, 1.0), (1.0, -2.0, 0.5), "t"),
                     reaction_body="crank"))
        m.add(Force("wind", "link_ef", (0.1, 0.02), 30.0, (0.0, 1.0), frame="body"))
        m.add(punch_load("punch", "slider", "F", 4000.0, end=-0.4748225, travel=0.003))
        m.add(Force("cushion", "slider", "F",
                    Table((-0.48, -0.45), (800.0, 0.0), "slider.F.y", outside=0.0), (0.0, 1.0)))
    return m


def motion_law(t):
    """phi(t) with exact derivatives: a crank that speeds up and wobbles."""
    w0, a0, amp, om = 6.0, 4.0, 0.3, 9.0
    q = w0 * t + 0.5 * a0 * t**2 + amp * np.sin(om * t)
    qd = w0 + a0 * t + amp * om * np.cos(om * t)
    qdd = a0 - amp * om**2 * np.sin(om * t)
    return q, qd, qdd


@pytest.fixture(scope="module")
def six_bar_result():
    model = six_bar().compile()
    t = np.linspace(0.0, 1.0, 401)
    res = kinetostatics(model, over="phi", t=t, law=motion_law, point=(0.1, -0.2))
    return model, res


def _kinetic_rate(model, res):
    """dT/dt = sum m v_c . a_c + J omega alpha, from point kinematics."""
    out = np.zeros(res.n)
    for k, b in enumerate(model.body_names):
        vc = point_velocity(model, res.x, res.xdot, b, "com")
        ac = point_acceleration(model, res.x, res.xdot, res.xddot, b, "com")
        out += model.mass[k] * np.sum(vc * ac, axis=-1)
        out += model.inertia[k] * res.xdot[:, 3 * k + 2] * res.xddot[:, 3 * k + 2]
    return out


def test_driving_power_balances_kinetic_energy_rate_and_load_power(six_bar_result):
    model, res = six_bar_result
    fm = force_model(model)
    p_loads = np.array([fm.applied(res.t[k], res.x[k], res.xdot[k], res.q[k], res.qdot[k])[0]
                        @ res.xdot[k] for k in range(res.n)])
    dTdt = _kinetic_rate(model, res)
    p_drive = res.power["phi"]
    scale = np.max(np.abs(dTdt)) + np.max(np.abs(p_loads))
    err = np.max(np.abs(p_drive - (dTdt - p_loads))) / scale
    assert err < 1e-9, err
    assert res.stats["power_balance_rel"] < 1e-9
    # the punch acted in this run (the balance covers its jumps)
    punch = next(ld for ld in model.mechanism.loads if ld.name == "punch").magnitude
    yF = point_position(model, res.x, "slider", "F")[:, 1]
    vF = point_velocity(model, res.x, res.xdot, "slider", "F")[:, 1]
    assert 0 < np.count_nonzero(punch.factor(yF, vF)) < res.n


def test_newton_euler_holds_for_every_body(six_bar_result):
    model, res = six_bar_result
    fm = force_model(model)
    nb = model.n_bodies
    force = np.zeros((res.n, nb, 2))
    moment = np.zeros((res.n, nb))  # about each body's centre of mass
    rc = np.stack([point_position(model, res.x, b, "com") for b in model.body_names], axis=1)
    # applied loads, from the forward-dynamics evaluator (force, moment about frame origin)
    for k in range(res.n):
        F, _ = fm.applied(res.t[k], res.x[k], res.xdot[k], res.q[k], res.qdot[k])
        Fb = F.reshape(nb, 3)
        arm = rc[k] - res.x[k].reshape(nb, 3)[:, :2]
        force[k] += Fb[:, :2]
        moment[k] += Fb[:, 2] - (arm[:, 0] * Fb[:, 1] - arm[:, 1] * Fb[:, 0])
    # reactions: +R on the child, -R on the parent, at the joint point
    for j, R in res.reactions.items():
        jt = model.mechanism.joints[j]
        P = res.joint_points[j]
        M = res.moments[j]
        for body, sgn in ((jt.child, 1.0), (jt.parent, -1.0)):
            if body == "ground":
                continue
            b = model.body_index(body)
            d = P - rc[:, b]
            force[:, b] += sgn * R
            moment[:, b] += sgn * (M + d[:, 0] * R[:, 1] - d[:, 1] * R[:, 0])
    # the drive torque acts on the crank (absolute angle coordinate)
    moment[:, model.body_index("crank")] += res.driving["phi"]
    for k, b in enumerate(model.body_names):
        ac = point_acceleration(model, res.x, res.xdot, res.xddot, b, "com")
        alpha = res.xddot[:, 3 * k + 2]
        scale = max(max(np.max(np.abs(R)) for R in res.reactions.values()), 1.0)
        assert np.max(np.abs(force[:, k] - model.mass[k] * ac)) < 1e-9 * scale, b
        assert np.max(np.abs(moment[:, k] - model.inertia[k] * alpha)) < 1e-9 * scale * 0.3, b


def test_frame_receives_external_loads_minus_inertia(six_bar_result):
    model, res = six_bar_result
    O = np.array([0.1, -0.2])
    ext_f = np.zeros((res.n, 2))
    ext_m = np.zeros(res.n)
    g = model.gravity
    for k, b in enumerate(model.body_names):
        rc = point_position(model, res.x, b, "com") - O
        ac = point_acceleration(model, res.x, res.xdot, res.xddot, b, "com")
        f = model.mass[k] * (g - ac)
        ext_f += f
        ext_m += (rc[:, 0] * f[:, 1] - rc[:, 1] * f[:, 0]
                  - model.inertia[k] * res.xddot[:, 3 * k + 2])
    # Force loads (external, not carried by the frame here)
    from mechdyn.model.forces import LoadContext, evaluate

    for ld in model.mechanism.loads:
        if not isinstance(ld, Force):
            continue
        for k in range(res.n):
            ctx = LoadContext(model, res.t[k], res.q[k], res.qdot[k], res.x[k], res.xdot[k])
            mag = evaluate(ld.magnitude, ctx)
            d = np.asarray(ld.direction)
            th = res.x[k, 3 * model.body_index(ld.body) + 2]
            if ld.frame == "body":
                d = np.array([np.cos(th) * d[0] - np.sin(th) * d[1],
                              np.sin(th) * d[0] + np.cos(th) * d[1]])
            p = point_position(model, res.x[k], ld.body, ld.point) - O
            ext_f[k] += mag * d
            ext_m[k] += p[0] * mag * d[1] - p[1] * mag * d[0]
    scale = np.max(np.abs(ext_f))
    np.testing.assert_allclose(res.frame_force, ext_f, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(res.frame_moment, ext_m, rtol=0, atol=1e-9 * scale)
    # the frame loads are the sum of their parts
    tot = sum(res.frame_loads.values())
    np.testing.assert_allclose(tot[:, :2], res.frame_force, atol=1e-12 * scale)


def test_batched_loads_equal_the_forward_dynamics_evaluator(six_bar_result):
    model, res = six_bar_result
    fm = force_model(model)
    F, ground, Qd = applied_forces(model, res.t, res.x, res.xdot, res.q, res.qdot)
    ref = np.array([fm.applied(res.t[k], res.x[k], res.xdot[k], res.q[k], res.qdot[k])[0]
                    for k in range(res.n)])
    np.testing.assert_allclose(F, ref, rtol=1e-13, atol=1e-10)
    assert not np.any(Qd)


def test_constant_speed_cycle_has_zero_mean_drive_work_without_dissipation():
    """Over a closed cycle at constant speed, gravity and springs return their work."""
    m = six_bar(loads=False)
    m.add(Spring("balancer", "ground", "S", "slider", "F", stiffness=2000.0, free_length=0.5))
    res = kinetostatics(m, over="phi", speed=2 * np.pi, values=np.linspace(0, 2 * np.pi, 721))
    work = np.trapezoid(res.power["phi"], res.t)
    assert abs(work) < 1e-5 * np.max(np.abs(res.power["phi"])) * res.t[-1]
