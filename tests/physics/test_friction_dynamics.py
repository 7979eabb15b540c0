"""Forward dynamics with friction in the pairs (issue 12, item 3), against closed forms and
an independent integration of the one-coordinate equation written here."""

import numpy as np
import pytest
from dynamics_models import four_bar, slider_crank
from scipy.integrate import simpson, solve_ivp
from scipy.optimize import brentq

import mechdyn
from mechdyn import Mechanism
from mechdyn.errors import ModelError
from mechdyn.mechanism.load import Force, Spring, Table, Torque

G = 9.81


def _block(angle, mu, m=2.0, guide_length=0.0, com=(0.0, 0.0), smoothing=0.0, g=G):
    """A block sliding on a guide through the origin that rises at ``angle``; coordinate
    ``s`` = its travel up the guide, m."""
    mech = Mechanism("block on an incline", gravity=(0.0, -g))
    mech.add_body("block", mass=m, inertia=0.01, com=com, pose=(0.0, 0.0, angle))
    mech.add_prismatic("guide", "ground", "block", axis=(np.cos(angle), np.sin(angle)),
                       friction=mu, guide_length=guide_length, smoothing=smoothing)
    mech.add_coordinate("s", kind="travel", joint="guide")
    return mech


def _reaction(tr, joint):
    return tr.stats["variable_structure"]["forces"][joint]


