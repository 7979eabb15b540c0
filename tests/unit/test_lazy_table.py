"""The forces, frame loads and energies of a run evaluated on first use give the numbers of
the evaluation at the end of the run (a sink's chunk), raise its errors, and read, copy and
pickle as the eager records did."""

import copy
import pickle

import numpy as np
import pytest

import mechdyn
from mechdyn.examples.paper_case import press_idle
from mechdyn.results.lazy_table import LazyDict
from mechdyn.results.trajectory import SwitchedSamples
from mechdyn.simulate import samples as run_samples


@pytest.fixture(scope="module")
def press():
    return press_idle().compile()


def _eager(model, t_end, **kw):
    """The run with its table evaluated as the run ends (one chunk handed to a sink)."""
    return mechdyn.simulate(model, t_end, progress=False, sink=lambda part, start: None,
                            chunk=10**6, **kw)


@pytest.mark.parametrize("case", ["press", "press_cycle"])
def test_lazy_table_is_the_table_of_the_run(press, case):
    model = press if case == "press" else mechdyn.examples.load("press_cycle").compile()
    t_end = 0.05 if case == "press" else 0.12
    lazy, eager = (f(model, t_end) for f in (mechdyn.simulate, _eager))
    assert not lazy.energy.evaluated
    assert set(lazy.energy) == set(eager.energy)
    for k in eager.energy:
        assert np.array_equal(lazy.energy[k], eager.energy[k]), k
    vs, ve = lazy.switching, eager.switching
    for k in ("frame_force", "frame_moment", "impact_losses", "mode_index"):
        assert np.array_equal(vs[k], ve[k]), k
    assert vs.mode == ve.mode and vs.modes == ve.modes and vs.penetration == ve.penetration
    for el, f in ve.forces.items():  # the sink's columns cover every element of the model
        assert np.array_equal(vs.forces.get(el, np.zeros_like(f)), f), el
    assert lazy.stats["penetration"] == eager.stats["penetration"]
    assert lazy.energy_drift() == eager.energy_drift()
    df_l, df_e = lazy.to_dataframe(), eager.to_dataframe()
    for col in df_l.columns:
        assert np.array_equal(df_l[col].to_numpy(), df_e[col].to_numpy()), col


def test_an_error_of_the_table_is_raised_at_every_use(press, monkeypatch):
    tr = mechdyn.simulate(press, 0.01, progress=False)

    def broken(*args, **kwargs):
        raise FloatingPointError("forces")

    monkeypatch.setattr(run_samples, "element_forces", broken)
    for _ in range(2):
        with pytest.raises(FloatingPointError, match="forces"):
            _ = tr.energy["kinetic"]
        with pytest.raises(FloatingPointError, match="forces"):
            _ = tr.switching.frame_force
    monkeypatch.undo()
    assert tr.energy["kinetic"].shape == tr.t.shape
    assert tr.switching.forces["O"].shape == (tr.t.size, 2)


def test_lazy_records_read_copy_and_pickle_as_dicts(press):
    tr = mechdyn.simulate(press, 0.01, progress=False)
    e = tr.energy
    assert isinstance(e, dict) and not e.evaluated
    plain = dict(e)
    assert e.evaluated and list(plain) == list(e.keys()) == list({**e})
    assert e == plain and len(e) == len(plain) and "balance" in e
    assert type(copy.copy(e)) is dict and type(e.copy()) is dict
    back = pickle.loads(pickle.dumps(mechdyn.simulate(press, 0.01, progress=False).energy))
    assert type(back) is dict and np.array_equal(back["balance"], e["balance"])
    vs = mechdyn.simulate(press, 0.01, progress=False).switching
    vs2 = pickle.loads(pickle.dumps(vs))
    assert isinstance(vs2, SwitchedSamples) and "_fill" not in vs2.__dict__
    assert np.array_equal(vs2.frame_force, vs.frame_force) and vs2.forces.keys() == \
        vs.forces.keys()


def test_lazy_dict_fills_once_on_any_use():
    calls = []

    def fill():
        calls.append(1)
        return {"a": 1, "b": 2}

    for use in (len, list, repr, bool, dict, lambda d: d.get("a"), lambda d: "a" in d,
                lambda d: d == {"a": 1, "b": 2}, lambda d: d | {"c": 3}):
        calls.clear()
        d = LazyDict.lazy(fill)
        use(d)
        use(d)
        assert calls == [1]
    d = LazyDict.lazy(fill)
    d["c"] = 3
    assert dict(d) == {"a": 1, "b": 2, "c": 3}
