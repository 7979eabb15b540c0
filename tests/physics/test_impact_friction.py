"""Friction in impacts (issue 12, item 4): the oblique impact of a free rod's end on a
floor with Coulomb friction, against the rigid-body impact closed form."""

import warnings

import numpy as np
import pytest

from mechdyn.dynamics.mode_system import ModeSystem
from mechdyn.mechanism import Mechanism
from mechdyn.mechanism.contact import Contact, Stop
from mechdyn.mechanism.switch import add_element
from mechdyn.model.switchable import switched_model
from mechdyn.modelfile.switches import parse_switches
from mechdyn.simulate.impact import impact

M, L = 2.0, 0.8  # kg, m
J = M * L * L / 12  # kg m^2, about the centre
TH = 0.6  # rad, the rod's angle to the floor


def _rod(kind, mu, e):
    """A free rod (x, y and angle through two massless carriages) whose lower end A
    touches the floor y = 0, as a stop on ``rod.A.y`` or as a point-on-line contact."""
    m = Mechanism("free rod", gravity=(0.0, 0.0))
    m.add_body("cx", mass=0.0, inertia=0.0)
    m.add_body("cy", mass=0.0, inertia=0.0)
    m.add_body("rod", mass=M, inertia=J, points={"A": (-L / 2, 0.0), "B": (L / 2, 0.0)})
    m.add_prismatic("px", "ground", "cx", axis=(1.0, 0.0))
    m.add_prismatic("py", "cx", "cy", axis=(0.0, 1.0))
    m.add_revolute("G", "cy", "rod")
    m.add_coordinate("X", kind="travel", joint="px")
    m.add_coordinate("Y", kind="travel", joint="py")
    m.add_coordinate("th", kind="angle", body="rod")
    if kind == "stop":
        add_element(m, Stop("floor", "rod.A.y", lower=0.0, restitution=e, friction=mu))
    else:
        add_element(m, Contact("floor", "rod", "A", "ground", (0.0, 0.0), (1.0, 0.0),
                               friction=mu, restitution=e))
    return m


def _impact(kind, mu, e, vel):
    model = _rod(kind, mu, e).compile()
    sm = switched_model(model)
    q = np.array([0.0, L / 2 * np.sin(TH), TH])  # A on the floor
    ms = ModeSystem(sm, frozenset(), {}, np.zeros(9))
    x, xd, _ = ms.state(q, np.asarray(vel, float))
    tok = "floor@lower" if kind == "stop" else "floor@contact"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a closed stop's friction note (e = 0 cases)
        return impact(sm, x, xd, frozenset(), frozenset(), {}, [tok]), tok


def _closed_form(vel, mu, e):
    """Rigid-body impact of the rod's end A at r = (-L/2 cos TH, -L/2 sin TH) from its
    centre: impulse (Pt, Pn) at A changes v_G by P/M and omega by (r x P)/J, so the
    velocity of A changes by W (Pt, Pn) with
        W = [[1/M + ry^2/J, -rx ry/J], [-rx ry/J, 1/M + rx^2/J]].
    Stick: vt+ = 0 and vn+ = -e vn-; slide (s = the sign of the sliding): Pt = -mu s Pn
    and vn+ = -e vn-."""
    vx, vy, w = vel
    rx, ry = -L / 2 * np.cos(TH), -L / 2 * np.sin(TH)
    vt, vn = vx - w * ry, vy + w * rx
    W = np.array([[1 / M + ry * ry / J, -rx * ry / J], [-rx * ry / J, 1 / M + rx * rx / J]])
    pt, pn = np.linalg.solve(W, [-vt, -(1 + e) * vn])
    if abs(pt) <= mu * pn:
        return "stick", pt, pn, vt, W
    for s in (np.sign(vt), -np.sign(vt)):
        pn = -(1 + e) * vn / (W[1, 1] - mu * s * W[1, 0])
        pt = -mu * s * pn
        if s * (vt + W[0, 0] * pt + W[0, 1] * pn) > 0:
            return "slide", pt, pn, vt, W
    raise AssertionError("no consistent closed form")


@pytest.mark.parametrize("kind", ["stop", "contact"])
@pytest.mark.parametrize("vel, mu, e, state", [
    ((0.3, -2.0, 1.0), 2.0, 0.5, "stick"),
    ((0.3, -2.0, 1.0), 0.8, 0.0, "stick"),
    ((3.0, -2.0, 1.0), 0.2, 0.5, "slide"),
    ((-2.5, -1.5, -2.0), 0.3, 0.0, "slide"),
])
def test_oblique_impact_of_a_rod_end_against_the_closed_form(kind, vel, mu, e, state):
    want, pt, pn, vt, W = _closed_form(vel, mu, e)
    assert want == state
    res, tok = _impact(kind, mu, e, vel)
    np.testing.assert_allclose(res.impulses[tok], pn, rtol=1e-12)
    np.testing.assert_allclose(res.impulses["floor.tangent"], pt, rtol=1e-12)
    np.testing.assert_allclose(res.element_impulses["floor.tangent"], pt, rtol=1e-12)
    vt_plus = vt + W[0, 0] * pt + W[0, 1] * pn
    np.testing.assert_allclose(res.velocity_after["floor.tangent"], vt_plus,
                               atol=1e-12 * abs(vt))
    np.testing.assert_allclose(res.velocity_after[tok], -e * res.velocity_before[tok],
                               rtol=1e-12, atol=1e-14)
    if state == "slide":
        assert np.sign(vt_plus) == np.sign(vt)  # no reversal: Routh's result as well
        assert res.friction_states["floor"] == ("slip+" if vt > 0 else "slip-")
        assert abs(pt) == pytest.approx(mu * pn, rel=1e-13)
    else:
        assert res.friction_states["floor"] == "stick" and abs(pt) <= mu * pn
    # the rod's momentum jumps by the impulse; the frame receives its opposite
    vx, vy, w = vel
    qd = np.asarray(res.xdot_plus)[6:9]
    np.testing.assert_allclose(M * (qd[:2] - [vx, vy]), [pt, pn], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.frame_impulse[:2], [-pt, -pn], rtol=1e-12, atol=1e-12)
    # and the opposite of the jump of its angular momentum about the ground origin
    gx, gy = 0.0, L / 2 * np.sin(TH)
    dH = gx * M * (qd[1] - vy) - gy * M * (qd[0] - vx) + J * (qd[2] - w)
    np.testing.assert_allclose(res.frame_impulse[2], -dH, rtol=1e-12, atol=1e-12)
    assert res.energy_lost > 0