# ----------------------------------------------------------------------------- (a) incline
@pytest.mark.parametrize("guide_length", [0.0, 0.08])
def test_block_stays_at_rest_below_the_friction_angle(guide_length):
    a, mu, m = 0.3, 0.5, 2.0  # tan a = 0.309 < mu
    tr = mechdyn.simulate(_block(a, mu, m, guide_length), 0.5, q0=[0.0], qdot0=[0.0],
                          t_eval=np.linspace(0.0, 0.5, 11), progress=False)
    assert tr.status == "success", tr.message
    assert [(e.kind, e.element) for e in tr.events] == [("stick", "guide")]
    assert all("guide:stick" in md for md in tr.stats["variable_structure"]["mode"])
    assert np.max(np.abs(tr.q)) < 1e-10 and np.max(np.abs(tr.qdot)) < 1e-10
    # the guide holds the whole weight: normal m g cos a and friction m g sin a
    np.testing.assert_allclose(_reaction(tr, "guide")[:, :2], [[0.0, m * G]] * 11,
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("guide_length", [0.0, 0.08])
def test_block_slides_at_g_sin_minus_mu_cos_above_the_friction_angle(guide_length):
    a, mu, T = 0.5, 0.3, 0.4
    tr = mechdyn.simulate(_block(a, mu, guide_length=guide_length), T, q0=[0.0],
                          qdot0=[0.0], t_eval=np.linspace(0.0, T, 9), progress=False)
    assert tr.status == "success", tr.message
    assert [(e.kind, e.element, e.message) for e in tr.events] == [("slip", "guide", "slip-")]
    acc = -G * (np.sin(a) - mu * np.cos(a))  # along the guide, up positive
    np.testing.assert_allclose(tr.qddot[:, 0], acc, rtol=1e-10)
    np.testing.assert_allclose(tr.q[:, 0], 0.5 * acc * tr.t**2, rtol=0, atol=1e-10)
    np.testing.assert_allclose(tr.qdot[:, 0], acc * tr.t, rtol=0, atol=1e-10)
    # the frame carries the normal force and the friction: m g - m a (ground frame)
    m, u = 2.0, np.array([np.cos(a), np.sin(a)])
    frame = tr.stats["variable_structure"]["frame_force"]
    np.testing.assert_allclose(frame, np.broadcast_to(-m * acc * u - [0.0, m * G], frame.shape),
                               rtol=0, atol=1e-10)
    assert "NumPy path" in tr.stats["backend_note"]


def test_gib_edge_loads_of_an_offset_block():
    """A block whose centre of mass sits h above the joint point of a level guide of
    length L, pulled by P along the guide at the joint point, sliding forward.  It
    cannot turn, so (moments about the centre of mass) the reaction's moment about the
    joint point is M = -h m acc, its normal force N = m g, and m acc = P - mu S with
    S = |N/2 - M/L| + |N/2 + M/L| = 2 |M| / L once |M| / L > N / 2 (the gibs bear at
    opposite edges): acc = P / (m (1 + 2 mu h / L))."""
    m, h, L, mu, P = 2.0, 0.3, 0.1, 0.2, 40.0
    mech = _block(0.0, mu, m, guide_length=L, com=(0.0, h))
    mech.add(Force("pull", "block", (0.0, 0.0), P, direction=(1.0, 0.0)))
    tr = mechdyn.simulate(mech, 0.2, q0=[0.0], qdot0=[0.1], t_eval=[0.0, 0.1, 0.2],
                          progress=False)
    assert tr.status == "success", tr.message
    acc = P / (m * (1 + 2 * mu * h / L))
    M = -h * m * acc
    assert abs(M) / L > m * G / 2
    np.testing.assert_allclose(tr.qddot[:, 0], acc, rtol=1e-10)
    np.testing.assert_allclose(_reaction(tr, "guide")[:, 1:], [[m * G, M]] * 3, rtol=1e-10)


@pytest.mark.parametrize("h", [0.2, 0.3])
def test_tall_block_braking_on_short_gibs_jams(h):
    """A block sliding forward on a level guide with no force but gravity, its centre of
    mass h above the joint point, gibs of length L: braking at acc = -mu g needs the
    reaction moment M = h m mu g, and the edge loads stay those of N = m g only while
    2 |M| / L <= N, i.e. 2 mu h / L <= 1.  Beyond, sliding friction admits no motion (a
    Painleve-type jam): the run stops at once with status self-locking."""
    m, L, mu = 2.0, 0.1, 0.2
    tr = mechdyn.simulate(_block(0.0, mu, m, guide_length=L, com=(0.0, h)), 0.2, q0=[0.0],
                          qdot0=[1.0], t_eval=[0.0, 0.1, 0.2], progress=False)
    if 2 * mu * h / L <= 1:
        assert tr.status == "success", tr.message
        np.testing.assert_allclose(tr.qddot[:, 0], -mu * G, rtol=1e-12)
    else:
        assert tr.status == "self-locking"
        assert "'guide'" in tr.message and "t = 0 s" in tr.message


def test_friction_oscillator_reverses_then_sticks():
    """Mass on a spring on a rough level guide, released at x0: each half swing is
    harmonic about +-d (d = mu m g / k) and loses 2 d of amplitude; it sticks at the
    first turning point where |x| <= d."""
    m, k, mu, x0 = 1.0, 400.0, 0.3, 0.05
    d = mu * m * G / k
    mech = _block(0.0, mu, m)
    mech.add_ground({"A": (-1.0, 0.0)})
    mech.add(Spring("k", "ground", "A", "block", (0.0, 0.0), stiffness=k, free_length=1.0))
    w = np.sqrt(k / m)
    turns, x = [], x0
    while abs(x) > d:  # the turning points of the closed form
        x = -(x - np.sign(x) * 2 * d)
        turns.append(x)
    T = (len(turns) + 1) * np.pi / w
    tr = mechdyn.simulate(mech, T, q0=[x0], qdot0=[0.0], progress=False)
    assert tr.status == "success", tr.message
    ev = [e for e in tr.events if e.element == "guide"]
    flips = ["slip+", "slip-"] * len(turns)
    assert [e.message for e in ev] == ["slip-", *flips[:len(turns) - 1], "stick"]
    np.testing.assert_allclose([e.t for e in ev[1:]], np.arange(1, len(turns) + 1) * np.pi / w,
                               rtol=0, atol=1e-10)
    np.testing.assert_allclose([e.q_after[0] for e in ev[1:]], turns, rtol=0, atol=1e-10)
    held = tr.q[tr.t >= ev[-1].t, 0]
    assert np.ptp(held) == 0.0 and abs(held[0] - turns[-1]) < 1e-10
    assert tr.energy_drift() < 1e-9 * 0.5 * k * x0**2 + 1e-12


def test_breakaway_under_a_growing_pull():
    """A block at rest on a level guide pulled by c t: it sticks until c t* = mu m g,
    then x = c (t - t*)^3 / (6 m)."""
    m, mu, c = 2.0, 0.25, 40.0
    mech = _block(0.0, mu, m)
    mech.add(Force("pull", "block", "com", Table((0.0, 1.0), (0.0, c), "t", outside=None),
                   direction=(1.0, 0.0)))
    ts = mu * m * G / c
    tr = mechdyn.simulate(mech, 0.3, q0=[0.0], qdot0=[0.0], t_eval=np.linspace(0, 0.3, 31),
                          progress=False)
    assert tr.status == "success", tr.message
    ev = [(e.kind, e.message) for e in tr.events]
    assert ev == [("stick", "stick"), ("slip", "slip+")]
    assert tr.events[1].t == pytest.approx(ts, abs=1e-10)
    x = c * np.clip(tr.t - ts, 0, None) ** 3 / (6 * m)
    np.testing.assert_allclose(tr.q[:, 0], x, rtol=0, atol=1e-10)


# ----------------------------------------------------------------------------- (b) pendulum
def _pendulum_acceleration(th, w, s, m, a, Jc, mu, r):
    """theta'' of a compound pendulum (pivot at the origin, centre of mass a along the
    bar, theta from the horizontal) with pin friction mu r |R| against the rotation
    direction s: J_O theta'' = -m g a cos(theta) - s mu r |R|, R = m a_c - m g the pin
    force (a_c: radial -a theta'^2, tangential a theta''), solved for theta''."""
    J_O = Jc + m * a * a
    er, et = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])

    def f(al):
        R = m * a * (-w * w * er + al * et) - m * np.array([0.0, -G])
        return J_O * al + m * G * a * np.cos(th) + s * mu * r * np.hypot(*R)
    return brentq(f, -1e3, 1e3, xtol=1e-15, rtol=1e-15)


