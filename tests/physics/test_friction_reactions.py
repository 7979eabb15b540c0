"""The reactions of pairs with friction, sticking and slipping (issue 12): kinetostatics of
a forward run against closed forms, and the one reaction reporter (issue 9) with friction:
the forward run's table and ``kinetostatics(trajectory=run)`` give every joint's force and
moment, friction included, to round-off."""

import warnings

import numpy as np
import pytest
from dynamics_models import pendulum, slider_crank

import mechdyn
from mechdyn import Mechanism
from mechdyn.dynamics.reactions import KinetostaticsWarning
from mechdyn.mechanism.load import Force, Table, Torque

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


def _rough_slider_crank(mu_pin, r, mu_guide, L):
    mech = slider_crank()
    j = mech.joints
    for n in ("O", "A", "B"):
        j[n] = type(j[n])(**{**j[n].__dict__, "friction": mu_pin, "pin_radius": r})
    j["guide"] = type(j["guide"])(**{**j["guide"].__dict__, "friction": mu_guide,
                                     "guide_length": L})
    return mech


@pytest.mark.parametrize("case", ["driven", "coming to rest"])
def test_forward_table_and_kinetostatics_report_the_same_reactions_with_friction(case):
    """A slider-crank with friction in its three pins and its guide, driven by a motor
    (every pair slips) or let go slowly with rough pairs (it slips, then comes to rest
    and every pair sticks: the four stick rows hold its one freedom together, a
    statically indeterminate share that both report by the same least norm).  The run's
    table and kinetostatics(trajectory=run) give every joint's force and moment (a pin's:
    its friction moment on the child) to 1e-8 of the largest reaction.  Independently of
    either: in the slipping samples the table's pin moments are -mu r |R| s and the
    guide's tangential force -mu S s (S = |N/2 - M/L| + |N/2 + M/L| of its normal force N
    and moment M, s the pair's slip direction of the mode); sticking, each friction is
    within its capacity."""
    if case == "driven":
        mu_p, r, mu_g, L, T, w0 = 0.1, 0.01, 0.15, 0.04, 0.01, 25.0
        mech = _rough_slider_crank(mu_p, r, mu_g, L)
        mech.add(Torque("motor", "crank", 3.0))
    else:
        mu_p, r, mu_g, L, T, w0 = 0.2, 0.02, 0.6, 0.04, 0.05, 1.0
        mech = _rough_slider_crank(mu_p, r, mu_g, L)
    tr = mechdyn.simulate(mech, T, q0=[0.6], qdot0=[w0], rtol=1e-10,
                          t_eval=np.linspace(0.0, T, 21), progress=False)
    assert tr.status == "success", tr.message
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinetostaticsWarning)  # the sticking group
        res = mechdyn.kinetostatics(mech, trajectory=tr)
    vs = tr.stats["variable_structure"]
    forces = vs["forces"]
    scale = max(np.max(np.abs(res.reactions[j])) for j in res.reactions)
    for j in ("O", "A", "B", "guide"):
        f = np.asarray(forces[j])
        assert f.shape == (tr.t.size, 3)
        np.testing.assert_allclose(f[:, :2], res.reactions[j], rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(f[:, 2], res.moments[j], rtol=0, atol=1e-8 * scale)
    assert {"M_O_Nm", "M_A_Nm", "M_B_Nm", "M_guide_Nm"} <= set(tr.to_dataframe())
    state = {j: np.array([next(t.split(":")[1] for t in md if t.startswith(j + ":"))
                          for md in vs["mode"]]) for j in ("O", "A", "B", "guide")}
    s = {j: np.where(st == "slip+", 1.0, -1.0) for j, st in state.items()}
    slip = {j: st != "stick" for j, st in state.items()}
    for j in ("O", "A", "B"):
        f = np.asarray(forces[j])
        cap = mu_p * r * np.hypot(f[:, 0], f[:, 1])
        np.testing.assert_allclose(f[slip[j], 2], -(cap * s[j])[slip[j]], rtol=0,
                                   atol=1e-12 * scale)
    g = np.asarray(forces["guide"])  # the guide's axis is the ground's x axis
    S = np.abs(g[:, 1] / 2 - g[:, 2] / L) + np.abs(g[:, 1] / 2 + g[:, 2] / L)
    np.testing.assert_allclose(g[slip["guide"], 0], -(mu_g * S * s["guide"])[slip["guide"]],
                               rtol=0, atol=1e-12 * scale)
    if case == "driven":
        assert all(v.all() for v in slip.values())
        return
    # at rest: the friction holds the weights, whatever its share among the pairs.  Per
    # unit crank rate (rod angle b: sin b = (e - r sin phi) / l) the pairs turn at
    # w_O = 1, w_A = b' - 1, w_B = -b' and the slider moves at x'; the virtual power of
    # the friction, sum M_j w_j + f_guide x', balances that of gravity and is within the
    # capacity sum mu r |R_j| |w_j| + mu S |x'|
    rest = ~slip["guide"]
    assert rest.sum() >= 5 and (~rest).sum() >= 5 and all(np.array_equal(~slip[j], rest)
                                                           for j in slip)
    rc, lr, e = 0.08, 0.25, -0.02
    phi = tr.q[rest, 0]
    b = np.arcsin((e - rc * np.sin(phi)) / lr)
    bd = -rc * np.cos(phi) / (lr * np.cos(b))
    xd = -rc * np.sin(phi) - lr * np.sin(b) * bd
    w = {"O": np.ones_like(phi), "A": bd - 1.0, "B": -bd}
    p_grav = -G * (0.8 * (0.03 * np.cos(phi) - 0.005 * np.sin(phi))
                   + 1.2 * (rc * np.cos(phi) + 0.1 * np.cos(b) * bd))
    p_fric = sum(np.asarray(forces[j])[rest, 2] * w[j] for j in w) + g[rest, 0] * xd
    np.testing.assert_allclose(p_fric, -p_grav, rtol=1e-10)
    cap = sum(mu_p * r * np.hypot(*np.asarray(forces[j])[rest, :2].T) * np.abs(w[j])
              for j in w) + mu_g * S[rest] * np.abs(xd)
    assert np.all(np.abs(p_fric) <= cap)


def test_toggle_press_with_friction_one_reporter():
    """The toggle-press example with friction in every pin and the ram guide, 50 ms of
    its stroke: the run's table and kinetostatics(trajectory=run) give every joint's
    force and moment to 1e-8 of the largest reaction."""
    from mechdyn import examples

    mech = examples.load("toggle_press_friction")
    tr = mechdyn.simulate(mech, 0.05, t_eval=np.linspace(0.0, 0.05, 11), rtol=1e-10,
                          progress=False)
    assert tr.status == "success", tr.message
    res = mechdyn.kinetostatics(mech, trajectory=tr)
    forces = tr.stats["variable_structure"]["forces"]
    scale = max(np.max(np.abs(res.reactions[j])) for j in res.reactions)
    assert len(res.reactions) == 7
    for j in res.reactions:
        f = np.asarray(forces[j])
        np.testing.assert_allclose(f[:, :2], res.reactions[j], rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(f[:, 2], res.moments[j], rtol=0, atol=1e-8 * scale)
        assert np.max(np.abs(res.moments[j])) > 0  # every pair has friction
