"""The variable grammar (mechdyn.model.variable): one parser for switch conditions, stops,
coordinate locks and load tables, checked against hand-made geometry."""

import numpy as np
import pytest

from mechdyn.errors import ModelError
from mechdyn.examples import press_cycle
from mechdyn.model.forces import LoadContext
from mechdyn.model.variable import Variable, parse, parse_variable, quantity
from mechdyn.modelfile.switches import variable_kind


@pytest.fixture(scope="module")
def press():
    mech = press_cycle.build()
    return mech, mech.compile()


def test_every_form_parses():
    coords = ("phi", "psi", "p")
    assert parse(" t ", coords) == Variable("t", "time")
    assert parse("psi", coords) == Variable("psi", "coordinate", "psi")
    assert parse("psi_dot", coords).rate
    assert parse("joint:C", coords) == Variable("joint:C", "joint", "C")
    assert parse("angle:rocker", coords) == Variable("angle:rocker", "angle", "rocker")
    assert parse("rod.B.y", coords).points == (("rod", "B"),)
    assert parse("rod.B.y", coords).comp == 1
    assert parse("dist( rod.B , slider.ear )", coords).points == (("rod", "B"), ("slider", "ear"))
    # a coordinate whose name ends in _dot is the coordinate, not a rate
    assert not parse("a_dot", ("a", "a_dot")).rate


def test_unknown_forms_list_the_forms_and_the_coordinates():
    with pytest.raises(ModelError, match=r"unknown variable 'phj'; valid variables: .*"
                                         r"'joint:NAME'.*coordinates: 'phi', 'psi', 'p'"):
        parse("phj", ("phi", "psi", "p"))
    with pytest.raises(ModelError, match=r"point reference 'rod' must be 'body.point'"):
        parse("dist(rod, slider.ear)", ())


def test_names_are_checked_against_the_mechanism_and_give_the_unit_kind(press):
    mech, model = press
    assert [variable_kind(mech, v) for v in ("t", "psi", "p_dot", "joint:C", "joint:guide",
                                             "angle:rod", "rod.B.x", "dist(rod.B, slider.ear)")] \
        == ["time", "angle", "velocity", "angle", "length", "angle", "length", "length"]
    with pytest.raises(ModelError, match=r"unknown revolute or prismatic joint 'Q'.*'guide'"):
        quantity(parse("joint:Q", mech.coordinates), mech)
    with pytest.raises(ModelError, match=r"unknown point 'P' of body 'rod'; valid point names"):
        quantity(parse("rod.P.x", mech.coordinates), mech)
    with pytest.raises(ModelError, match=r"unknown body 'rood'"):
        parse_variable(model, "angle:rood")
    with pytest.raises(ModelError, match=r"allowed only in switch conditions"):
        parse_variable(model, "dist(rod.B, slider.ear)")


def test_measures_are_the_geometry_of_the_pose(press):
    mech, model = press
    rng = np.random.default_rng(3)
    x = model.x_sketch + 0.1 * rng.normal(size=model.n_x)
    xd = rng.normal(size=model.n_x)
    X = x.reshape(-1, 3)

    def point(body, name):
        b = model.body_index(body)
        s = model.point_local(body, name)
        c, sn = np.cos(X[b, 2]), np.sin(X[b, 2])
        return X[b, :2] + [c * s[0] - sn * s[1], sn * s[0] + c * s[1]]

    rod, rocker, slider = (model.body_index(b) for b in ("rod", "rocker", "slider"))
    cases = {"angle:rod": X[rod, 2], "joint:C": X[rocker, 2] - X[slider, 2],
             "joint:guide": X[slider, 0], "rod.B.y": point("rod", "B")[1],
             "dist(rod.B, slider.ear)": np.hypot(*(point("rod", "B") - point("slider", "ear")))}
    for spec, want in cases.items():
        m = parse_variable(model, spec, allow_distance=True)
        assert m.value(x) == pytest.approx(want, abs=1e-14), spec
        h = 1e-6  # the rate is the derivative along xdot
        rate = (m.value(x + h * xd) - m.value(x - h * xd)) / (2 * h)
        assert m.rate(x, xd) == pytest.approx(rate, rel=1e-7, abs=1e-9), spec
    assert parse_variable(model, "psi_dot", allow_rate=True).value(x, xd) == pytest.approx(
        xd[3 * rocker + 2])
    # the same strings in a load table's context
    q = np.zeros(model.n_q)
    ctx = LoadContext(model, 0.5, q, q + 2.0, x, xd)
    for spec, want in cases.items():
        assert ctx.variable(spec) == pytest.approx(want, abs=1e-14), spec
    assert ctx.variable("t") == 0.5 and ctx.variable("p_dot") == 2.0