def test_pendulum_with_pin_friction_loses_amplitude_as_its_one_coordinate_equation():
    """Compound pendulum released from rest at 90 deg from the hanging position, friction
    moment mu r |R| at its pin.  Oracle: J_O theta'' = -m g a cos(theta) - s mu r |R|,
    R = m a_c - m g the pin force (a_c the acceleration of the centre of mass: radial
    -a theta'^2, tangential a theta''), an implicit equation in theta'' solved by
    bisection at every evaluation, integrated by SciPy to the turning point."""
    m, a, Jc, mu, r = 2.0, 0.5, 0.05, 0.2, 0.02
    mech = Mechanism("pendulum with pin friction", gravity=(0.0, -G))
    mech.add_body("bar", mass=m, inertia=Jc, com=(a, 0.0), pose=(0.0, 0.0, 0.0))
    mech.add_revolute("O", "ground", "bar", friction=mu, pin_radius=r)
    mech.add_coordinate("theta", kind="angle", body="bar")
    tr = mechdyn.simulate(mech, 2.0, q0=[0.0], qdot0=[0.0], rtol=1e-12, progress=False)
    assert tr.status == "success", tr.message

    def theta_dd(th, w, s):
        return _pendulum_acceleration(th, w, s, m, a, Jc, mu, r)

    def half_swing(th0, s):
        def turn(t, y):
            return y[1]
        turn.terminal, turn.direction = True, -s
        sol = solve_ivp(lambda t, y: [y[1], theta_dd(y[0], y[1], s)], (0.0, 5.0), [th0, 0.0],
                        method="DOP853", rtol=1e-13, atol=1e-14, events=turn)
        return sol.t_events[0][0], sol.y_events[0][0][0]

    t1, th1 = half_swing(0.0, -1.0)  # falls clockwise, up to the far side
    t2, th2 = half_swing(th1, 1.0)  # and back
    ev = [e for e in tr.events if e.element == "O"]
    assert [e.message for e in ev[:3]] == ["slip-", "slip+", "slip-"]
    down = -np.pi / 2
    for e, t, th in ((ev[1], t1, th1), (ev[2], t1 + t2, th2)):
        assert e.t == pytest.approx(t, abs=1e-8)
        assert e.q_before[0] == pytest.approx(th, abs=1e-8)
    # the amplitude lost per half swing, and it is a real loss (about 0.06 rad)
    lost = np.pi / 2 - abs(ev[1].q_before[0] - down)
    assert lost == pytest.approx(np.pi / 2 - abs(th1 - down), abs=1e-8)
    assert lost > 0.01
    assert tr.energy_drift() < 1e-9


