"""The frame loads of the switched press cycle against the momentum balance, and their spectra.

Newton's second law for all the moving bodies of the press together: the rate of
change of their momentum P = sum m v_c equals the external forces on them -- the
weights, the force loads that no element anchors on the frame (ram springs, cylinder,
punch) and what the frame applies.  So the frame receives

    F_frame = -dP/dt + sum m g + F_ext,
    M_frame = -dH/dt + sum (r_c - R) x (m g + F_ext)        (about the point R),

with H = sum J_c omega + (r_c - R) x m v_c.  The motor's stator reaction, the piston's
return spring and the return cylinder (rocker on ram) are internal to machine + frame
and drop out.  Here dP/dt and dH/dt come from the recorded body accelerations, the
loads from their tables evaluated in this file, and the frame load of the run from
another road: the multipliers of the grounded joints, stops and contacts (issue 11,
"frame loads from every run").  Across an impact the momentum jumps by the impulse the
frame gives, minus the impulse it receives (``impulses["frame"]`` of the event).

The spectra (:mod:`mechdyn.results.spectrum`): the ram axis is x, so Fx carries the
machine's vertical load, with one work stroke every third turn; the lock acts across
the ram axis, and its engagement and release step Fy.
"""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.signal import find_peaks

import mechdyn as md
from mechdyn.mechanism.load import Force
from mechdyn.model.forces import com_arms
from mechdyn.results import spectrum as sp

T_END = 1.5  # s: three and a half work cycles (one every third turn, ~0.42 s)
POINT = np.array([-0.5, 0.1])  # m: the reference point of the frame moment


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@pytest.fixture(scope="module")
def run():
    mech = md.examples.load("press_cycle")
    model = mech.compile()
    tr = md.simulate(model, T_END, rtol=1e-9, dt_out=1e-4, point=POINT, progress=False)
    assert tr.status == "success", tr.message
    return mech, model, tr


def _motion(model, tr):
    """Centres of mass r_c, their velocities and accelerations (n, nb, 2), the angular
    velocities and accelerations (n, nb), from the recorded body frames."""
    nb = model.n_bodies
    arm = com_arms(model, tr.x)
    perp = np.stack([-arm[..., 1], arm[..., 0]], axis=-1)
    xd = tr.xdot.reshape(-1, nb, 3)
    acc = tr.xddot().reshape(-1, nb, 3)
    w, al = xd[..., 2], acc[..., 2]
    rc = tr.x.reshape(-1, nb, 3)[..., :2] + arm
    vc = xd[..., :2] + w[..., None] * perp
    ac = acc[..., :2] + al[..., None] * perp - (w**2)[..., None] * arm
    return rc, vc, ac, w, al


def _table(tab, s):
    """A load table at the values s of its variable: linear, periodic, outside value."""
    s = np.asarray(s, float)
    if tab.period:
        s = tab.x[0] + np.mod(s - tab.x[0], tab.period)
    v = np.interp(s, tab.x, tab.y)
    if tab.outside is not None:
        v = np.where((s < tab.x[0]) | (s > tab.x[-1]), tab.outside, v)
    return v


def _external(mech, model, tr, rc):
    """Weights plus the force loads at the centres of mass, ground-fixed directions,
    per body (n, nb, 2), N."""
    names = list(model.body_names)
    F = np.broadcast_to(model.mass[:, None] * np.asarray(model.gravity), rc.shape).copy()
    forces = [ld for ld in mech.loads if isinstance(ld, Force)]
    assert {ld.name for ld in forces} == {"ram_springs", "cylinder_force", "punch"}
    for ld in forces:
        assert ld.point == "com" and ld.frame == "ground"
        var = ld.magnitude.variable
        if var in model.coordinate_names:
            s = tr.q[:, list(model.coordinate_names).index(var)]
        elif var == "joint:guide":  # the ram's travel on its guide: along x from O (the origin)
            s = tr.x[:, 3 * names.index("slider")]
        else:
            body, _, axis = var.split(".")
            s = rc[:, names.index(body), "xy".index(axis)]
        F[:, names.index(ld.body)] += _table(ld.magnitude, s)[:, None] * np.asarray(
            ld.direction)
    return F


