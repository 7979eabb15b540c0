"""Compound pendulum: exact period (complete elliptic integral), closed-form motion
(Jacobi elliptic functions) and measured convergence orders.

Oracle: with J_O = J_c + m a^2, w0 = sqrt(m g a / J_O), k = sin(theta0 / 2),
the period is T = 4 K(k) / w0 and the angle from the downward vertical is
sin(phi / 2) = k sn(K - w0 t | k^2), phi' = -2 k w0 cn(K - w0 t | k^2)
(released from rest at phi = theta0).
"""

import numpy as np
import pytest
from dynamics_models import pendulum
from scipy.special import ellipj, ellipk

from mechdyn.integrate import Event
from mechdyn.simulate.run import simulate

M, A, JC, G = 2.0, 0.5, 0.05, 9.81
THETA0 = np.deg2rad(170.0)
JO = JC + M * A**2
W0 = np.sqrt(M * G * A / JO)
K = np.sin(THETA0 / 2)
KK = ellipk(K**2)
PERIOD = 4 * KK / W0


def exact(t, theta0=THETA0):
    """Body angle (from +x) and its rate at time t, released at rest from theta0."""
    k = np.sin(theta0 / 2)
    sn, cn, dn, _ = ellipj(ellipk(k**2) - W0 * np.asarray(t), k**2)
    phi = 2 * np.arcsin(k * sn)
    return phi - np.pi / 2, -2 * k * W0 * cn


def test_period_matches_elliptic_integral():
    # the angular velocity turns from negative to positive once per period, at the far end
    ev = Event(lambda t, q, v: v[0], "reversal", direction=1)
    tr = simulate(pendulum(), 1.2 * PERIOD, rtol=1e-13, atol=1e-15, events=[ev])
    assert tr.success, tr.message
    # released at rest at the +170 deg end: v goes negative, rises through 0 at T/2
    times = [e.t for e in tr.events]
    assert len(times) == 1
    assert 2 * times[0] == pytest.approx(PERIOD, rel=1e-9)
    # and with the other direction: the return to the start after a full period
    ev2 = Event(lambda t, q, v: v[0], "back", direction=-1)
    tr2 = simulate(pendulum(), 1.2 * PERIOD, rtol=1e-13, atol=1e-15, events=[ev2])
    assert [e.t for e in tr2.events][0] == pytest.approx(PERIOD, rel=1e-9)


def test_motion_matches_jacobi_closed_form():
    te = np.linspace(0.0, PERIOD, 25)
    tr = simulate(pendulum(), PERIOD, rtol=1e-12, atol=1e-14, t_eval=te)
    th, w = exact(te)
    np.testing.assert_allclose(tr.q[:, 0], th, atol=1e-9)
    np.testing.assert_allclose(tr.qdot[:, 0], w, atol=1e-8 * W0)
    # T + U conserved (no non-conservative forces)
    assert tr.energy_drift() < 1e-10 * np.max(tr.energy["kinetic"])


@pytest.mark.parametrize("integrator, order", [("rk4", 4), ("wilson", 2)])
def test_measured_order_on_pendulum(integrator, order):
    # 60 deg amplitude: released from 170 deg the motion lingers near the unstable top and
    # the errors are not yet asymptotic at practical step sizes
    t_end = 2.0
    ns = np.array([50, 100, 200, 400])
    th_ref, w_ref = exact(t_end, np.deg2rad(60.0))
    errs = []
    for n in ns:
        tr = simulate(pendulum(60.0), t_end, integrator=integrator, steps=int(n))
        assert tr.success
        errs.append(abs(tr.q[-1, 0] - th_ref) + abs(tr.qdot[-1, 0] - w_ref) / W0)
    slope = np.polyfit(np.log(t_end / ns), np.log(errs), 1)[0]
    assert slope == pytest.approx(order, abs=0.15)
