"""The bundled model file of the paper's dynamic case equals its Python construction."""

import numpy as np

import mechdyn
from mechdyn.examples.paper_case import T_END, WILSON_STEPS, press_idle


def test_model_file_and_python_case_give_the_same_motion():
    from_file = mechdyn.examples.load("clutchless_press_paper")
    in_python = press_idle()
    runs = [mechdyn.simulate(m, T_END, integrator="wilson", steps=WILSON_STEPS,
                             backend="numpy", progress=False)
            for m in (from_file, in_python)]
    assert all(r.success for r in runs)
    assert np.allclose(runs[0].q, runs[1].q, rtol=0, atol=1e-12)
    assert np.allclose(runs[0].qdot, runs[1].qdot, rtol=0, atol=1e-9)


def test_the_paper_initial_state_is_in_the_file():
    mech = mechdyn.examples.load("clutchless_press_paper")
    init = mech.extras["initial"]
    assert np.isclose(np.rad2deg(init["q"]["phi"]), -64.1)
    assert np.isclose(np.rad2deg(init["q"]["psi"]), -46.34)
    assert np.isclose(init["qdot"]["phi"], 43.5) and init["qdot"]["psi"] == 0.0
