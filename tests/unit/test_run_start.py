"""The start of a run kept with the compiled model: the next run from the same state gives
the numbers of the first (bitwise), in its own mode system and workspace."""

import numpy as np
import pytest

import mechdyn
from mechdyn.dynamics.run_start import STARTS_KEPT
from mechdyn.examples.paper_case import press_idle


def _kept(model):
    return list(model.memo.get("run starts", []))


def _same(a, b):
    for k in ("t", "q", "qdot", "qddot", "x", "xdot"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    for k in a.energy:
        assert np.array_equal(a.energy[k], b.energy[k]), k
    assert a.status == b.status and a.stats["evaluations"] == b.stats["evaluations"]


@pytest.mark.parametrize("name", ["press", "four_bar"])
def test_a_kept_start_gives_the_first_run(name):
    model = (press_idle() if name == "press" else mechdyn.examples.load(name)).compile()
    t_end = 0.05
    first = mechdyn.simulate(model, t_end, progress=False)
    assert len(_kept(model)) == 1
    again = mechdyn.simulate(model, t_end, progress=False)
    _same(first, again)
    assert [e.kind for e in first.events] == [e.kind for e in again.events]
    # another state: another start; the same with other options of the loop as well
    other = mechdyn.simulate(model, t_end, progress=False, qdot0=np.full(model.n_q, 0.5))
    assert len(_kept(model)) == 2 and other.success
    mechdyn.simulate(model, t_end, progress=False, gap_tol=1e-6)
    assert len(_kept(model)) == 3
    _same(first, mechdyn.simulate(model, t_end, progress=False))


@pytest.mark.parametrize("name", ["toggle_press_friction", "press_cycle"])
def test_starts_with_friction_or_events_are_not_kept(name):
    """Friction in the pairs (its mode systems carry the pairs' states), stops closing at
    the start (its events are the run's): the start is made anew by every run."""
    model = mechdyn.examples.load(name).compile()
    a = mechdyn.simulate(model, 0.01, progress=False)
    assert _kept(model) == []
    b = mechdyn.simulate(model, 0.01, progress=False)
    _same(a, b)
    assert [(e.t, e.kind, e.element) for e in a.events] == \
        [(e.t, e.kind, e.element) for e in b.events]


def test_a_bounded_number_of_starts_is_kept():
    model = press_idle().compile()
    for k in range(STARTS_KEPT + 3):
        mechdyn.simulate(model, 1e-3, progress=False, qdot0={"phi": 1.0 + k})
    assert len(_kept(model)) == STARTS_KEPT


def _pool(model):
    return [v for k, v in model.memo.items() if isinstance(k, tuple) and k[0] == "run equations"]


def test_the_equations_of_a_kept_start_serve_the_next_run():
    model = press_idle().compile()
    first = mechdyn.simulate(model, 0.05, progress=False, rtol=1e-9)
    (pool,) = _pool(model)
    assert len(pool) == 1
    eqs = pool[0][0]
    # kept without the run: no mode system, workspace or anchor of it
    assert eqs.ms is None and eqs._anchor is None
    for kw in ({"integrator": "rk4", "steps": 40}, {"rtol": 1e-9}):
        tr = mechdyn.simulate(model, 0.05, progress=False, **kw)
        assert len(pool) == 1 and pool[0][0] is eqs  # taken, restarted, given back
    _same(first, tr)
    assert tr.stats["compile_time_s"] == 0.0


def test_a_run_within_a_run_has_its_own_equations():
    """An event function that runs the same model from the same state: the inner run does
    not share the outer run's equations (nor its kernel's workspace)."""
    model = press_idle().compile()
    ref = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9)
    inner = []

    def g(t, q, qdot):
        if not inner:
            inner.append(mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9))
        return 1.0

    outer = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9,
                             events=[mechdyn.integrate.Event(g, "inner run")])
    _same(ref, inner[0])
    plain = mechdyn.simulate(model, 0.02, progress=False, rtol=1e-9,
                             events=[mechdyn.integrate.Event(lambda t, q, qd: 1.0, "none")])
    _same(plain, outer)
    assert len(_pool(model)[0]) == 2
