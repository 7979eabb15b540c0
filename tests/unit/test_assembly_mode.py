"""Declared assembly modes: the initial assembly reaches the declared branch of a loop."""

import numpy as np
import pytest

from mechdyn import Mechanism, ModelError
from mechdyn.kinematics.assembly import solve_position, turn_signs
from mechdyn.model.constraints import point_position

# crank 40 mm, coupler 120 mm, rocker 80 mm, frame 100 mm (Grashof crank-rocker)
A_, B_, C_, D_ = 0.04, 0.12, 0.08, 0.10


def four_bar(turn=None, phi=1.0):
    """Sketch drawn on the open branch (B above the frame line)."""
    m = Mechanism("four-bar")
    m.add_ground(points={"O": (0, 0), "C": (D_, 0)})
    A = np.array([A_ * np.cos(phi), A_ * np.sin(phi)])
    C = np.array([D_, 0.0])
    dist = np.hypot(*(C - A))
    # B from the circle intersection, the upper solution (open branch here)
    a = (B_**2 - C_**2 + dist**2) / (2 * dist)
    h = np.sqrt(B_**2 - a**2)
    e = (C - A) / dist
    B = A + a * e + h * np.array([-e[1], e[0]])
    m.add_body("crank", mass=1, inertia=1e-3, points={"A": (A_, 0)}, pose=(0, 0, phi))
    th2 = np.arctan2(*(B - A)[::-1])
    m.add_body("coupler", mass=1, inertia=1e-3, points={"A": (0, 0), "B": (B_, 0)},
               pose=(A[0], A[1], th2))
    th3 = np.arctan2(*(B - C)[::-1])
    m.add_body("rocker", mass=1, inertia=1e-3, points={"C": (0, 0), "B": (C_, 0)},
               pose=(C[0], C[1], th3))
    m.add_revolute("O", "ground", "crank", "O", (0, 0))
    m.add_revolute("A", "crank", "coupler", "A", "A")
    m.add_revolute("B", "coupler", "rocker", "B", "B")
    m.add_revolute("C", "ground", "rocker", "C", "C")
    m.add_coordinate("phi", body="crank")
    if turn is not None:
        m.add_assembly_mode("elbow B", ("coupler", "A"), ("coupler", "B"), ("ground", "C"), turn)
    return m


def freudenstein_B(phi, sign):
    """Closed-form position of B on either branch (intersection of two circles)."""
    A = np.array([A_ * np.cos(phi), A_ * np.sin(phi)])
    C = np.array([D_, 0.0])
    dist = np.hypot(*(C - A))
    a = (B_**2 - C_**2 + dist**2) / (2 * dist)
    h = np.sqrt(B_**2 - a**2)
    e = (C - A) / dist
    return A + a * e + sign * h * np.array([-e[1], e[0]])


def test_sketch_branch_is_reported_by_its_turn():
    model = four_bar().compile()
    B = point_position(model, model.x0, "coupler", "B")
    assert np.allclose(B, freudenstein_B(1.0, +1), atol=1e-12)


@pytest.mark.parametrize("turn, side", [("right", +1), ("left", -1)])
def test_declared_mode_is_reached_from_either_sketch(turn, side):
    # A -> B -> C turns right when B is on the upper (sketch) side, left on the lower one
    model = four_bar(turn).compile()
    assert turn_signs(model, model.x0)["elbow B"] == (1 if turn == "left" else -1)
    B = point_position(model, model.x0, "coupler", "B")
    assert np.allclose(B, freudenstein_B(1.0, side), atol=1e-12)
    # and continuity keeps it over a whole turn
    x = model.x0
    for phi in np.linspace(1.0, 1.0 + 2 * np.pi, 145):
        x = solve_position(model, [phi], x)
        assert np.allclose(point_position(model, x, "coupler", "B"), freudenstein_B(phi, side),
                           atol=1e-11)


def test_unknown_point_of_an_assembly_mode_is_named():
    m = four_bar()
    m.add_assembly_mode("elbow", ("coupler", "A"), ("coupler", "X"), ("ground", "C"), "left")
    with pytest.raises(ModelError, match=r"assembly mode 'elbow': point Q: unknown point 'X'"):
        m.validate()


def test_bad_turn_is_refused():
    with pytest.raises(ValueError, match="turn must be one of"):
        four_bar().add_assembly_mode("e", ("coupler", "A"), ("coupler", "B"), ("ground", "C"),
                                     "up")


def test_model_file_assembly_table_chooses_the_branch():
    import mechdyn

    text = mechdyn.examples.path("four_bar").read_text()
    for turn, expect in (("right", -1.0), ("left", 1.0)):
        model = mechdyn.loads(text.replace('turn = "right"', f'turn = "{turn}"'),
                              "four_bar.toml").compile()
        assert turn_signs(model, model.x0)["open"] == expect
        # the two branches are mirror images about the line A-C: B differs, A and C do not
        phi = float(model.x0[2])
        B = point_position(model, model.x0, "coupler", "B")
        assert np.allclose(B, freudenstein_B(phi, -expect), atol=1e-9)


def test_model_file_assembly_point_must_name_body_and_point():
    import mechdyn

    text = mechdyn.examples.path("four_bar").read_text().replace('"coupler.B"', '"coupler"')
    with pytest.raises(ModelError, match=r"write a point as \"body.point\""):
        mechdyn.loads(text, "four_bar.toml")
