"""The reactions of pairs with friction, sticking and slipping (issue 12): kinetostatics of
a forward run against closed forms, and the one reaction reporter (issue 9) with friction:
the forward run's table and ``kinetostatics(trajectory=run)`` give every joint's force and
moment, friction included, to round-off."""

import numpy as np
import pytest
from dynamics_models import pendulum

import mechdyn
from mechdyn import Mechanism
from mechdyn.mechanism.load import Force, Table

G = 9.81


def _pulled_block(m, mu, c):
    """A block on a level rough guide pulled along it by c t (N)."""
    mech = Mechanism("pulled block", gravity=(0.0, -G))
    mech.add_body("block", mass=m, inertia=0.01)
    mech.add_prismatic("guide", "ground", "block", axis=(1.0, 0.0), friction=mu)
    mech.add_coordinate("s", kind="travel", joint="guide")
    mech.add(Force("pull", "block", "com", Table((0.0, 1.0), (0.0, c), "t", outside=None),
                   direction=(1.0, 0.0)))
    return mech


def test_kinetostatics_of_a_block_that_sticks_then_breaks_away():
    """Pulled by c t, the block sticks while c t <= mu m g: the guide holds it with the
    friction -c t (the stick row's force, within mu S = mu m g) and the normal force m g;
    from t* = mu m g / c it slides, v = c (t - t*)^2 / (2 m), with the friction -mu m g
    and the power mu m g v lost in the guide."""
    m, mu, c = 2.0, 0.25, 40.0
    mech = _pulled_block(m, mu, c)
    t = np.linspace(0.0, 0.3, 31)
    tr = mechdyn.simulate(mech, 0.3, q0=[0.0], qdot0=[0.0], t_eval=t, progress=False)
    assert tr.status == "success", tr.message
    res = mechdyn.kinetostatics(mech, trajectory=tr)
    assert res.status == "success", res.message
    ts = mu * m * G / c
    stick = np.array(["guide:stick" in md for md in res.sample_modes])
    assert stick.sum() >= 13 and (~stick).sum() >= 18  # both segments, event sample twice
    tt = res.t
    friction = np.where(stick, -c * tt, -mu * m * G)
    np.testing.assert_allclose(res.reactions["guide"][:, 0], friction, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.reactions["guide"][:, 1], m * G, rtol=0, atol=1e-10)
    held = res.element_forces["guide:stick"][stick]
    np.testing.assert_allclose(held, -c * tt[stick], rtol=0, atol=1e-10)
    assert np.all(np.abs(held) <= mu * m * G + 1e-10)
    v = c * np.clip(tt - ts, 0.0, None) ** 2 / (2 * m)
    np.testing.assert_allclose(res.losses["guide"], mu * m * G * v, rtol=0, atol=1e-10)


@pytest.mark.parametrize("deg", [-80.0, -100.0])
def test_kinetostatics_of_a_pendulum_held_by_its_pin_friction(deg):
    """A pendulum at rest where the pin's friction holds it (|cos theta| <= mu r / a):
    the pin carries the weight, R = (0, m g), and its friction moment on the bar is
    m g a cos theta (against the weight's moment), within mu r |R|."""
    m, a, Jc, mu, r = 2.0, 0.05, 0.01, 0.5, 0.02
    th = np.deg2rad(deg)
    mech = pendulum(deg + 90.0, m=m, a=a, Jc=Jc, g=G)
    pin = mech.joints["O"]
    mech.joints["O"] = type(pin)(**{**pin.__dict__, "friction": mu, "pin_radius": r})
    tr = mechdyn.simulate(mech, 0.2, q0=[th], qdot0=[0.0], t_eval=[0.0, 0.1, 0.2],
                          progress=False)
    assert tr.status == "success", tr.message
    res = mechdyn.kinetostatics(mech, trajectory=tr)
    M = m * G * a * np.cos(th)
    assert abs(M) <= mu * r * m * G
    np.testing.assert_allclose(res.reactions["O"], [[0.0, m * G]] * res.t.size, rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(res.moments["O"], M, rtol=1e-12)
    np.testing.assert_allclose(res.element_forces["O:stick"], M, rtol=1e-12)
    np.testing.assert_allclose(res.losses["O"], 0.0)
