"""Kinetostatics with friction in the pairs against closed forms (issue 12, item 2).

The mechanism: an offset slider-crank with massless links, crank O-A (radius r), rod
A-B (length l), slider B on the line y = e, turned at a constant speed omega; a process
force of constant magnitude P0 on the slider that resists its motion (-P0 sgn(v) along
x); Coulomb friction mu in the guide and a friction circle mu_O r_O at the crank pin O.

Closed form (free bodies; the rod is a two-force member since pins A and B are
frictionless).  u = (B - A) / l = (cos beta, sin beta) the rod direction, F_c the rod's
compression, v the slider's velocity.  Slider: along y, N + F_c u_y = 0; along x,
F_c u_x - mu |N| sgn(v) - P0 sgn(v) = 0.  With sgn(F_c) = sgn(v) (the rod pushes the
slider forwards and pulls it back),

    F_c = P0 sgn(v) / (u_x - mu |u_y|) = P0 sgn(v) cos(rho) / cos(|beta| + rho),

rho = atan(mu) the friction angle.  Crank (massless): the driving torque balances the
moment of the rod's force -F_c u at A and the pin friction mu_O r_O |R_O| against the
rotation, |R_O| = |F_c|:  T = F_c (A x u) + mu_O r_O |F_c| sgn(omega).

The mechanism locks where no F_c exists: u_x <= mu |u_y|, i.e. where the rod's force
falls inside the guide's friction cone (|beta| >= 90 deg - rho).
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.errors import Status
from mechdyn.kinetostatics.inverse import kinetostatics
from mechdyn.mechanism import Force

OMEGA = 10.0  # rad/s
P0 = 1000.0  # N


def slider_crank(r, l, e, mu, mu_o=0.0, r_o=0.0, guide_length=0.0, pin_a=(0.0, 0.0),
                 pin_b=(0.0, 0.0)):
    phi0 = 0.3
    A = r * np.array([np.cos(phi0), np.sin(phi0)])
    xb = A[0] + np.sqrt(l**2 - (e - A[1]) ** 2)
    m = md.Mechanism("slider-crank with friction")
    m.add_ground({"O": (0.0, 0.0), "G": (0.0, e)})
    m.add_body("crank", points={"A": (r, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("rod", points={"B": (l, 0.0)},
               pose=(A[0], A[1], np.arctan2(e - A[1], xb - A[0])))
    m.add_body("slider", pose=(xb, e, 0.0))
    m.add_revolute("O", "ground", "crank", "O", friction=mu_o, pin_radius=r_o)
    m.add_revolute("A", "crank", "rod", "A", friction=pin_a[0], pin_radius=pin_a[1])
    m.add_revolute("B", "rod", "slider", "B", friction=pin_b[0], pin_radius=pin_b[1])
    m.add_prismatic("guide", "ground", "slider", "G", (1.0, 0.0), friction=mu,
                    guide_length=guide_length)
    m.add_coordinate("phi", "angle", body="crank")
    # the process force: P0 against the slider's velocity (x rate of body 3)
    m.add(Force("process", "slider", (0.0, 0.0), lambda c: P0 * np.sign(c.xdot[..., 6]),
                (-1.0, 0.0)))
    return m


def closed_form(phi, r, l, e, mu, mu_o=0.0, r_o=0.0):
    A = r * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    h = np.sqrt(l**2 - (e - A[:, 1]) ** 2)
    u = np.stack([h, e - A[:, 1]], axis=-1) / l
    v = OMEGA * (-r * np.sin(phi) + (e - A[:, 1]) * r * np.cos(phi) / h)  # dx_B/dt
    den = u[:, 0] - mu * np.abs(u[:, 1])
    Fc = P0 * np.sign(v) / den
    T = Fc * (A[:, 0] * u[:, 1] - A[:, 1] * u[:, 0]) + mu_o * r_o * np.abs(Fc) * np.sign(OMEGA)
    N = -Fc * u[:, 1]
    return dict(T=T, Fc=Fc, u=u, v=v, N=N, locked=den <= 0,
                p_in=T * OMEGA, p_out=P0 * np.abs(v),
                loss_guide=mu * np.abs(N) * np.abs(v), loss_O=mu_o * r_o * np.abs(Fc) * OMEGA)


GEOM = dict(r=0.05, l=0.2, e=0.012, mu=0.2, mu_o=0.1, r_o=0.01)


@pytest.fixture(scope="module")
def run():
    phi = np.linspace(0.0, 2 * np.pi, 361)
    res = kinetostatics(slider_crank(**GEOM, guide_length=0.08), over="phi", speed=OMEGA,
                        values=phi)
    return res, closed_form(phi, **GEOM)


def test_driving_torque_and_reactions_against_the_friction_angle(run):
    res, cf = run
    assert np.abs(cf["v"]).min() > 1e-3  # no sample at a dead centre (sgn(v) defined)
    assert res.status == Status.SUCCESS and not res.locked.any()
    scale = np.abs(cf["T"]).max()
    assert np.abs(res.driving["phi"] - cf["T"]).max() < 1e-10 * scale
    # the rod force on the slider, and the guide's force on it: normal N and friction
    Fs = P0 * 10
    np.testing.assert_allclose(res.reactions["B"], cf["Fc"][:, None] * cf["u"], rtol=0,
                               atol=1e-10 * Fs)
    np.testing.assert_allclose(res.joint_frame["guide"][:, 1], cf["N"], rtol=0, atol=1e-10 * Fs)
    np.testing.assert_allclose(res.joint_frame["guide"][:, 0],
                               -GEOM["mu"] * np.abs(cf["N"]) * np.sign(cf["v"]), rtol=0,
                               atol=1e-10 * Fs)
    # the friction angle form of the rod force
    rho, beta = np.arctan(GEOM["mu"]), np.arctan2(cf["u"][:, 1], cf["u"][:, 0])
    np.testing.assert_allclose(np.abs(cf["Fc"]), P0 * np.cos(rho) / np.cos(np.abs(beta) + rho),
                               rtol=1e-12)


def test_losses_and_efficiency(run):
    res, cf = run
    P = np.abs(cf["p_in"]).max()
    np.testing.assert_allclose(res.losses["guide"], cf["loss_guide"], rtol=0, atol=1e-10 * P)
    np.testing.assert_allclose(res.losses["O"], cf["loss_O"], rtol=0, atol=1e-10 * P)
    np.testing.assert_allclose(res.power_out, cf["p_out"], rtol=0, atol=1e-10 * P)
    ok = cf["p_in"] > 0
    np.testing.assert_allclose(res.efficiency[ok], (cf["p_out"] / cf["p_in"])[ok], rtol=1e-9)
    df = res.to_dataframe()
    for col in ("P_loss_guide_W", "P_loss_O_W", "P_loss_W", "P_out_W", "efficiency"):
        assert col in df.columns
    assert "P_loss_A_W" not in df.columns  # a frictionless pair has no loss column


def test_cycle_efficiency_two_ways(run):
    res, cf = run
    e = res.energies()
    # way 1: output energy / input energy; way 2: 1 - losses / input (in = out + losses)
    eta1 = res.cycle_efficiency
    w_in = np.trapezoid(res.driving["phi"] * res.qdot[:, 0], res.t)
    w_loss = sum(np.trapezoid(p, res.t) for p in res.losses.values())
    eta2 = 1.0 - w_loss / w_in
    assert abs(eta1 - eta2) < 1e-12
    assert abs(e["input"] - (e["output"] + e["losses"])) < 1e-12 * e["input"]
    # and against the closed form's energies
    t = (res.values - res.values[0]) / OMEGA
    eta_cf = np.trapezoid(cf["p_out"], t) / np.trapezoid(cf["p_in"], t)
    assert abs(eta1 - eta_cf) < 1e-10
    assert 0.5 < eta1 < 1.0
    assert "cycle efficiency" in res.summary()


LOCK = dict(r=0.1, l=0.2, e=0.09, mu=0.5)


def test_self_locking_where_the_friction_cone_contains_the_rod_force():
    phi = np.deg2rad(np.arange(0.0, 360.0, 1.0))
    with pytest.warns(md.dynamics.reactions.KinetostaticsWarning, match="self-locking"):
        res = kinetostatics(slider_crank(**LOCK), over="phi", speed=OMEGA, values=phi)
    cf = closed_form(phi, **LOCK)
    # the closed form: locked where |u_y| > cos(rho), sin(phi) < (e - l cos(rho)) / r
    rho = np.arctan(LOCK["mu"])
    s = (LOCK["e"] - LOCK["l"] * np.cos(rho)) / LOCK["r"]
    lock_from, lock_to = np.pi - np.arcsin(s), 2 * np.pi + np.arcsin(s)
    assert np.rad2deg([lock_from, lock_to]) == pytest.approx([242.7296, 297.2704], abs=1e-4)
    expected = (phi > lock_from) & (phi < lock_to)
    np.testing.assert_array_equal(expected, cf["locked"])
    assert res.status == Status.SELF_LOCKING
    np.testing.assert_array_equal(res.locked, expected)
    assert np.isnan(res.driving["phi"][expected]).all()
    free = ~expected
    assert np.abs(res.driving["phi"][free] - cf["T"][free]).max() < 1e-9 * np.abs(
        cf["T"][free]).max()
    # reported with the crank angle: the first and last locked samples, 243 and 297 deg
    assert "phi = 243 .. 297 deg" in " ".join(res.warnings)
    assert "self-locked" in res.summary()


def test_without_friction_nothing_changes():
    res = kinetostatics(slider_crank(0.05, 0.2, 0.012, 0.0), over="phi", speed=OMEGA,
                        values=np.linspace(0.0, 2 * np.pi, 37))
    assert res.power_out is None and res.losses == {}
    assert "P_loss_W" not in res.to_dataframe().columns


def test_toggle_press_example_with_friction():
    """The bundled toggle press with friction in every pin and the ram guide: same motion
    and loads as the frictionless file; per pair, the loss is the law mu r |R| |w_rel|
    (pins) or mu S |v| (guide, with the edge loads of the reported normal force and
    moment); the energy balance over the cycle; the friction costs input energy."""
    from mechdyn import examples

    phi = np.linspace(0.0, 2 * np.pi, 361)
    w = 40 * 2 * np.pi / 60
    res = kinetostatics(examples.load("toggle_press_friction"), over="phi", speed=w, values=phi)
    ideal = kinetostatics(examples.load("toggle_press"), over="phi", speed=w, values=phi)
    assert res.status == Status.SUCCESS
    np.testing.assert_allclose(res.x, ideal.x, atol=1e-12)
    mech = res.model.mechanism
    body = {n: k for k, n in enumerate(res.model.body_names)}
    for j in "ABCDEF":
        jt = mech.joints[j]
        wc = _spin(res, body, jt.child) - _spin(res, body, jt.parent)
        law = jt.friction * jt.pin_radius * res.force_magnitude(j) * np.abs(wc)
        np.testing.assert_allclose(res.losses[j], law, rtol=1e-12, atol=1e-9)
    g = mech.joints["slide"]
    N, M = res.joint_frame["slide"][:, 1], res.moments["slide"]
    S = np.abs(N / 2 - M / g.guide_length) + np.abs(N / 2 + M / g.guide_length)
    v = res.xdot[:, 3 * body["slider"] + 1]  # the slide is vertical
    np.testing.assert_allclose(res.losses["slide"], g.friction * S * np.abs(v), rtol=1e-12,
                               atol=1e-9)
    np.testing.assert_allclose(res.joint_frame["slide"][:, 0], -g.friction * S * np.sign(v),
                               rtol=1e-12, atol=1e-9)
    # over the cycle: input = output + losses (+ the kinetic energy's change, ~0)
    e = res.energies()
    assert abs(e["input"] - e["output"] - e["losses"]) < 1e-10 * e["input"]
    assert 0.2 < res.cycle_efficiency < 0.6
    assert np.trapezoid(res.driving_total_power, res.t) > np.trapezoid(
        ideal.driving_total_power, ideal.t)


def _spin(res, body, name):
    """Angular velocity of a body (0 for the ground)."""
    return res.xdot[:, 3 * body[name] + 2] if name in body else np.zeros(res.n)


def test_friction_circles_in_every_pin():
    """Friction in pins O, A and B and in the guide: the rod is still a two-force member
    but its force line is tangent to the friction circles at A and B, so it makes an angle
    delta with the rod: moments about A on the massless rod,
    l (u x F) = M_fA - M_fB = |F| (rho_B s_B - rho_A s_A), so
    sin(delta) = sgn(F_c) (rho_B s_B - rho_A s_A) / l, with s_A = sgn(w_rod - omega),
    s_B = sgn(0 - w_rod) and rho = mu r_pin; the slider and crank as before, the crank
    also carrying -M_fA: T = A x F + rho_O |F| sgn(omega) - rho_A |F| s_A.  |R| is not
    linear in the multipliers, so Newton iterates here."""
    r, l, e, mu = 0.05, 0.2, 0.012, 0.2
    rho = {"O": 0.1 * 0.01, "A": 0.12 * 0.015, "B": 0.15 * 0.012}
    m = slider_crank(r, l, e, mu, mu_o=0.1, r_o=0.01, pin_a=(0.12, 0.015), pin_b=(0.15, 0.012))
    phi = np.deg2rad(np.arange(360.0) + 0.5)  # off 90 and 270 deg, where w_rod = 0
    res = kinetostatics(m, over="phi", speed=OMEGA, values=phi)
    assert res.status == Status.SUCCESS and res.stats["friction_iterations"] >= 2

    A = r * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    sin_t = (e - A[:, 1]) / l
    u = np.stack([np.sqrt(1 - sin_t**2), sin_t], axis=-1)
    w_rod = -r * np.cos(phi) * OMEGA / (l * u[:, 0])
    v = OMEGA * (-r * np.sin(phi) + r * np.cos(phi) * sin_t / u[:, 0])
    sA, sB = np.sign(w_rod - OMEGA), np.sign(-w_rod)
    best, found = np.full(phi.size, np.nan), np.zeros(phi.size, int)
    for sgn_f in (1.0, -1.0):  # the sign of the rod's compression consistent with the law
        d = np.arcsin(sgn_f * (rho["B"] * sB - rho["A"] * sA) / l)
        eF = np.stack([np.cos(d) * u[:, 0] - np.sin(d) * u[:, 1],
                       np.sin(d) * u[:, 0] + np.cos(d) * u[:, 1]], axis=-1)
        # slider: F_c eF_x - mu |F_c eF_y| sgn(v) - P0 sgn(v) = 0
        Fc = P0 * np.sign(v) / (eF[:, 0] - mu * np.abs(eF[:, 1]) * sgn_f * np.sign(v))
        F = Fc[:, None] * eF
        T = (A[:, 0] * F[:, 1] - A[:, 1] * F[:, 0]) + rho["O"] * np.abs(Fc) - rho["A"] * np.abs(
            Fc) * sA
        best = np.where(np.sign(Fc) == sgn_f, T, best)
        found += np.sign(Fc) == sgn_f
    assert (found == 1).all()  # one consistent solution at every position
    assert np.abs(res.driving["phi"] - best).max() < 1e-10 * np.abs(best).max()


def test_self_locking_toggle_position_driven_from_the_slider():
    """The centred slider-crank driven from the slider (a toggle near each dead centre)
    against a load torque Q0 resisting the crank's rotation, with the friction circle
    rho_O = mu_O r_O at the crank pin.  Massless crank: with c = A x u the arm of the rod's
    force about O, -F_c c - rho_O |F_c| sgn(w) - Q0 sgn(w) = 0 has a solution
    |F_c| = Q0 / (|c| - rho_O) only where |c| > rho_O: the mechanism locks where the rod's
    force line passes inside the pin's friction circle.  The drive force on the
    (frictionless) slider is P = -F_c u_x, F_c = -sgn(c w) |F_c|."""
    from mechdyn.mechanism import Torque

    r, l, mu_o, r_o, q0 = 0.05, 0.2, 0.3, 0.03, 50.0
    rho_o = mu_o * r_o
    phi0 = 4.0  # the lower half-turn: the slider moves +x while the crank turns CCW
    A0 = r * np.array([np.cos(phi0), np.sin(phi0)])
    xb0 = A0[0] + np.sqrt(l**2 - A0[1] ** 2)
    m = md.Mechanism("slider-driven slider-crank")
    m.add_body("crank", points={"A": (r, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("rod", points={"B": (l, 0.0)}, pose=(A0[0], A0[1], np.arctan2(-A0[1], xb0 - A0[0])))
    m.add_body("slider", pose=(xb0, 0.0, 0.0))
    m.add_revolute("O", "ground", "crank", friction=mu_o, pin_radius=r_o)
    m.add_revolute("A", "crank", "rod", "A")
    m.add_revolute("B", "rod", "slider", "B")
    m.add_prismatic("guide", "ground", "slider")
    m.add_coordinate("s", "travel", joint="guide")
    m.add(Torque("load", "crank", lambda c: -q0 * np.sign(c.xdot[..., 2])))
    s = np.linspace(l - r + 1e-4, l + r - 1e-4, 201)
    with pytest.warns(md.dynamics.reactions.KinetostaticsWarning, match="self-locking"):
        res = kinetostatics(m, over="s", speed=0.5, values=s)
    # the closed form on the lower branch
    phi = 2 * np.pi - np.arccos((s**2 + r**2 - l**2) / (2 * s * r))
    A = r * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    u = np.stack([s - A[:, 0], -A[:, 1]], axis=-1) / l
    c = A[:, 0] * u[:, 1] - A[:, 1] * u[:, 0]
    w = np.gradient(phi, s) * 0.5  # only its sign is used: CCW while s grows
    assert (w > 0).all()
    locked = np.abs(c) < rho_o
    assert locked[:2].all() and locked[-2:].all() and not locked[50:150].any()
    assert res.status == Status.SELF_LOCKING
    np.testing.assert_array_equal(res.locked, locked)
    Fc = -np.sign(c * w) * q0 / (np.abs(c) - rho_o)
    ok = ~locked
    P = -Fc * u[:, 0]
    assert np.abs(res.driving["s"][ok] - P[ok]).max() < 1e-10 * np.abs(P[ok]).max()
    # reported with the slider's travel where the friction circle starts to hold the
    # force (crank angle phi[k] there)
    k = int(np.flatnonzero(~locked)[-1]) + 1  # the first locked sample of the far end
    assert f"s = {s[k]:.6g} .. {s[-1]:.6g} m" in " ".join(res.warnings)
    np.testing.assert_allclose(res.x[:, 2] % (2 * np.pi), phi, atol=1e-9)


def test_statics_with_friction_says_that_friction_is_left_out():
    from mechdyn import examples

    phi = np.linspace(0.5, 1.0, 3)
    res = kinetostatics(examples.load("toggle_press_friction"), over="phi", speed=0.0,
                        values=phi)
    ideal = kinetostatics(examples.load("toggle_press"), over="phi", speed=0.0, values=phi)
    assert any(w.startswith("statics (speed 0) of a model with friction in joint(s) 'A'")
               and "'slide'" in w for w in res.warnings)
    np.testing.assert_allclose(res.driving["phi"], ideal.driving["phi"], rtol=1e-12)
    assert not any("friction" in w for w in ideal.warnings)
