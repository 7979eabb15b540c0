"""Every analysis takes a Mechanism (compiled and validated for you) or a compiled Model."""

import numpy as np

import mechdyn


def test_analyses_give_the_same_result_for_a_mechanism_and_its_model():
    mech = mechdyn.examples.load("slider_crank")
    model = mech.compile()
    values = np.linspace(0.0, 2 * np.pi, 13)
    a, b = (mechdyn.sweep(m, "phi", values) for m in (mech, model))
    assert np.array_equal(a.x, b.x)
    a, b = (mechdyn.kinetostatics(m, speed=10.0, values=values) for m in (mech, model))
    assert np.array_equal(a.driving["phi"], b.driving["phi"])
    a, b = (mechdyn.reduce_model(m) for m in (mech, model))
    assert np.array_equal(a.J_red, b.J_red)
    a, b = (mechdyn.simulate(m, 0.01, progress=False) for m in (mech, model))
    assert np.array_equal(a.q, b.q)