def _balance(run):
    """(frame force, frame moment) of the run and of the momentum balance."""
    mech, model, tr = run
    rc, vc, ac, w, al = _motion(model, tr)
    F = _external(mech, model, tr, rc)
    m = model.mass
    f_bal = -np.einsum("b,nbk->nk", m, ac) + F.sum(axis=1)
    m_bal = (-(al @ model.inertia) - np.einsum("b,nb->n", m, _cross(rc - POINT, ac))
             + _cross(rc - POINT, F).sum(axis=1))
    vs = tr.stats["variable_structure"]
    return vs.frame_force, vs.frame_moment, f_bal, m_bal


def test_between_events_the_frame_load_balances_the_momentum_of_the_mechanism(run):
    frame, moment, f_bal, m_bal = _balance(run)
    # measured: 5e-16 of the largest force (89 kN), 2e-14 of the largest moment
    np.testing.assert_allclose(frame, f_bal, rtol=0, atol=1e-10 * np.abs(frame).max())
    np.testing.assert_allclose(moment, m_bal, rtol=0, atol=1e-10 * np.abs(moment).max())


def test_the_recorded_momentum_is_the_time_integral_of_the_loads(run):
    """The same balance in integral form, without accelerations: P(t) - P(t_a) =
    integral of (external forces - frame force) over each segment between events, by
    the trapezoidal rule on the 0.1 ms samples (its error, not the integrator's, sets
    the tolerance: the punch table rises 15 kN within 0.1 mm of ram travel)."""
    mech, model, tr = run
    rc, vc, _, _, _ = _motion(model, tr)
    rate = _external(mech, model, tr, rc).sum(axis=1) - tr.stats["variable_structure"].frame_force
    P = np.einsum("b,nbk->nk", model.mass, vc)
    cuts = np.flatnonzero(np.diff(tr.t) == 0.0) + 1  # samples before and after each event
    bounds = np.r_[0, cuts, tr.t.size]
    worst = 0.0
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        if b - a < 4:
            continue
        integral = cumulative_trapezoid(rate[a:b], tr.t[a:b], axis=0, initial=0.0)
        scale = np.trapezoid(np.abs(rate[a:b]), tr.t[a:b], axis=0).max()
        worst = max(worst, np.abs(P[a:b] - P[a] - integral).max() / scale)
    assert worst < 3e-3  # measured 1.2e-3


def test_at_impacts_the_momentum_jumps_by_minus_the_impulse_on_the_frame(run):
    _, model, tr = run
    rc, vc, _, w, _ = _motion(model, tr)
    P = np.einsum("b,nbk->nk", model.mass, vc)
    H = w @ model.inertia + np.einsum("b,nb->n", model.mass, _cross(rc - POINT, vc))
    checked, kinds = 0, set()
    for t_ev in sorted({ev.t for ev in tr.events}):
        at = [ev for ev in tr.events if ev.t == t_ev]
        idx = np.flatnonzero(tr.t == t_ev)
        if idx.size < 2:
            continue
        before, after = idx[0], idx[-1]
        dP, dH = P[after] - P[before], H[after] - H[before]
        with_impulse = [ev for ev in at if "frame" in ev.impulses]
        if not with_impulse:  # releases, separations: no jump
            np.testing.assert_allclose(dP, 0.0, rtol=0, atol=1e-9)
            assert abs(dH) < 1e-9
            continue
        imp = with_impulse[0].impulses["frame"]
        scale = max(np.abs(dP).max(), 1.0)
        np.testing.assert_allclose(dP, -imp[:2], rtol=0, atol=1e-12 * scale)
        assert dH == pytest.approx(-imp[2], rel=0, abs=1e-11 * scale)
        checked += 1
        kinds |= {(ev.kind, ev.element.split("@")[0]) for ev in with_impulse}
    # the lock's engagement, the ram on its stop, the piston on its stops and on the ram
    assert {("engage", "rocker_lock"), ("impact", "ram_stop"), ("impact", "piston_stops"),
            ("impact", "piston_on_ram")} <= kinds
    assert checked >= 40
    assert any(ev.kind == "release" for ev in tr.events)


