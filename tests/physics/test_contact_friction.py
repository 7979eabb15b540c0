"""Unilateral contacts: Coulomb friction on an incline, indeterminate contacts, the LCP."""

import numpy as np
import pytest

from mechdyn.mechanism import Mechanism
from mechdyn.mechanism.contact import Contact
from mechdyn.mechanism.switch import add_element
from mechdyn.simulate.gaps import ContactError, solve_lcp
from mechdyn.simulate.segments import simulate_events

G = 9.81


def _block_on_incline(angle, mu, points=((0.0, 0.0),), compliance=(0.0,)):
    """A block kept from turning (two prismatic joints through a massless carriage)
    resting on the line of slope ``angle`` through the origin."""
    m = Mechanism("block on an incline")
    m.add_body("carriage", mass=0.0, inertia=0.0)
    m.add_body("block", mass=2.0, inertia=0.01)
    m.add_prismatic("px", "ground", "carriage", axis=(1.0, 0.0))
    m.add_prismatic("py", "carriage", "block", axis=(0.0, 1.0))
    m.add_coordinate("sx", kind="travel", joint="px")
    m.add_coordinate("sy", kind="travel", joint="py")
    d = (np.cos(angle), np.sin(angle))
    for k, (p, c) in enumerate(zip(points, compliance, strict=True)):
        add_element(m, Contact(f"c{k}", "block", p, "ground", (0.0, 0.0), d, friction=mu,
                               compliance=c))
    return m


def test_block_sticks_below_the_friction_angle():
    a, mu = 0.3, 0.5  # tan a = 0.309 < mu
    tr = simulate_events(_block_on_incline(a, mu), 0.5, q0=[np.cos(a), np.sin(a)],
                         qdot0=[0.0, 0.0], dt_out=0.05)
    assert tr.status == "success", tr.message
    assert all("c0:stick" in mset for mset in tr.stats["variable_structure"]["mode"])
    np.testing.assert_allclose(tr.q, np.broadcast_to(tr.q[0], tr.q.shape), atol=1e-14)
    # the contact carries the normal component of the weight
    np.testing.assert_allclose(tr.stats["variable_structure"]["forces"]["c0"],
                               2.0 * G * np.cos(a), rtol=1e-12)


def test_block_slides_with_the_analytic_acceleration_above_the_friction_angle():
    a, mu, T = 0.5, 0.3, 0.4
    tr = simulate_events(_block_on_incline(a, mu), T, q0=[np.cos(a), np.sin(a)],
                         qdot0=[0.0, 0.0], dt_out=0.05)
    assert tr.status == "success", tr.message
    acc = -G * (np.sin(a) - mu * np.cos(a))
    u = np.array([np.cos(a), np.sin(a)])
    np.testing.assert_allclose(tr.qddot @ u, acc, rtol=1e-10)
    np.testing.assert_allclose((tr.q - tr.q[0]) @ u, 0.5 * acc * tr.t ** 2, atol=1e-11)
    # it stays on the incline: no penetration, no lift-off
    n = np.array([-np.sin(a), np.cos(a)])
    assert np.max(np.abs(tr.q @ n)) < 1e-12
    # friction dissipates mu N |v| : the energy balance closes
    assert tr.energy_drift() < 1e-9


def test_sliding_block_comes_to_rest_and_sticks_when_pushed_uphill():
    a, mu = 0.2, 0.5
    tr = simulate_events(_block_on_incline(a, mu), 0.5, q0=[np.cos(a), np.sin(a)],
                         qdot0=[0.5 * np.cos(a), 0.5 * np.sin(a)], dt_out=0.01)
    dec = G * (np.sin(a) + mu * np.cos(a))
    stick = [e for e in tr.events if e.kind == "stick"]
    assert len(stick) == 1
    assert stick[0].t == pytest.approx(0.5 / dec, abs=1e-10)
    assert np.all(np.abs(tr.qdot[tr.t > stick[0].t + 1e-9]) < 1e-12)


def test_statically_indeterminate_contacts_share_the_load_by_their_compliance():
    # the block cannot turn, so two contact points on a level floor are redundant
    tr = simulate_events(_block_on_incline(0.0, 0.0, points=((-0.1, 0.0), (0.1, 0.0)),
                                           compliance=(1e-6, 3e-6)),
                         0.1, q0=[0.0, 0.0], qdot0=[0.0, 0.0], dt_out=0.05)
    assert tr.status == "success", tr.message
    f = tr.stats["variable_structure"]["forces"]
    total = f["c0"] + f["c1"]
    np.testing.assert_allclose(total, 2.0 * G, rtol=1e-10)
    np.testing.assert_allclose(f["c0"] / f["c1"], 3.0, rtol=1e-8)


def test_lcp_solution_is_complementary_and_matches_enumeration():
    rng = np.random.default_rng(3)
    for _ in range(20):
        A = rng.normal(size=(5, 5))
        H = A @ A.T + 0.1 * np.eye(5)
        r = rng.normal(size=5)
        sol = solve_lcp(H, r)
        w = H @ sol.z + r
        assert np.all(sol.z >= -1e-12) and np.all(w >= -1e-9)
        assert abs(sol.z @ w) < 1e-9
    # a non-symmetric (sliding friction) P-matrix goes to the active-set enumeration
    H = np.array([[2.0, 0.5], [-0.3, 1.0]])
    sol = solve_lcp(H, np.array([-1.0, -1.0]))
    assert sol.method == "enumeration"
    np.testing.assert_allclose(H @ sol.z + [-1.0, -1.0], 0.0, atol=1e-12)


def test_lcp_without_solution_raises_a_contact_error():
    with pytest.raises(ContactError, match="no solution"):
        solve_lcp(np.array([[-1.0]]), np.array([-1.0]))
