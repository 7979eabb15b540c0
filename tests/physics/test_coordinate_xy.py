"""Coordinates of kind "x" and "y" (the ground position of a body's origin), checked
against closed forms: a free body in flight, and the elliptic trammel swept over the
position of one slider."""

import numpy as np
import pytest

import mechdyn
from mechdyn import Mechanism, ModelError
from mechdyn.kinematics.sweep import sweep
from mechdyn.modelfile import loads

G = 9.81


def free_block(com=(0.1, 0.05)):
    """A free body with coordinates x, y (offset 0.5 m) and angle of its frame."""
    m = Mechanism("block", gravity=(0.0, -G))
    m.add_body("block", mass=2.0, inertia=0.1, com=com)
    m.add_coordinate("X", kind="x", body="block")
    m.add_coordinate("Y", kind="y", body="block", offset=0.5)
    m.add_coordinate("th", kind="angle", body="block")
    return m


def _turn(th, p):
    c, s = np.cos(th), np.sin(th)
    return np.stack([c * p[0] - s * p[1], s * p[0] + c * p[1]], axis=-1)


def test_free_body_falls_at_g():
    """The centre of mass flies on the parabola of g, the body turns at constant rate,
    and the coordinates are its origin's x, y (+ offset) and its angle."""
    c = np.array([0.1, 0.05])
    m = free_block(tuple(c))
    q0, qd0 = np.array([0.3, 1.5, 0.2]), np.array([1.0, 2.0, 3.0])
    names = ("X", "Y", "th")
    m.set_initial(q=dict(zip(names, q0, strict=True)), qdot=dict(zip(names, qd0, strict=True)))
    assert m.compile().found_poses["block"] == pytest.approx((0.3, 1.0, 0.2), abs=1e-12)
    tr = mechdyn.simulate(m, 0.5, rtol=1e-11, atol=1e-12, progress=False)
    t = np.asarray(tr.t)
    th = q0[2] + qd0[2] * t
    r0 = np.array([q0[0], q0[1] - 0.5]) + _turn(q0[2], c)  # the centre of mass at t = 0
    w = qd0[2]
    v0 = qd0[:2] + w * np.array([-_turn(q0[2], c)[1], _turn(q0[2], c)[0]])
    r = r0 + np.outer(t, v0) + 0.5 * np.outer(t**2, (0.0, -G))
    origin = r - _turn(th, c)
    assert np.abs(tr.q[:, 2] - th).max() < 1e-8
    assert np.abs(tr.q[:, 0] - origin[:, 0]).max() < 1e-8
    assert np.abs(tr.q[:, 1] - (origin[:, 1] + 0.5)).max() < 1e-8


def test_free_body_without_offset_accelerates_at_g():
    m = free_block(com=(0.0, 0.0))
    m.set_initial(q={"X": 0.0, "Y": 0.0, "th": 0.0}, qdot={"X": 0.0, "Y": 0.0, "th": 0.0})
    tr = mechdyn.simulate(m, 0.3, rtol=1e-11, atol=1e-12, progress=False)
    t = np.asarray(tr.t)
    assert np.abs(tr.q[:, 1] - (-0.5 * G * t**2)).max() < 1e-9
    assert np.abs(tr.qdot[:, 1] + G * t).max() < 1e-8
    assert np.abs(tr.q[:, 0]).max() < 1e-12


L = 0.2


def trammel():
    """Elliptic trammel: slider s1 on the ground's x axis, s2 on its y axis, a bar of
    length L pinned to both; the coordinate is the x of s1's origin."""
    m = Mechanism("trammel")
    x0 = 0.12
    y0 = np.sqrt(L**2 - x0**2)
    m.add_body("s1", mass=1.0, pose=(x0, 0.0, 0.0))
    m.add_body("s2", mass=1.0, pose=(0.0, y0, 0.0))
    m.add_body("bar", mass=1.0, points={"B": (L, 0.0)}, pose=(x0, 0.0, np.arctan2(y0, -x0)))
    m.add_prismatic("gx", "ground", "s1", axis=(1.0, 0.0))
    m.add_prismatic("gy", "ground", "s2", axis=(0.0, 1.0))
    m.add_revolute("A", "s1", "bar")
    m.add_revolute("B", "s2", "bar", (0.0, 0.0), "B")
    m.add_coordinate("xa", kind="x", body="s1")
    return m