def _crank_frequency(model, tr):
    phi = tr.q[:, list(model.coordinate_names).index("phi")]
    return (phi[-1] - phi[0]) / (tr.t[-1] - tr.t[0]) / (2.0 * np.pi), phi


def test_the_frame_load_spectrum_shows_the_crank_and_the_work_cycle(run):
    _, model, tr = run
    f_crank, phi = _crank_frequency(model, tr)  # 7.11 Hz
    resolution = 1.0 / T_END
    t, fx = sp.history(tr, "Fx_frame_N")
    _, fy = sp.history(tr, "Fy_frame_N")
    # the vertical load: one work stroke every third turn, its harmonics
    top = sp.dominant(t, fx, 3)
    assert top["f_Hz"][0] == pytest.approx(f_crank / 3.0, abs=resolution)  # 2.371 Hz
    cycles = top["f_Hz"] / (f_crank / 3.0)
    np.testing.assert_allclose(cycles, np.round(cycles), atol=resolution / (f_crank / 3.0))
    peak = sp.spectrum(t, fx, window="hann")
    assert peak["f_Hz"][peak["amplitude"][1:].idxmax()] == pytest.approx(f_crank / 3.0,
                                                                         abs=resolution)
    three_turns = sp.order_spectrum(phi, fx, period=6.0 * np.pi, orders=9)
    assert three_turns["amplitude"][1:].idxmax() == 1
    # across the ram axis: the crank's turn (order 3 of the three-turn cycle)
    three_turns = sp.order_spectrum(phi, fy, period=6.0 * np.pi, orders=9)
    assert three_turns["amplitude"][1:].idxmax() == 3
    # its strongest components are crank orders, the first among them (measured: orders
    # 1, 4 and 5 with 472, 466 and 369 N: orders 1 and 4 are nearly equal)
    orders = sp.dominant(t, fy, 3)["f_Hz"] / f_crank
    np.testing.assert_allclose(orders, np.round(orders), atol=resolution / f_crank)
    assert 1.0 in np.round(orders).tolist()


def test_the_spectrogram_marks_the_lock_engagements_and_releases(run):
    """Broadband energy (the spectrogram above 200 Hz, far above the crank orders): the
    engagement (a plastic impact) and the release (a step of the lock's force) of the
    rocker lock stand out in Fy within one window, and every burst of Fx or Fy lies
    within one window of an event of the run."""
    _, _, tr = run
    segment = 0.01  # s
    events = np.array(sorted({ev.t for ev in tr.events}))
    lock = [ev.t for ev in tr.events if ev.element == "rocker_lock"]
    assert len(lock) == 7  # four engagements, three releases
    for column in ("Fx_frame_N", "Fy_frame_N"):
        f, tc, amp = sp.spectrogram(*sp.history(tr, column), segment=segment)
        broad = amp[f > 200.0].sum(axis=0)
        peaks, _ = find_peaks(broad, height=0.05 * broad.max())
        for p in peaks:
            assert np.min(np.abs(events - tc[p])) <= segment, (column, tc[p])
        if column == "Fy_frame_N":
            for t_ev in lock:
                near = np.abs(tc - t_ev) <= segment
                around = (np.abs(tc - t_ev) > 2 * segment) & (np.abs(tc - t_ev) < 6 * segment)
                assert np.isin(np.flatnonzero(near), peaks).any(), t_ev
                # measured: 180 to 1000 times the level around
                assert broad[near].max() > 20.0 * np.median(broad[around])
