"""The start of a run kept in a workspace the caller passes: the next run from the same
state gives the numbers of the first (bitwise); without a workspace nothing is kept."""

import numpy as np
import pytest

import mechdyn
from mechdyn.examples.paper_case import press_idle
from mechdyn.model.workspace import Workspace
from mechdyn.simulate import run_start


def _same(a, b):
    for k in ("t", "q", "qdot", "qddot", "x", "xdot"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    for k in a.energy:
        assert np.array_equal(a.energy[k], b.energy[k]), k
    assert a.status == b.status and a.stats["evaluations"] == b.stats["evaluations"]


@pytest.mark.parametrize("name", ["press", "four_bar"])
def test_a_kept_start_gives_the_first_run(name):
    model = (press_idle() if name == "press" else mechdyn.examples.load(name)).compile()
    t_end, ws = 0.05, Workspace()
    first = mechdyn.simulate(model, t_end, progress=False, workspace=ws)
    assert len(ws.starts) == 1
    again = mechdyn.simulate(model, t_end, progress=False, workspace=ws)
    _same(first, again)
    assert [e.kind for e in first.events] == [e.kind for e in again.events]
    _same(first, mechdyn.simulate(model, t_end, progress=False))  # no workspace: anew
    # another state: another start; the same with other options of the loop as well
    other = mechdyn.simulate(model, t_end, progress=False, qdot0=np.full(model.n_q, 0.5),
                             workspace=ws)
    assert len(ws.starts) == 2 and other.success
    mechdyn.simulate(model, t_end, progress=False, gap_tol=1e-6, workspace=ws)
    assert len(ws.starts) == 3
    _same(first, mechdyn.simulate(model, t_end, progress=False, workspace=ws))


@pytest.mark.parametrize("name", ["toggle_press_friction", "press_cycle"])
def test_starts_with_friction_or_events_are_not_kept(name):
    """Friction in the pairs (its mode systems carry the pairs' states), stops closing at
    the start (its events are the run's): the start is made anew by every run."""
    model = mechdyn.examples.load(name).compile()
    ws = Workspace()
    a = mechdyn.simulate(model, 0.01, progress=False, workspace=ws)
    assert ws.starts == {}
    b = mechdyn.simulate(model, 0.01, progress=False, workspace=ws)
    _same(a, b)
    assert [(e.t, e.kind, e.element) for e in a.events] == \
        [(e.t, e.kind, e.element) for e in b.events]


def test_a_bounded_number_of_starts_is_kept(monkeypatch):
    monkeypatch.setattr(run_start, "KEPT", 4)
    model, ws = press_idle().compile(), Workspace()
    for k in range(7):
        mechdyn.simulate(model, 1e-3, progress=False, qdot0={"phi": 1.0 + k}, workspace=ws)
    assert len(ws.starts) == 4


def test_the_equations_of_a_kept_start_serve_the_next_run():
    model, ws = press_idle().compile(), Workspace()
    first = mechdyn.simulate(model, 0.05, progress=False, rtol=1e-9, workspace=ws)
    (pool,) = ws.equations.values()
    assert len(pool) == 1
    eqs = pool[0][0]
    # kept without the run: no mode system or anchor of it
    assert eqs.ms is None and eqs._anchor is None
    for kw in ({"integrator": "rk4", "steps": 40}, {"rtol": 1e-9}):
        tr = mechdyn.simulate(model, 0.05, progress=False, workspace=ws, **kw)
        assert len(pool) == 1 and pool[0][0] is eqs  # taken, restarted, given back
    _same(first, tr)
    assert tr.stats["compile_time_s"] == 0.0


def test_a_run_within_a_run_has_its_own_workspace():
    """An event function that runs the same model from the same state: the inner run,
    given no workspace, shares nothing with the outer one."""
    model, ws = press_idle().compile(), Workspace()
    ref = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9)
    inner = []

    def g(t, q, qdot):
        if not inner:
            inner.append(mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9))
        return 1.0

    outer = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9, workspace=ws,
                             events=[mechdyn.integrate.Event(g, "inner run")])
    _same(ref, inner[0])
    plain = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9,
                             events=[mechdyn.integrate.Event(lambda t, q, qd: 1.0, "none")])
    _same(plain, outer)
