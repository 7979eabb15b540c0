"""The bundled examples load, assemble, and move as their comments say."""

import math

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.errors import ModelError
from mechdyn.kinematics import solve_position
from mechdyn.model.constraints import point_position

NAMES = ["andrews_squeezer", "bolt_buffer", "clutchless_press", "clutchless_press_lumped",
         "clutchless_press_paper",
         "four_bar", "press_cycle", "slider_crank", "toggle_press", "toggle_press_friction",
         "toggle_press_paper"]


def test_every_example_is_listed_with_a_description():
    listed = examples.list_examples()
    assert [n for n, _ in listed] == NAMES
    assert all(desc and "\n" not in desc for _, desc in listed)


def test_unknown_example_lists_the_names():
    with pytest.raises(ModelError, match="unknown example 'fourbar'; valid example names: "
                                         "'andrews_squeezer', 'bolt_buffer', 'clutchless_press', "
                                         "'clutchless_press_lumped', 'clutchless_press_paper', "
                                         "'four_bar', 'press_cycle', 'slider_crank', "
                                         "'toggle_press', 'toggle_press_friction', "
                                         "'toggle_press_paper'"):
        examples.path("fourbar")
    assert examples.path("four_bar.toml") == examples.path("four_bar")


@pytest.mark.parametrize("name", NAMES)
def test_example_loads_and_assembles_at_its_initial_coordinates(name):
    mech = examples.load(name)
    model = mech.compile()
    q0 = np.array([mech.extras["initial"]["q"][c] for c in model.coordinate_names])
    x = solve_position(model, q0, model.x0)
    assert np.all(np.isfinite(x))
    # the sketch is drawn at the initial coordinates, so it hardly moves
    assert np.max(np.abs(x - model.x_sketch)) < 1e-4
    assert set(mech.extras["initial"]["qdot"]) <= set(model.coordinate_names)


def _sweep(model, degrees_step=1.0):
    """Poses over a whole crank turn from the assembled sketch (raises on a singular pose)."""
    q0 = float(model.x0[2])  # the crank is the first body in every 1-DOF example
    x = model.x0
    xs = []
    for k in range(int(round(360 / degrees_step)) + 1):
        x = solve_position(model, [q0 + math.radians(k * degrees_step)], x)
        xs.append(x)
    return np.array(xs)


@pytest.mark.parametrize("name", ["four_bar", "toggle_press", "slider_crank", "andrews_squeezer"])
def test_one_dof_example_turns_a_whole_revolution_without_a_singular_position(name):
    model = examples.load(name).compile()
    xs = _sweep(model)
    # back where it started after one turn, crank angle + 2 pi: the same assembly branch
    turn = np.zeros(model.n_x)
    turn[2] = 2 * math.pi
    assert np.allclose(xs[-1] - xs[0], turn, rtol=0, atol=1e-9)


def test_four_bar_transmission_angle_stays_as_documented():
    model = examples.load("four_bar").compile()
    xs = _sweep(model)
    th_coupler = xs[:, 3 * model.body_index("coupler") + 2]
    th_rocker = xs[:, 3 * model.body_index("rocker") + 2]
    mu = np.degrees(np.abs(np.angle(np.exp(1j * (th_rocker - th_coupler)))))
    # comment in four_bar.toml: 26.4 deg at phi = 0 to 86.4 deg at phi = 180 deg
    assert mu.min() == pytest.approx(26.4, abs=0.05)
    assert mu.max() == pytest.approx(86.4, abs=0.05)


def test_toggle_press_stroke_and_dead_centres_as_documented():
    model = examples.load("toggle_press").compile()
    coarse = _sweep(model)  # 1 deg steps from the sketch at phi = 90 deg
    phi_coarse = coarse[:, 2]
    phi = np.radians(np.arange(90.0, 450.0, 0.05))
    guess = np.stack([np.interp(phi, phi_coarse, coarse[:, i]) for i in range(model.n_x)], -1)
    x = solve_position(model, phi[:, None], guess)  # one batched Newton solve
    y = point_position(model, x, "slider", "com")[:, 1]
    phi = np.mod(phi, 2 * np.pi)
    assert y.max() - y.min() == pytest.approx(0.1234, abs=0.0001)  # stroke 123.4 mm
    assert math.degrees(phi[np.argmin(y)]) == pytest.approx(139.3, abs=0.1)  # BDC
    assert math.degrees(phi[np.argmax(y)]) == pytest.approx(14.0, abs=0.1)  # TDC
    near = np.degrees(phi[y < y.min() + 0.003])  # within 3 mm of BDC
    assert near.min() == pytest.approx(122.0, abs=0.1)
    assert near.max() == pytest.approx(160.1, abs=0.1)


def test_clutchless_press_sketch_is_on_the_documented_branch():
    mech = examples.load("clutchless_press")
    model = mech.compile()
    assert mech.dof == 2 and model.coordinate_names == ("phi", "psi")
    x = model.x0
    x_C = point_position(model, x, "slider", (0.0, 0.0))
    x_B = point_position(model, x, "rocker", "B")
    assert x_C == pytest.approx((0.024989, 0.0), abs=1e-6)
    assert x_B[0] == pytest.approx(0.045700, abs=1e-6)
    # crank inertia 0.034 kg m^2 about O, centre of mass 7.5 mm from O
    assert mech.bodies["crank"].inertia == pytest.approx(0.034 - 4.6 * 0.0075**2)
    assert not mech.joints["rocker_lock"].engaged
