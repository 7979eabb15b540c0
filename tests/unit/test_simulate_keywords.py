"""Every keyword of ``simulate`` acts on a fixed-structure and on a switched run alike,
or is reported by name; the defaults are the same on both."""

import warnings

import numpy as np
import pytest

from mechdyn.integrate import Event
from mechdyn.integrate.base import DEFAULT_RTOL, IntegratorOptionError, IntegratorWarning
from mechdyn.mechanism import Mechanism, Spring
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import add_element
from mechdyn.simulate.run import simulate

K, M, X0 = 400.0, 1.0, 0.05


def _oscillator(stop: bool):
    m = Mechanism("mass on a spring", gravity=(0.0, 0.0))
    m.add_ground(points={"A": (-1.0, 0.0)})
    m.add_body("mass", mass=M, inertia=0.1)
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    m.add(Spring("k", "ground", "A", "mass", (0.0, 0.0), stiffness=K, free_length=1.0))
    if stop:  # a stop that the motion never reaches: the run is switched, the motion free
        add_element(m, Stop("far", "s", lower=-1.0))
    return m


PATHS = pytest.mark.parametrize("stop", [False, True], ids=["fixed", "switched"])


def _run(stop, **kw):
    kw.setdefault("progress", False)
    return simulate(_oscillator(stop), 0.2, q0=[X0], qdot0=[0.0], **kw)


@PATHS
def test_default_tolerances_are_the_same(stop):
    tr = _run(stop)
    assert tr.status == "success"
    assert tr.stats["rtol"] == DEFAULT_RTOL
    assert np.all(np.asarray(tr.stats["atol"]) <= 1e-3 * DEFAULT_RTOL * 10 + 1e-30)
    w = np.sqrt(K / M)
    assert np.max(np.abs(tr.q[:, 0] - X0 * np.cos(w * tr.t))) < 1e-8


@PATHS
def test_callers_events_are_located_and_terminal_ones_stop_the_run(stop):
    calls = []

    def g(t, q, qdot):
        calls.append(t)
        return q[0]

    w = np.sqrt(K / M)
    tr = _run(stop, events=[Event(g, "zero", direction=-1, terminal=True)])
    assert calls and tr.status == "event"
    rec = [e for e in tr.events if getattr(e, "name", "") == "zero"]
    assert rec and abs(rec[0].t - np.pi / (2 * w)) < 1e-7


@PATHS
def test_options_without_effect_are_warned_about_by_name(stop):
    with pytest.warns(IntegratorWarning, match="rtol"):
        _run(stop, integrator="wilson", steps=200, rtol=1e-6)
    with pytest.warns(IntegratorWarning, match="d "):
        _run(stop, d=1e-3)
    with pytest.raises(IntegratorOptionError, match="first_step"):
        _run(stop, integrator="rk4", dt=1e-3, first_step=1e-4)
    with pytest.raises(IntegratorOptionError, match="steps"):
        _run(stop, integrator="dop853", steps=10)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _run(stop, integrator="dop853", first_step=1e-5, max_step=1e-2)


@PATHS
def test_backend_is_honoured(stop):
    assert _run(stop, backend="numpy").stats["backend"] == "numpy"


@PATHS
def test_samples_every_step_by_default_or_at_t_eval(stop):
    te = np.linspace(0.0, 0.2, 9)
    assert np.allclose(_run(stop, t_eval=te).t, te)
    tr = _run(stop)
    assert tr.t[0] == 0.0 and tr.t[-1] == pytest.approx(0.2) and tr.t.size > 9


def test_analogs_formulation_on_a_switched_run_is_warned_about():
    with pytest.warns(IntegratorWarning, match="formulation='analogs'"):
        _run(True, formulation="analogs")


@PATHS
def test_an_interrupted_run_keeps_its_samples_and_says_when(stop):
    """Ctrl-C (KeyboardInterrupt) during a run ends it with status "interrupted" and the
    samples computed so far, instead of a traceback that loses them."""
    def g(t, q, qdot):
        if t > 0.05:
            raise KeyboardInterrupt
        return 1.0

    tr = _run(stop, events=[Event(g, "ctrl-c")])
    assert tr.status == "interrupted" and "interrupted" in tr.message
    assert tr.t.size > 3 and 0.0 < tr.t[-1] <= 0.06
    assert np.all(np.isfinite(tr.q))