@pytest.mark.parametrize("deg, holds", [(-80.0, True), (-70.0, False)])
def test_pendulum_at_rest_sticks_where_pin_friction_holds_it(deg, holds):
    """At rest the pin carries the weight, |R| = m g: the pin holds the pendulum where
    m g a |cos theta| <= mu r m g, |cos theta| <= mu r / a = 0.2 (78.5 deg from the
    horizontal); else it starts sliding as the one-coordinate equation says."""
    m, a, Jc, mu, r = 2.0, 0.05, 0.01, 0.5, 0.02
    th0 = np.deg2rad(deg)
    mech = Mechanism("pendulum at rest", gravity=(0.0, -G))
    mech.add_body("bar", mass=m, inertia=Jc, com=(a, 0.0), pose=(0.0, 0.0, th0))
    mech.add_revolute("O", "ground", "bar", friction=mu, pin_radius=r)
    mech.add_coordinate("theta", kind="angle", body="bar")
    tr = mechdyn.simulate(mech, 0.2, q0=[th0], qdot0=[0.0], t_eval=[0.0, 0.1, 0.2],
                          progress=False)
    assert tr.status == "success", tr.message
    assert tr.events[0].message == ("stick" if holds else "slip-")
    if holds:
        assert np.ptp(tr.q[:, 0]) == 0.0
    else:
        acc0 = _pendulum_acceleration(th0, 0.0, -1.0, m, a, Jc, mu, r)
        assert tr.qddot[0, 0] == pytest.approx(acc0, rel=1e-10)


def test_four_bar_with_pin_friction_reverses_every_pin_at_once():
    """A four-bar swinging under gravity with friction in its four pins.  A single pin
    whose relative rotation passes zero while the mechanism moves (the rocker turning
    back while the crank goes on) slips on the other way; at the mechanism's turning
    point (crank at rest) every pin reverses at the same instant: the pins hold one
    freedom together and break away together.  The energy balance closes."""
    mech = four_bar()
    for n in ("O", "A", "B", "C"):
        mech.joints[n] = type(mech.joints[n])(**{**mech.joints[n].__dict__, "friction": 0.2,
                                                  "pin_radius": 0.01})
    tr = mechdyn.simulate(mech, 0.8, q0=[np.pi / 2], qdot0=[0.0], progress=False)
    assert tr.status == "success", tr.message
    at: dict = {}
    for e in tr.events:
        if e.t > 0:
            at.setdefault(e.t, []).append(e)
    whole = [t for t, evs in at.items() if len(evs) == 4]
    assert len(whole) == 1  # the turning point of the crank
    assert abs(at[whole[0]][0].qdot_before[0]) < 1e-9
    assert {e.element for e in at[whole[0]]} == {"O", "A", "B", "C"}
    passing = [evs[0] for t, evs in at.items() if len(evs) == 1]
    assert passing and all(abs(e.qdot_before[0]) > 1.0 for e in passing)
    assert tr.energy_drift() < 1e-9
    assert tr.energy["work_friction"][-1] > 0


