"""The supports of a machine against closed forms (issue 11, item 3).

Rigid frame: a rotating unbalance on two bolts, split by statics; any load on any
supports adds back up to the load.  Elastic mounting: natural frequencies of a rigid
body on springs, the 1-DOF transmissibility (Den Hartog, Mechanical Vibrations, ch. 3)
and the coupled sliding-rocking response written out by hand; the time response at
steady state against the frequency response.  A real run through support_loads.
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.foundation import (
    AnchorBolt,
    Foundation,
    Isolator,
    distribute,
    excitation_warnings,
    frame_loads,
    mounted_response,
    natural_frequencies,
    support_loads,
    transmissibility,
)

A, H = 0.4, 0.3  # half-distance of the bolts, height of the rotor axis, m
P = 20e3  # preload, N


def _two_bolts(**kw):
    return Foundation([AnchorBolt("left", -A, 0.0, 2e8, 1e8, preload=P, **kw),
                       AnchorBolt("right", A, 0.0, 2e8, 1e8, preload=P, **kw)])


def test_rotating_unbalance_on_two_bolts_is_split_by_statics():
    m, e, w = 5.0, 0.02, 2 * np.pi * 25.0  # 5 kg at 20 mm, 1500 rpm: m e w^2 = 2.47 kN
    F0 = m * e * w**2
    t = np.linspace(0.0, 0.08, 4001)
    Fx, Fy = F0 * np.cos(w * t), F0 * np.sin(w * t)  # on the frame, at the bearing (0, H)
    M = -H * Fx  # about the origin, between the bolts at floor level
    s = distribute(_two_bolts(), Fx, Fy, M, t=t)
    # statics of a symmetric pair: shear halves, axial = Fy/2 -/+ M/(2a) (left/right)
    for name, sign in (("left", -1.0), ("right", 1.0)):
        axial = Fy / 2 + sign * M / (2 * A)
        np.testing.assert_allclose(s.fx[name], Fx / 2, rtol=0, atol=1e-9 * F0)
        np.testing.assert_allclose(s.fy[name], axial, rtol=0, atol=1e-9 * F0)
        np.testing.assert_allclose(s.tension[name], P + np.maximum(axial, 0), rtol=0,
                                   atol=1e-9 * F0)
        np.testing.assert_allclose(s.clamp[name], P - axial, rtol=0, atol=1e-9 * F0)
    assert s.first_opening is None  # 2.47 kN cannot open a 20 kN joint


def test_first_bolt_to_open_and_its_time_by_statics():
    w, F0 = 2 * np.pi * 25.0, 45e3
    t = np.linspace(0.0, 0.04, 40001)
    Fx, Fy = F0 * np.cos(w * t), F0 * np.sin(w * t)
    s = distribute(_two_bolts(), Fx, Fy, -H * Fx, t=t)
    # left clamp P - F0/2 (sin wt + (H/A) cos wt) = P - amp sin(wt + phase): closed at
    # t = 0, zero first at wt = asin(P/amp) - phase; the right one follows at + 2 phase
    amp, phase = F0 / 2 * np.hypot(1, H / A), np.arctan2(H / A, 1.0)
    assert s.clamp["left"][0] > 0
    t_open = (np.arcsin(P / amp) - phase) / w
    name, when = s.first_opening
    assert name == "left"
    assert abs(when - t_open) < 1e-9
    row = s.peaks()["right"]
    assert row["clamp_min_N"] == pytest.approx(P - amp, rel=1e-6)
    df = s.to_dataframe()
    assert {"N_right_N", "V_right_N", "clamp_right_N", "Fy_base_N"} <= set(df.columns)


def test_bolt_with_a_load_factor_is_in_equilibrium_and_opens_later():
    s = distribute(_two_bolts(load_factor=0.2), [0.0, 0.0], [0.0, 2 * 20e3 / 0.8], [0.0, 0.0])
    share = s.fy["left"]
    # tension = clamp + share (equilibrium of the joint) while closed; opens at P/(1-Phi)
    np.testing.assert_allclose(s.tension["left"], s.clamp["left"] + share, atol=1e-6)
    assert s.clamp["left"][-1] == pytest.approx(0.0, abs=1e-6)


def test_the_weight_of_the_base_presses_on_the_bolts():
    f = Foundation(_two_bolts().supports, mass=1000.0, inertia=80.0, com=(0.1, 0.5))
    s = distribute(f, [0.0], [0.0], [0.0], gravity=(0.0, -9.81))
    W = 1000.0 * 9.81
    # the weight at x = 0.1 on bolts at -/+0.4: levers 0.5 and 0.3 of 0.8
    assert s.fy["left"][0] == pytest.approx(-W * 0.3 / 0.8, rel=1e-12)
    assert s.fy["right"][0] == pytest.approx(-W * 0.5 / 0.8, rel=1e-12)
    assert s.clamp["right"][0] == pytest.approx(P + W * 0.5 / 0.8, rel=1e-12)


def test_support_forces_add_up_to_the_load():
    rng = np.random.default_rng(7)
    f = Foundation([AnchorBolt("b1", -0.7, 0.05, 3e8, 1e8, preload=1e4),
                    AnchorBolt("b2", 0.6, -0.02, 2e8, 2e8),
                    Isolator("i1", 0.1, 0.3, 4e6, 9e6, cy=1e3),
                    Isolator("i2", 1.3, 0.0, 1e6, 5e6)])
    F = rng.normal(scale=1e4, size=(200, 3))
    point = (0.35, 0.8)
    s = distribute(f, *F.T, point=point)
    fx = np.array([s.fx[n] for n in f.names])
    fy = np.array([s.fy[n] for n in f.names])
    xs = np.array([[sp.x - point[0], sp.y - point[1]] for sp in f.supports])
    moment = (xs[:, 0, None] * fy - xs[:, 1, None] * fx).sum(axis=0)
    scale = np.max(np.abs(F))
    np.testing.assert_allclose(fx.sum(axis=0), F[:, 0], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(fy.sum(axis=0), F[:, 1], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(moment, F[:, 2], rtol=0, atol=1e-12 * scale)


def _isolated(h=0.0, a=0.5, kx=1e5, ky=4e5, cx=0.0, cy=0.0, m=200.0, J=25.0):
    """Two equal isolators at x = -/+a, h below the centre of mass at (0.2, 0.5)."""
    c = (0.2, 0.5)
    return Foundation([Isolator("L", c[0] - a, c[1] - h, kx, ky, cx, cy),
                       Isolator("R", c[0] + a, c[1] - h, kx, ky, cx, cy)],
                      mass=m, inertia=J, com=c)


def test_natural_frequencies_of_a_rigid_body_on_springs():
    m, J, a, kx, ky = 200.0, 25.0, 0.5, 1e5, 4e5
    modes = natural_frequencies(_isolated())
    expected = np.sort([np.sqrt(2 * kx / m), np.sqrt(2 * ky / m), np.sqrt(2 * ky * a**2 / J)])
    np.testing.assert_allclose(modes.omega, expected, rtol=1e-12)
    np.testing.assert_allclose(modes.frequencies, expected / (2 * np.pi), rtol=1e-12)
    # mounts h below the centre of mass: sliding and rocking couple, a quadratic in w^2
    h = 0.3
    kxx, kxt, ktt = 2 * kx, 2 * kx * h, 2 * kx * h**2 + 2 * ky * a**2
    b, c = -(m * ktt + J * kxx), kxx * ktt - kxt**2
    roots = np.sort((-b + np.array([-1, 1]) * np.sqrt(b**2 - 4 * m * J * c)) / (2 * m * J))
    coupled = np.sort(np.concatenate([np.sqrt(roots), [np.sqrt(2 * ky / m)]]))
    np.testing.assert_allclose(natural_frequencies(_isolated(h=h)).omega, coupled, rtol=1e-12)


def test_transmissibility_of_a_symmetric_pair_is_the_one_dof_closed_form():
    m, ky, cy = 200.0, 4e5, 900.0
    f = _isolated(ky=ky, cy=cy, cx=300.0, h=0.25)
    wn, zeta = np.sqrt(2 * ky / m), 2 * cy / (2 * np.sqrt(2 * ky * m))
    r = np.concatenate([np.linspace(0.05, 5.0, 397), [1.0, np.sqrt(2.0)]])
    closed = np.sqrt(1 + (2 * zeta * r)**2) / np.sqrt((1 - r**2)**2 + (2 * zeta * r)**2)
    T = transmissibility(f, r * wn, "y")
    np.testing.assert_allclose(np.abs(T), closed, rtol=1e-6)
    assert abs(T[-1]) == pytest.approx(1.0, rel=1e-9)  # every curve passes 1 at r = sqrt 2


def test_coupled_sliding_rocking_transmissibility_written_out():
    m, J, a, h, kx, ky = 200.0, 25.0, 0.5, 0.3, 1e5, 4e5
    f = _isolated(h=h)
    w = np.linspace(1.0, 150.0, 301)
    # horizontal unit force at the centre of mass; undamped (x, theta) by Cramer's rule
    kxx, kxt, ktt = 2 * kx, 2 * kx * h, 2 * kx * h**2 + 2 * ky * a**2
    det = (kxx - m * w**2) * (ktt - J * w**2) - kxt**2
    x, th = (ktt - J * w**2) / det, -kxt / det
    Fx_floor = kxx * x + kxt * th
    got = transmissibility(f, w, "x")
    np.testing.assert_allclose(got.real, Fx_floor, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(got.imag, 0.0, atol=1e-9)
    # the moment about the centre of mass the floor receives, from the whole resultant
    R = transmissibility(f, w, "x", resultant=True)
    np.testing.assert_allclose(R[:, 2].real, kxt * x + ktt * th, rtol=1e-6, atol=1e-9)


def test_time_response_reaches_the_frequency_response():
    f = _isolated(h=0.3, cx=800.0, cy=900.0)
    w = 1.3 * natural_frequencies(f).omega[1]
    e = np.array([0.6, 0.8, 0.05])
    period = 2 * np.pi / w
    t = np.linspace(0.0, 400 * period, 400 * 400 + 1)
    load = np.outer(np.sin(w * t), e)
    point = (0.9, 1.1)
    r = mounted_response(f, t, *load.T, point=point, start="rest")
    last = t > t[-1] - 20 * period
    basis = np.column_stack([np.sin(w * t[last]), np.cos(w * t[last])])
    coef = np.linalg.lstsq(basis, r.floor[last], rcond=None)[0]
    # the load is taken linear between samples: its fundamental is sinc^2(w dt / 2) of sin
    hold = np.sinc(w * (t[1] - t[0]) / (2 * np.pi))**2
    expected = transmissibility(f, w, e, point=point, resultant=True) * np.linalg.norm(e)
    # a load sin(wt) gives Re(T) sin(wt) + Im(T) cos(wt)
    np.testing.assert_allclose(coef[0], hold * expected.real, rtol=0, atol=1e-8)
    np.testing.assert_allclose(coef[1], hold * expected.imag, rtol=0, atol=1e-8)
    total = np.sum(list(r.supports.values()), axis=0)
    np.testing.assert_allclose(total, r.floor[:, :2], rtol=0, atol=1e-9)


def test_excitation_orders_near_a_natural_frequency_are_named():
    f = _isolated()
    fn = natural_frequencies(f).frequencies
    warnings = excitation_warnings(f, 60.0 * fn[1] / 2 * 1.1)  # order 2 at 0.909 fn
    assert any(w.mode == 1 and w.order == 2 for w in warnings)
    assert excitation_warnings(f, 60.0 * fn[0] / 10) == []  # orders 0.1 .. 0.4 of fn[0]


def test_a_real_run_through_support_loads():
    point = (0.05, -0.02)
    tr = md.simulate(md.examples.load("slider_crank"), 0.05, t_eval=np.linspace(0, 0.05, 51),
                     progress=False, point=point)
    assert tr.success, tr.message
    f = Foundation([AnchorBolt("b1", -0.3, -0.1, 2e8, 1e8, preload=5e3),
                    AnchorBolt("b2", 0.4, -0.1, 2e8, 1e8, preload=5e3),
                    Isolator("pad", 0.1, -0.1, 1e7, 5e7)])
    s = support_loads(f, tr, point=point)
    h = frame_loads(tr, point)
    np.testing.assert_allclose(s.t, tr.t)
    fx = sum(s.fx.values())
    fy = sum(s.fy.values())
    moment = sum((sp.x - point[0]) * s.fy[sp.name] - (sp.y - point[1]) * s.fx[sp.name]
                 for sp in f.supports)
    scale = np.max(np.abs([h.Fx, h.Fy]))
    np.testing.assert_allclose(fx, h.Fx, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(fy, h.Fy, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(moment, h.M, rtol=0, atol=1e-12 * scale)
    df = tr.to_dataframe()
    np.testing.assert_allclose(h.Fy, df["Fy_frame_N"])
    assert np.ptp(h.Fy) > 0  # the run does load its frame


def test_a_kinetostatics_record_brings_its_own_point():
    point = (0.2, 0.1)
    model = md.examples.load("slider_crank").compile()
    tr = md.simulate(model, 0.02, t_eval=np.linspace(0, 0.02, 21), progress=False)
    ks = md.kinetostatics(model, trajectory=tr, point=point)
    f = _two_bolts()
    s = support_loads(f, ks)  # the moment about ks.frame_point, taken from the record
    np.testing.assert_allclose(s.point, point)
    moment = sum((sp.x - point[0]) * s.fy[sp.name] - (sp.y - point[1]) * s.fx[sp.name]
                 for sp in f.supports)
    np.testing.assert_allclose(moment, ks.frame_moment, rtol=0,
                               atol=1e-12 * np.max(np.abs(ks.frame_force)))
    # the same loads as from the run's own frame columns about the origin
    about_origin = support_loads(f, tr)
    for name in f.names:
        np.testing.assert_allclose(s.fy[name], about_origin.fy[name], rtol=1e-9, atol=1e-6)
