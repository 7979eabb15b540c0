"""Segments with event functions in the compiled DOP853 loop (``kept_steps``).

Oracles: the zero crossings of a torsion oscillator (theta = A cos(omega t): theta = 0 at
t = (k + 1/2) pi / omega) and SciPy's own DOP853 stepped from Python
(``integrator="scipy-dop853"``), which must find the press cycle's events -- every lock,
stop and impact -- at the same times to 1e-9 s (issue 9's rule).
"""

import numpy as np
import pytest
from test_compiled_loop import A0, OMEGA, oscillator

from mechdyn.dynamics.compiled import numba_available
from mechdyn.examples import press_cycle
from mechdyn.integrate.events import Event
from mechdyn.simulate import compiled_loop as compiled
from mechdyn.simulate.run import simulate

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")


@pytest.fixture
def kept(monkeypatch):
    """Counts the steps yielded by the compiled loop to segments with event functions."""
    calls = []
    real = compiled.kept_steps

    def spy(*args, **kw):
        for step in real(*args, **kw):
            calls.append(step.t)
            yield step

    monkeypatch.setattr(compiled, "kept_steps", spy)
    return calls


def test_oscillator_zero_crossings_at_the_closed_form_times(kept):
    ev = Event(lambda t, q, v: q[0], "zero", direction=0)
    tr = simulate(oscillator(), 1.0, rtol=1e-12, events=[ev], progress=False)
    assert tr.success, tr.message
    assert len(kept) == tr.stats["steps"] > 0  # every step from the compiled loop
    want = (np.arange(5) + 0.5) * np.pi / OMEGA
    want = want[want < 1.0]
    np.testing.assert_allclose([e.t for e in tr.events], want, rtol=0, atol=1e-11)
    assert np.max(np.abs(tr.q[:, 0] - A0 * np.cos(OMEGA * tr.t))) < 1e-10


def test_terminal_event_ends_the_run_at_the_crossing(kept):
    ev = Event(lambda t, q, v: q[0], "zero", direction=-1, terminal=True)
    tr = simulate(oscillator(), 1.0, rtol=1e-12, events=[ev], progress=False)
    assert kept and tr.t[-1] == pytest.approx(0.5 * np.pi / OMEGA, abs=1e-11)
    assert abs(tr.q[-1, 0]) < 1e-11


def test_press_cycle_events_as_with_scipy_dop853(kept):
    # 0.3 s: the idle stops, the piston's bounces on its stops and the ram, the lock
    runs = {m: press_cycle.run(t_end=0.3, dt_out=2e-3, progress=False, method=m)
            for m in ("dop853", "scipy-dop853")}
    ours, ref = runs["dop853"], runs["scipy-dop853"]
    assert ours.status == ref.status == "success"
    assert len(kept) == ours.stats["steps"]  # every step of the run from the compiled loop
    assert [(e.kind, e.element) for e in ours.events] == \
        [(e.kind, e.element) for e in ref.events]
    assert ("engage", "rocker_lock") in [(e.kind, e.element) for e in ours.events]
    np.testing.assert_allclose([e.t for e in ours.events], [e.t for e in ref.events],
                               rtol=0, atol=1e-9)
    assert ours.t.shape == ref.t.shape and np.max(np.abs(ours.t - ref.t)) < 1e-9  # events too
    # the motion against a converged run: SciPy's DOP853 is 4e-7 rad off one at this rtol
    # (1e-9), from a step at about 0.22 s -- its steps are not ended at the knees of the
    # press's load tables, as the compiled loop's are
    conv = press_cycle.run(t_end=0.3, dt_out=2e-3, progress=False, rtol=1e-12)
    assert conv.t.shape == ours.t.shape
    assert np.max(np.abs(ours.q - conv.q)) < 1e-7