def test_trammel_swept_over_a_body_position():
    xs = np.linspace(0.15, -0.15, 31)
    sw = sweep(trammel(), "xa", xs).raise_for_status()
    assert np.allclose(sw.q[:, 0], xs, atol=1e-13)
    y = sw.x[:, 3 * 1 + 1]  # s2's origin
    assert np.abs(y - np.sqrt(L**2 - xs**2)).max() < 1e-12
    # its velocity analog dy/dx = -x / y
    assert np.abs(sw.xdot[:, 4] + xs / np.sqrt(L**2 - xs**2)).max() < 1e-9


def test_model_file_x_y_coordinates():
    text = """
[model]
name = "block on a vertical guide"
[ground.points]
G = ["300 mm", "0 mm"]
[bodies.block]
mass = "2 kg"
inertia = "0.1 kg*m^2"
[joints]
guide = {type = "prismatic", parent = "ground", child = "block", parent_point = "G", axis = [0, 1]}
[coordinates.Y]
kind = "y"
body = "block"
offset = "10 mm"
[initial]
Y = "1010 mm"
[initial_speed]
Y = "2 m/s"
"""
    m = loads(text)
    c = m.coordinates["Y"]
    assert (c.kind, c.body, c.offset) == ("y", "block", pytest.approx(0.01))
    assert m.compile().found_poses["block"] == pytest.approx((0.3, 1.0, 0.0))
    tr = mechdyn.simulate(m, 0.2, rtol=1e-11, atol=1e-12, progress=False)
    assert np.abs(tr.q[:, 0] - (1.01 + 2.0 * tr.t - 0.5 * G * tr.t**2)).max() < 1e-9
    with pytest.raises(ModelError, match=r"\[coordinates\.Y\] joint: kind 'y' measures a "
                                         r"body; give 'body', not 'joint'"):
        loads(text.replace('kind = "y"\nbody = "block"', 'kind = "y"\njoint = "guide"'))
    with pytest.raises(ModelError, match=r"\[coordinates\.Y\].*'z'.*'travel', 'x', 'y'"):
        loads(text.replace('kind = "y"', 'kind = "z"'))


def test_python_errors_name_the_coordinate():
    m = free_block()
    m.add_coordinate("Z", kind="y", body="blok")
    with pytest.raises(ModelError, match=r"coordinate 'Z': body: .*'blok'.*'block'"):
        m.compile()


def test_a_stop_on_a_body_position_is_not_drawn_as_an_angle():
    """A pendulum whose coordinate is the x of its origin (0.5 m from the pin): a stop on
    it is not drawn as a ray (that of a stop on an angle); one on the pin's angle is.

    The pin P is at the bar's far end and the centre of mass at its origin, 0.5 m from
    the pin, so the mass matrix in X is well away from zero (a centre of mass on the pin
    would leave X massless and the run creeping)."""
    from mechdyn.mechanism.contact import Stop
    from mechdyn.results.animate import frame_geometry

    m = Mechanism("pendulum")
    m.add_body("bar", mass=1.0, com=(0.0, 0.0), points={"P": (0.5, 0.0)},
               pose=(-0.5 * np.cos(1.2), -0.5 * np.sin(1.2), 1.2))
    m.add_revolute("O", "ground", "bar", (0.0, 0.0), "P")
    m.add_coordinate("X", kind="x", body="bar")
    m.add(Stop("wall", "X", upper=0.45))
    m.add(Stop("pin_limit", "joint:O", upper=3.0))
    tr = mechdyn.simulate(m, 0.1, t_eval=np.linspace(0.0, 0.1, 3), progress=False)
    assert tr.x[0, 2] == pytest.approx(1.2, abs=1e-9)
    assert set(frame_geometry(tr, 1)["stops"]) == {"pin_limit@upper"}
