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
