"""Every integrator (rk4, wilson, the adaptive ones) in the segment loop of variable-structure
models."""

import numpy as np
import pytest
from test_impact_stop import X0, M, _closed_form, _oscillator

from mechdyn.cli import main
from mechdyn.integrate import RungeKutta4
from mechdyn.integrate.base import IntegratorOptionError
from mechdyn.simulate.run import simulate

E = 0.6


def _impacts(integrator, dt, **kw):
    tr = simulate(_oscillator(E), 0.55, integrator=integrator, dt=dt, q0=[X0], qdot0=[0.0],
                  progress=False, **kw)
    assert tr.status == "success", tr.message
    return tr, [ev for ev in tr.events if ev.kind == "impact"]


@pytest.mark.parametrize("name, order, min_ratio, c_t", [("rk4", 4, 8.0, 2e3),
                                                         ("wilson", 2, 3.0, 10.0)])
def test_impact_time_converges_at_the_integrators_order(name, order, min_ratio, c_t):
    errs = []
    for dt in (4e-3, 2e-3, 1e-3):
        tr, imp = _impacts(name, dt)
        times, losses, _ = _closed_form(E, len(imp))
        assert len(imp) == 2
        assert tr.stats["integrator"].startswith(name)
        np.testing.assert_allclose([ev.t for ev in imp], times, rtol=0,
                                   atol=c_t * dt ** order)
        # the impact law itself is exact: lost = (1 - e^2) T just before the impact
        T_before = np.array([0.5 * M * ev.qdot_before[0] ** 2 for ev in imp])
        np.testing.assert_allclose([ev.energy_lost for ev in imp], (1 - E ** 2) * T_before,
                                   rtol=1e-12)
        # ... and T before the impact carries the integration error only
        np.testing.assert_allclose([ev.energy_lost for ev in imp], losses,
                                   rtol=10 * c_t * dt ** order)
        np.testing.assert_allclose([ev.q_after[0] for ev in imp], -0.05, atol=1e-12)
        errs.append(abs(imp[0].t - times[0]))
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all(ratios > min_ratio), ratios
    assert np.all(ratios < 2.0 ** order * 1.5), ratios


def test_steps_option_and_integrator_instances():
    tr, imp = _impacts("wilson", None, steps=275, theta=1.4, iterations=3)
    assert "dt=0.002 s" in tr.stats["integrator"] and len(imp) == 2
    tr2 = simulate(_oscillator(E), 0.3, integrator=RungeKutta4(dt=2e-3), q0=[X0],
                   qdot0=[0.0], progress=False)
    assert tr2.status == "success" and tr2.stats["integrator"].startswith("rk4")
    # every integrator of the package runs the switched model; an implicit one
    # finds the same impacts
    tr3, imp3 = _impacts("radau", None, rtol=1e-10)
    times, _, _ = _closed_form(E, len(imp3))
    assert np.max(np.abs([ev.t for ev in imp3] - np.asarray(times))) < 1e-6
    with pytest.raises(IntegratorOptionError, match="theta"):
        simulate(_oscillator(E), 0.1, integrator="wilson", dt=1e-3, theta=1.2, progress=False)


def test_cli_press_cycle_rk4_with_dt(capsys):
    code = main(["simulate", "press_cycle", "--t-end", "0.02 s", "--integrator", "rk4",
                 "--dt", "1ms"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "status: success" in out and "rk4 (dt=0.001 s)" in out
