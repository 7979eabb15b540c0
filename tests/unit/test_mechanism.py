"""Validation of mechanism descriptions: every problem reported at once, clearly."""

import numpy as np
import pytest

from mechdyn import Mechanism, ModelError
from mechdyn.kinematics import residual, solve_position


def slider_crank(r=0.05, l=0.2, phi=0.3):
    m = Mechanism("slider-crank")
    m.add_body("crank", mass=1.0, inertia=0.01, com=(r / 2, 0), points={"A": (r, 0)},
               pose=(0, 0, phi))
    beta = -np.arcsin(r * np.sin(phi) / l)
    m.add_body("rod", mass=1.0, inertia=0.01, com=(l / 2, 0), points={"A": (0, 0), "B": (l, 0)},
               pose=(r * np.cos(phi), r * np.sin(phi), beta))
    m.add_body("slider", mass=1.0, pose=(r * np.cos(phi) + l * np.cos(beta), 0, 0))
    m.add_revolute("O", "ground", "crank")
    m.add_revolute("A", "crank", "rod", "A", "A")
    m.add_revolute("B", "rod", "slider", "B", (0, 0))
    m.add_prismatic("P", "ground", "slider", (0, 0), (1, 0), (0, 0))
    m.add_coordinate("phi", body="crank")
    return m


def test_valid_slider_crank_compiles_with_small_residual():
    model = slider_crank().compile()
    assert model.n_q == 1 and model.n_x == 9
    assert np.max(np.abs(residual(model, model.x0))) < 1e-12


def test_all_problems_reported_at_once():
    m = slider_crank()
    m.add_body("bad", mass=-2.0, inertia=-1.0)
    m.add_revolute("X", "grund", "bad", (0, 0), "nowhere")
    with pytest.raises(ModelError) as info:
        m.validate()
    text = str(info.value)
    assert "mass must be >= 0" in text
    assert "inertia must be >= 0" in text
    assert "unknown body 'grund'" in text and "'ground'" in text and "'crank'" in text
    assert "unknown point 'nowhere'" in text
    assert len(info.value.problems) >= 4


def test_gruebler_mismatch_is_reported():
    m = slider_crank()
    m.add_coordinate("extra", body="rod")
    with pytest.raises(ModelError, match="degree"):
        m.validate()


def test_dependent_coordinate_is_reported():
    # crank angle and the relative angle of its own ground pivot measure the same motion
    m = slider_crank()
    m.joints.pop("P")
    m.add_coordinate("same", kind="relative_angle", joint="O")
    with pytest.raises(ModelError, match="not independent"):
        m.validate()


def test_zero_mass_is_allowed():
    m = slider_crank()
    m.bodies["rod"] = type(m.bodies["rod"])("rod", mass=0.0, inertia=0.0,
                                            com=m.bodies["rod"].com,
                                            points=dict(m.bodies["rod"].points),
                                            pose=m.bodies["rod"].pose)
    m.validate()


def test_unknown_coordinate_body_lists_valid_names():
    m = slider_crank()
    m.coordinates.clear()
    m.add_coordinate("phi", body="krank")
    with pytest.raises(ModelError, match=r"unknown body 'krank'.*'crank'"):
        m.validate()


def test_newton_keeps_branch_and_reaches_tiny_residual():
    model = slider_crank().compile()
    x = model.x0
    for phi in np.linspace(0.3, 0.3 + 2 * np.pi, 73):
        x = solve_position(model, [phi], x)
        assert np.max(np.abs(residual(model, x))) < 1e-12
        assert x[6] > 0  # the slider stays on the right of the crank pivot


def test_non_finite_sketch_pose_is_named():
    m = slider_crank()
    rod = m.bodies["rod"]
    m.bodies["rod"] = type(rod)("rod", mass=rod.mass, inertia=rod.inertia, com=rod.com,
                                points=dict(rod.points), pose=(np.nan, 0.0, 0.0))
    with pytest.raises(ModelError, match=r"body 'rod': pose must be finite"):
        m.validate()
