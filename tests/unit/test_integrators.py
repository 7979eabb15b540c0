"""Integrators of q'' = f(t, q, q'): orders, tolerances, events, dense output, options.

Oracles: the harmonic oscillator q = cos(w t) and closed-form quadratures.
"""

import numpy as np
import pytest

from mechdyn.integrate import (
    INTEGRATORS,
    AdaptiveIntegrator,
    Event,
    IntegratorOptionError,
    ScipyIntegrator,
    make_integrator,
    solve,
)
from mechdyn.integrate.base import hermite_dense
from mechdyn.integrate.compiled_dop853 import DOP853
from mechdyn.integrate.driver import segment_integrators

W = 2.0  # rad/s


def oscillator(t, q, v):
    return -W * W * q


def measured_order(hs, errs):
    """Slope of log(error) against log(h), by least squares (as diffrax's test_ode_order)."""
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


@pytest.mark.parametrize("name, order", [("rk4", 4), ("wilson", 2)])
def test_fixed_step_order(name, order):
    t_end = 3.0
    ns = np.array([40, 80, 160, 320])
    errs = []
    for n in ns:
        s = solve(name, oscillator, 0.0, [1.0], [0.0], t_end, steps=int(n))
        errs.append(abs(s.q[-1, 0] - np.cos(W * t_end)) + abs(s.qdot[-1, 0]
                                                               + W * np.sin(W * t_end)))
    assert measured_order(t_end / ns, errs) == pytest.approx(order, abs=0.15)


def test_wilson_theta_converges_second_order():
    t_end = 3.0
    ns = np.array([80, 160, 320, 640])
    errs = [abs(solve("wilson", oscillator, 0.0, [1.0], [0.0], t_end, steps=int(n),
                      theta=1.4).q[-1, 0] - np.cos(W * t_end)) for n in ns]
    assert measured_order(t_end / ns, errs) == pytest.approx(2.0, abs=0.2)


def test_wilson_counts_evaluations():
    integ = make_integrator("wilson", steps=10, iterations=3, tol=None)
    s = solve(integ, oscillator, 0.0, [1.0], [0.0], 1.0)
    # one evaluation at the start, then per step 3 corrector passes + 1 at the step end
    assert s.stats["evaluations"] == 1 + 10 * 4
    assert s.stats["steps"] == 10


def test_rk4_counts_evaluations():
    s = solve("rk4", oscillator, 0.0, [1.0], [0.0], 1.0, steps=25)
    assert s.stats["evaluations"] == 1 + 25 * 4


@pytest.mark.parametrize("method", ["dop853", "rk45", "radau", "lsoda", "bdf"])
def test_adaptive_meets_tolerance(method):
    rtol = 1e-10 if method == "dop853" else 1e-8
    s = solve(method, oscillator, 0.0, [1.0], [0.0], 2.0, rtol=rtol, atol=rtol * 1e-2)
    err = abs(s.q[-1, 0] - np.cos(W * 2.0))
    assert err < 200 * rtol
    assert s.stats["evaluations"] > 0 and s.stats["steps"] > 0


def test_dense_output_at_t_eval():
    te = np.linspace(0.0, 2.0, 37)
    s = solve("dop853", oscillator, 0.0, [1.0], [0.0], 2.0, t_eval=te, rtol=1e-12,
              atol=1e-14)
    np.testing.assert_allclose(s.t, te)
    np.testing.assert_allclose(s.q[:, 0], np.cos(W * te), atol=1e-10)
    np.testing.assert_allclose(s.qdot[:, 0], -W * np.sin(W * te), atol=1e-9)
    np.testing.assert_allclose(s.qddot[:, 0], -W * W * np.cos(W * te), atol=1e-9)


@pytest.mark.parametrize("name, opts, tol", [("dop853", {"rtol": 1e-12, "atol": 1e-14}, 1e-10),
                                             ("rk4", {"steps": 400}, 1e-7)])
def test_event_locates_velocity_reversal(name, opts, tol):
    # q' = -W sin(W t) crosses zero upwards at t = pi / W (half a period)
    ev = Event(lambda t, q, v: v[0], "reversal", direction=1, terminal=True)
    s = solve(name, oscillator, 0.0, [1.0], [0.0], 5.0, events=[ev], **opts)
    assert s.status == "event"
    assert len(s.events) == 1
    assert s.events[0].t == pytest.approx(np.pi / W, abs=tol)
    assert s.t[-1] == pytest.approx(np.pi / W, abs=tol)


def test_quadrature_state_is_integrated():
    # w' = q'^2 with q = cos(W t): w(T) = W^2 (T/2 - sin(2 W T) / (4 W))
    def f(t, q, v):
        return -W * W * q, np.array([v[0] ** 2])

    T = 1.3
    exact = W * W * (T / 2 - np.sin(2 * W * T) / (4 * W))
    for name, opts, tol in (("dop853", {"rtol": 1e-12, "atol": 1e-14}, 1e-10),
                            ("rk4", {"steps": 200}, 1e-7), ("wilson", {"steps": 2000}, 1e-5)):
        s = solve(name, f, 0.0, [1.0], [0.0], T, w0=[0.0], **opts)
        assert s.w[-1, 0] == pytest.approx(exact, abs=tol), name


