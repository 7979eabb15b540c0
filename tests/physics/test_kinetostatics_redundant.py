"""Redundant constraints: detected, named, and reported with the minimum-norm
reactions and a warning; driving torques stay unique and exact."""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.kinetostatics.inverse import KinetostaticsWarning, kinetostatics

G = 9.81


def door(two_hinges: bool = True) -> md.Mechanism:
    """A door turning about a vertical axis, seen in the plane: one or two coaxial hinges."""
    m = md.Mechanism("door", gravity=(0.0, -G))
    m.add_body("door", mass=30.0, inertia=2.5, com=(0.4, 0.0), pose=(0.0, 0.0, 0.3))
    m.add_revolute("hinge_top", "ground", "door")
    if two_hinges:
        m.add_revolute("hinge_bottom", "ground", "door")
    m.add_coordinate("theta", "angle", body="door")
    return m


def test_door_with_two_hinges_warns_and_splits_the_load_evenly():
    th = np.linspace(-1.0, 1.0, 21)
    with pytest.warns(KinetostaticsWarning, match="not unique"):
        res = kinetostatics(door(), over="theta", speed=0.0, values=th)
    assert res.status == "redundant"
    assert set(res.redundant_joints) == {"hinge_top", "hinge_bottom"}
    assert any("hinge_top" in w and "hinge_bottom" in w and "minimum-norm" in w
               for w in res.warnings)
    assert res.stats["redundant_equations"] == 2
    # the holding torque is unique: m g x_c
    np.testing.assert_allclose(res.driving["theta"], 30.0 * G * 0.4 * np.cos(th), rtol=1e-12)
    # the total hinge force carries the weight; minimum norm shares it half and half
    tot = res.reactions["hinge_top"] + res.reactions["hinge_bottom"]
    np.testing.assert_allclose(tot, np.broadcast_to([0.0, 30.0 * G], tot.shape), atol=1e-9)
    np.testing.assert_allclose(res.reactions["hinge_top"], res.reactions["hinge_bottom"],
                               atol=1e-9)
    # one hinge: the same torque, the whole load on it, no warning
    one = kinetostatics(door(False), over="theta", speed=0.0, values=th)
    assert one.status == "success" and not one.warnings
    np.testing.assert_allclose(one.driving["theta"], res.driving["theta"], rtol=1e-12)
    np.testing.assert_allclose(one.reactions["hinge_top"], tot, atol=1e-9)


A, D = 0.12, 0.40  # crank/rocker length and ground length of the parallelogram, m


def parallelogram(third: bool) -> md.Mechanism:
    phi0 = 0.7
    m = md.Mechanism("parallelogram", gravity=(0.0, -G))
    m.add_ground({"O1": (0.0, 0.0), "O2": (D, 0.0), "O3": (D / 2, 0.0)})
    ca = A * np.array([np.cos(phi0), np.sin(phi0)])
    m.add_body("crank", mass=1.0, inertia=0.002, com=(0.06, 0.0), points={"A": (A, 0.0)},
               pose=(0.0, 0.0, phi0))
    m.add_body("coupler", mass=3.0, inertia=0.05, com=(D / 2, 0.02),
               points={"A": (0.0, 0.0), "B": (D, 0.0), "C": (D / 2, 0.0)}, pose=(*ca, 0.0))
    m.add_body("rocker", mass=1.0, inertia=0.002, com=(0.06, 0.0), points={"B": (A, 0.0)},
               pose=(D, 0.0, phi0))
    m.add_revolute("O1", "ground", "crank", "O1", (0.0, 0.0))
    m.add_revolute("A", "crank", "coupler", "A", "A")
    m.add_revolute("B", "coupler", "rocker", "B", "B")
    m.add_revolute("O2", "ground", "rocker", "O2", (0.0, 0.0))
    if third:
        m.add_body("third", mass=0.8, inertia=0.0015, com=(0.06, 0.0), points={"C": (A, 0.0)},
                   pose=(D / 2, 0.0, phi0))
        m.add_revolute("O3", "ground", "third", "O3", (0.0, 0.0))
        m.add_revolute("C", "coupler", "third", "C", "C")
    m.add_coordinate("phi", "angle", body="crank")
    return m


def test_parallelogram_with_redundant_third_link():
    # (phi = 0 and pi are change points where all links lie on the ground line)
    values = np.linspace(0.2, np.pi - 0.2, 41)
    with pytest.warns(KinetostaticsWarning):
        res = kinetostatics(parallelogram(True), over="phi", speed=5.0, values=values)
    assert res.status == "redundant"
    assert res.stats["redundant_equations"] == 1
    assert {"O3", "C"} <= set(res.redundant_joints)
    # the coupler translates and the other links turn at omega about fixed pivots, so
    # T = 1/2 J_red omega^2 with J_red constant: at constant speed dT/dt = 0 and the
    # drive only balances gravity, tau omega = -P_gravity
    model = res.model
    p_grav = np.zeros(res.n)
    from mechdyn.model.constraints import point_velocity

    for k, b in enumerate(model.body_names):
        v = point_velocity(model, res.x, res.xdot, b, "com")
        p_grav += model.mass[k] * (-G) * v[:, 1]
    np.testing.assert_allclose(res.driving["phi"] * 5.0, -p_grav, rtol=0,
                               atol=1e-9 * np.max(np.abs(p_grav)))
    # Newton-Euler still holds with the minimum-norm reactions (coupler, translating)
    cp = model.body_index("coupler")
    f = (res.reactions["A"] - res.reactions["B"] - res.reactions["C"]
         + model.mass[cp] * np.array([0.0, -G]))
    from mechdyn.model.constraints import point_acceleration

    ac = point_acceleration(model, res.x, res.xdot, res.xddot, "coupler", "com")
    np.testing.assert_allclose(f, model.mass[cp] * ac, atol=1e-9 * np.max(np.abs(f)) + 1e-9)
    # without the third link: no warning
    plain = kinetostatics(parallelogram(False), over="phi", speed=5.0, values=values)
    assert plain.status == "success" and not plain.redundant_joints


def test_redundancy_is_not_reported_for_a_plain_mechanism():
    res = kinetostatics(door(False), over="theta", speed=1.0,
                        values=np.linspace(0.0, 1.0, 5))
    assert res.status == "success"
    assert res.redundant_joints == ()
    assert res.stats["redundant_equations"] == 0
