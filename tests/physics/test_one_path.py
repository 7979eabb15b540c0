"""One step control in the compiled DOP853 loop: a segment with event functions takes
the steps a segment without them takes, so a switchable element that never acts changes
no step of a run."""

import numpy as np
import pytest

import mechdyn
from mechdyn.mechanism.contact import Stop

pytestmark = pytest.mark.timeout(120)


def _pair(name):
    plain, fenced = mechdyn.examples.load(name), mechdyn.examples.load(name)
    c = fenced.compile().coordinate_names[0]
    fenced.add(Stop("far", c, lower=-1e4, upper=1e4))  # never reached: its gap is watched
    return plain, fenced


@pytest.mark.parametrize("name", [
    "slider_crank", "four_bar",
    pytest.param("toggle_press", marks=pytest.mark.xfail(strict=True, reason=(
        "its punch load is a table with sharp points: the loop with event functions "
        "does not yet reach them as the loop without does (80 against 91 samples, "
        "the step sizes apart from the second step on)")))])
def test_a_stop_that_never_closes_changes_no_step(name):
    plain, fenced = _pair(name)
    a = mechdyn.simulate(plain, 0.2, progress=False)  # every step is a sample
    b = mechdyn.simulate(fenced, 0.2, progress=False)
    assert a.success and b.success and not b.events
    for k in ("steps", "rejected", "evaluations"):
        assert a.stats[k] == b.stats[k], k
    for k in ("t", "q", "qdot"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    # the accelerations come from a position solve started from each path's last pose
    assert np.allclose(a.qddot, b.qddot, rtol=1e-12, atol=1e-9 * np.abs(a.qddot).max())


def test_samples_between_the_steps_agree_to_round_off():
    """Samples at t_eval come from each path's dense output of the same steps (the
    compiled loop's, and the kept step's in Python): equal to round-off."""
    plain, fenced = _pair("slider_crank")
    kw = dict(progress=False, t_eval=np.linspace(0.0, 0.2, 191))
    a, b = mechdyn.simulate(plain, 0.2, **kw), mechdyn.simulate(fenced, 0.2, **kw)
    assert a.stats["steps"] == b.stats["steps"]
    assert np.allclose(a.q, b.q, rtol=1e-13, atol=1e-12)
    assert np.allclose(a.qdot, b.qdot, rtol=1e-10, atol=1e-10)