def test_hermite_dense_orders():
    f = np.sin
    errs_q, errs_v = [], []
    hs = np.array([0.2, 0.1, 0.05])
    for h in hs:
        t0, t1 = 0.3, 0.3 + h
        d = hermite_dense(t0, [f(t0)], [np.cos(t0)], [-f(t0)], [0.0], [0.0],
                          t1, [f(t1)], [np.cos(t1)], [-f(t1)], [0.0], [0.0])
        s = t0 + 0.37 * h
        q, v, _ = d(s)
        errs_q.append(abs(q[0] - f(s)))
        errs_v.append(abs(v[0] - np.cos(s)))
    assert measured_order(hs, errs_q) == pytest.approx(6, abs=0.3)
    assert measured_order(hs, errs_v) == pytest.approx(5, abs=0.3)


# ---------------------------------------------------------------- bad options
def test_unknown_integrator_lists_valid_names():
    with pytest.raises(IntegratorOptionError, match="valid integrator names: wilson, rk4"):
        make_integrator("euler")
    assert isinstance(IntegratorOptionError("x"), ValueError)


@pytest.mark.parametrize("kwargs, match", [
    ({"name": "wilson", "steps": 0}, "`steps`"),
    ({"name": "rk4", "steps": -3}, "`steps`"),
    ({"name": "wilson", "steps": 2.5}, "`steps`"),
    ({"name": "wilson", "dt": -1e-3}, "`dt`"),
    ({"name": "wilson", "theta": 1.2}, "`theta`"),
    ({"name": "dop853", "rtol": 0.0}, "`rtol`"),
    ({"name": "radau", "rtol": -1e-6}, "`rtol`"),
    ({"name": "dop853", "atol": -1.0}, "`atol`"),
    ({"name": "dop853", "steps": 40}, "steps"),
    ({"name": "rk4", "theta": 1.4}, "theta"),
    ({"name": "wilson", "steps": 10, "dt": 0.1}, "either"),
])
def test_bad_options_name_the_option(kwargs, match):
    kwargs = dict(kwargs)
    name = kwargs.pop("name")
    with pytest.raises(IntegratorOptionError, match=match):
        make_integrator(name, **kwargs)


def test_negative_t_end_is_rejected():
    with pytest.raises(IntegratorOptionError, match="`t_end`"):
        solve("rk4", oscillator, 0.0, [1.0], [0.0], -1.0, steps=10)


def test_theta_one_and_above_limit_are_accepted():
    make_integrator("wilson", theta=1.0)
    make_integrator("wilson", theta=1.37)


def test_every_listed_integrator_runs():
    for name in INTEGRATORS:
        opts = {"steps": 50} if name in ("wilson", "rk4") else {"rtol": 1e-6}
        s = solve(name, oscillator, 0.0, [1.0], [0.0], 0.5, **opts)
        assert s.q[-1, 0] == pytest.approx(np.cos(W * 0.5), abs=1e-3), name


@pytest.mark.parametrize("name", [n for n in INTEGRATORS if n not in ("wilson", "rk4")])
def test_adaptive_integrators_share_one_base(name):
    """The package's DOP853 and SciPy's solvers are adaptive integrators with the same
    option checks; only the ``scipy-*`` names and SciPy's methods are SciPy's."""
    integ = make_integrator(name, rtol=1e-7, max_step=0.5)
    assert isinstance(integ, AdaptiveIntegrator) and integ.adaptive
    assert isinstance(integ, ScipyIntegrator) == (name != "dop853")
    assert isinstance(integ, DOP853) == (name == "dop853")
    assert (integ.rtol, integ.atol, integ.first_step, integ.max_step) == (1e-7, 1e-10, None,
                                                                          0.5)
    for bad, match in (({"rtol": 0.0}, "`rtol`"), ({"atol": [1e-9, -1.0]}, "`atol`"),
                       ({"first_step": -1e-3}, "`first_step`"), ({"max_step": 0}, "`max_step`")):
        with pytest.raises(IntegratorOptionError, match=match):
            make_integrator(name, **bad)


def test_atol_per_state_must_fit_the_state():
    for integ in (DOP853(atol=[1e-9, 1e-9, 1e-9]), ScipyIntegrator("rk45", atol=[1e-9] * 3)):
        with pytest.raises(IntegratorOptionError, match="`atol` has 3 components"):
            list(integ.integrate(oscillator, 0.0, [1.0], [0.0], 1.0))


def test_an_adaptive_instance_keeps_its_tolerances_in_a_run():
    """segment_integrators takes an instance's tolerances and step bounds, for the
    package's DOP853 as for SciPy's solvers (both adaptive, one not SciPy's)."""
    fixed = dict(dt=None, steps=None, iterations=None, tol=None, theta=None)
    for inst in (DOP853(rtol=1e-6, atol=1e-8, max_step=0.01), ScipyIntegrator("radau", 1e-6,
                                                                              1e-8)):
        factory, name = segment_integrators(inst, 0.0, 1.0, rtol=1e-10, atol=1e-13,
                                            first_step=None, max_step=None, **fixed)
        integ = factory(np.ones(1), 1e-4)
        assert name == inst.name and type(integ) is type(inst)
        assert integ.rtol == 1e-6 and integ.max_step == inst.max_step
        assert integ.atol.tolist() == [1e-8, 1e-7, 1e-5]
