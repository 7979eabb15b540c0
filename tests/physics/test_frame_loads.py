"""The load on the frame against the momentum balance of the mechanism.

Newton's second law for all the moving bodies together: the rate of change of their
total momentum equals the external forces on them -- the weights and what the frame
applies.  So what the frame receives is F_frame = -(dP/dt - sum m g), with
dP/dt = sum m a_c from the recorded accelerations of the centres of mass.  The frame
load of a run comes from another road: the multipliers of the grounded joints, the
ground ends of springs and the drives' stators.  The two agree to round-off on every
bundled fixed-structure example (issue 11: frame loads from every run).
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.model.forces import com_arms


@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "toggle_press",
                                  "clutchless_press", "andrews_squeezer"])
def test_frame_force_is_minus_the_rate_of_momentum_plus_the_weights(name):
    model = md.examples.load(name).compile()
    tr = md.simulate(model, 0.05, t_eval=np.linspace(0.0, 0.05, 51), progress=False)
    assert tr.status == "success", tr.message
    nb = model.n_bodies
    acc = tr.xddot().reshape(-1, nb, 3)
    omega = tr.xdot.reshape(-1, nb, 3)[..., 2]
    arm = com_arms(model, tr.x)  # centre of mass from the frame origin, ground frame
    perp = np.stack([-arm[..., 1], arm[..., 0]], axis=-1)
    a_c = acc[..., :2] + acc[..., 2, None] * perp - (omega**2)[..., None] * arm
    dP = np.einsum("b,nbk->nk", model.mass, a_c)
    expected = -(dP - model.mass.sum() * np.asarray(model.gravity))
    frame = tr.stats["variable_structure"].frame_force
    np.testing.assert_allclose(frame, expected, rtol=0, atol=1e-12 * np.max(np.abs(frame)))