def test_sliding_reversed_by_the_normal_impulse_opposes_the_final_sliding():
    # A slides to +x before; the rod's spin under the normal impulse sends it to -x: the
    # friction impulse opposes the sliding after the impact (the stated law)
    vel, mu, e = (0.3, -2.0, 1.0), 0.1, 0.5
    vx, vy, w = vel
    rx, ry = -L / 2 * np.cos(TH), -L / 2 * np.sin(TH)
    vt, vn = vx - w * ry, vy + w * rx
    W = np.array([[1 / M + ry * ry / J, -rx * ry / J], [-rx * ry / J, 1 / M + rx * rx / J]])
    pn = -(1 + e) * vn / (W[1, 1] + mu * W[1, 0])  # s = -1
    pt = mu * pn
    vt_plus = vt + W[0, 0] * pt + W[0, 1] * pn
    assert vt > 0 > vt_plus
    res, tok = _impact("stop", mu, e, vel)
    np.testing.assert_allclose([res.impulses[tok], res.impulses["floor.tangent"]], [pn, pt],
                               rtol=1e-12)
    assert res.friction_states["floor"] == "slip-"


def test_frictionless_impact_has_no_tangential_impulse():
    res, tok = _impact("stop", 0.0, 0.5, (0.3, -2.0, 1.0))
    assert "floor.tangent" not in res.impulses and res.friction_states == {}
    vy, w = -2.0, 1.0
    rx = -L / 2 * np.cos(TH)
    pn = -(1.5) * (vy + w * rx) / (1 / M + rx * rx / J)
    np.testing.assert_allclose(res.impulses[tok], pn, rtol=1e-12)


def test_a_stop_that_stays_closed_warns_that_its_friction_acts_in_impacts_only():
    model = _rod("stop", 0.8, 0.0).compile()
    sm = switched_model(model)
    ms = ModeSystem(sm, frozenset(), {}, np.zeros(9))
    x, xd, _ = ms.state(np.array([0.0, L / 2 * np.sin(TH), TH]), np.array([0.3, -2.0, 1.0]))
    with pytest.warns(UserWarning, match="stop 'floor' has friction = 0.8: it acts in its "
                                         "impacts only"):
        impact(sm, x, xd, frozenset(), frozenset(), {}, ["floor@lower"])


def test_stop_friction_is_checked_and_read_from_the_model_file():
    with pytest.raises(ValueError, match="stop 'st': friction must be >= 0"):
        Stop("st", "rod.A.y", lower=0.0, friction=-0.1)
    with pytest.raises(ValueError, match="stop 'st': friction needs a stop on a point "
                                         "coordinate"):
        Stop("st", "joint:px", lower=0.0, friction=0.2)
    assert Stop("st", "rod.A.x", upper=1.0, friction=0.2).tangent_variable() == "rod.A.y"
    m = _rod("contact", 0.0, 0.0)
    doc = {"stops": [{"name": "st", "variable": "rod.B.y", "lower": "0 mm",
                      "restitution": 0.3, "friction": 0.25},
                     {"name": "bad", "variable": "X", "lower": "0 mm", "friction": 0.25}]}
    probs = parse_switches(doc, m, "f.toml")
    assert len(probs) == 1 and "f.toml: [[stops]] #2 'bad'" in probs[0] \
        and "friction needs a stop on a point coordinate" in probs[0]
    st = m.extras["stops"][0]
    assert st.friction == 0.25 and st.restitution == 0.3


@pytest.mark.parametrize("mu, e, state", [(0.3, 0.5, "slide"), (1.0, 0.5, "stick")])
def test_a_falling_rod_hits_the_floor_in_a_simulation(mu, e, state):
    # released at rest in its angle TH, moving sideways at 1 m/s, the centre at 0.5 m:
    # it falls without turning and A meets the floor after a free fall of h
    from mechdyn.simulate.segments import simulate_events

    m = _rod("stop", mu, e)
    m.gravity = (0.0, -9.81)
    h = 0.5 - L / 2 * np.sin(TH)
    vel = (1.0, -np.sqrt(2 * 9.81 * h), 0.0)
    want, pt, pn, _, _ = _closed_form(vel, mu, e)
    assert want == state
    tr = simulate_events(m, 0.3, q0=[0.0, 0.5, TH], qdot0=[1.0, 0.0, 0.0], dt_out=0.05)
    assert tr.status == "success", tr.message
    ev = [ev for ev in tr.events if ev.kind == "impact"][0]
    assert ev.t == pytest.approx(np.sqrt(2 * h / 9.81), abs=1e-10)
    np.testing.assert_allclose([ev.impulses["floor"], ev.impulses["floor.tangent"]],
                               [pn, pt], rtol=1e-8)