# ----------------------------------------------------------------------------- (c) energy
def _rough_slider_crank():
    mech = slider_crank()
    j = mech.joints
    for n in ("O", "A", "B"):
        j[n] = type(j[n])(**{**j[n].__dict__, "friction": 0.1, "pin_radius": 0.01})
    j["guide"] = type(j["guide"])(**{**j["guide"].__dict__, "friction": 0.15,
                                     "guide_length": 0.04})
    return mech


def test_energy_balance_of_a_slider_crank_with_friction_in_every_pair():
    """T + U - W_drive + W_friction = const with W_drive = tau (phi - phi0) of a constant
    torque on the crank, and the recorded friction work is the integral of the friction
    power computed in the test from the reported reactions: mu r |R| |w_rel| per pin and
    mu S |v| for the guide (S from its normal force and moment, edge loads N/2 -+ M/L)."""
    mech = _rough_slider_crank()
    tau = 3.0
    mech.add(Torque("motor", "crank", tau))
    T_end = 0.15
    tr = mechdyn.simulate(mech, T_end, q0=[0.6], qdot0=[25.0], rtol=1e-11,
                          t_eval=np.linspace(0.0, T_end, 481), progress=False)
    assert tr.status == "success", tr.message
    assert any(e.element == "guide" for e in tr.events)  # passes the dead centres
    E = tr.energy
    W_f = E["work_friction"]
    bal = E["kinetic"] + E["potential"] - tau * (tr.q[:, 0] - 0.6) + W_f
    assert W_f[-1] > 0.1 * E["kinetic"][0]  # friction takes a good share of the energy
    assert np.max(np.abs(bal - bal[0])) < 1e-9 * E["kinetic"][0]
    np.testing.assert_allclose(E["work_nc"], tau * (tr.q[:, 0] - 0.6) - W_f, rtol=0,
                               atol=1e-9 * E["kinetic"][0])
    lost = W_f[-1]
    # the friction power from the reactions and relative speeds, by hand
    f = tr.stats["variable_structure"]["forces"]
    xd = tr.xdot  # bodies crank, rod, slider
    th_d = xd[:, 2::3]
    w_rel = {"O": th_d[:, 0], "A": th_d[:, 1] - th_d[:, 0], "B": th_d[:, 2] - th_d[:, 1]}
    P = sum(0.1 * 0.01 * np.hypot(*f[n][:, :2].T) * np.abs(w_rel[n]) for n in ("O", "A", "B"))
    N, M = f["guide"][:, 1], f["guide"][:, 2]
    S = np.abs(N / 2 - M / 0.04) + np.abs(N / 2 + M / 0.04)
    P = P + 0.15 * S * np.abs(xd[:, 6])
    # Simpson's rule between the events (the kinks of |v| are there; an event is recorded
    # as two samples at the same time)
    cuts = [0, *np.flatnonzero(np.diff(tr.t) == 0) + 1, len(tr.t)]
    integral = sum(simpson(P[a:b], x=tr.t[a:b]) for a, b in zip(cuts[:-1], cuts[1:],
                                                                  strict=True))
    np.testing.assert_allclose(integral, lost, rtol=1e-6)  # Simpson: h^4 ~ 2e-7 here


# ----------------------------------------------------------------------------- surface
def test_friction_is_refused_where_it_is_not_modelled():
    mech = _block(0.5, 0.3)
    with pytest.raises(ModelError, match="guide"):
        mechdyn.simulate(mech, 0.1, q0=[0.0], qdot0=[0.0], backend="numba", progress=False)


def test_smoothed_friction_has_no_stick_slip_modes():
    a, mu, eps = 0.5, 0.3, 1e-3
    tr = mechdyn.simulate(_block(a, mu, smoothing=eps), 0.4, q0=[0.0], qdot0=[0.0],
                          t_eval=np.linspace(0.0, 0.4, 9), rtol=1e-11, progress=False)
    assert tr.status == "success", tr.message
    assert not tr.events
    v = tr.qdot[:, 0]
    acc = -G * np.sin(a) - mu * G * np.cos(a) * np.tanh(v / eps)
    np.testing.assert_allclose(tr.qddot[:, 0], acc, rtol=1e-10, atol=1e-12)
