"""A compiled Model is constant: every analysis of every bundled example leaves every
attribute of its Model as it was (arrays compared by their bytes).

The fingerprint walks the Model's object graph -- its own attributes, the Mechanism,
the force model, the switchable elements, their lists, dicts and arrays -- so a cache
written anywhere under the Model (a dict growing, an array changed in place) is found.
"""

from __future__ import annotations

import functools
import types

import numpy as np
import pytest

import mechdyn
from mechdyn.integrate.driver import INTEGRATORS
from mechdyn.model.workspace import Workspace
from mechdyn.study.analyses import KinetostaticExtremes, SimulationMetrics

pytestmark = [pytest.mark.timeout(240), pytest.mark.filterwarnings("ignore")]

_ATOMS = (str, bytes, int, float, complex, bool, type(None), np.generic)


def _derived(cls, name: str) -> bool:
    return any(isinstance(c.__dict__.get(name), functools.cached_property)
               for c in cls.__mro__)


def fingerprint(obj) -> list:
    """A list that changes when anything reachable from ``obj`` does: arrays by dtype,
    shape and bytes, containers by their items, objects by their attributes, functions
    and classes by their identity (each object once)."""
    out: list = []
    seen: set[int] = set()
    stack = [("", obj)]
    while stack:
        path, o = stack.pop()
        if isinstance(o, _ATOMS):
            out.append((path, repr(o)))
            continue
        if id(o) in seen:
            out.append((path, "@", id(o)))
            continue
        seen.add(id(o))
        if isinstance(o, np.ndarray):
            if o.dtype == object:
                stack.extend((f"{path}[{k}]", v) for k, v in enumerate(o.ravel()))
            out.append((path, o.dtype.str, o.shape, o.tobytes() if o.dtype != object else b""))
        elif isinstance(o, dict):
            out.append((path, "dict", len(o)))
            for k, v in o.items():
                stack.extend([(f"{path}<key>", k), (f"{path}[{k!r}]", v)])
        elif isinstance(o, list | tuple | set | frozenset):
            items = sorted(o, key=repr) if isinstance(o, set | frozenset) else o
            out.append((path, type(o).__name__, len(o)))
            stack.extend((f"{path}[{k}]", v) for k, v in enumerate(items))
        elif isinstance(o, types.FunctionType | types.BuiltinFunctionType | type
                        | types.ModuleType | types.MethodType):
            out.append((path, "callable", id(o)))
        else:
            # a cached_property of an object is a pure function of its own fields,
            # computed once: not a cache of runs (the fields themselves are compared)
            attrs = {k: v for k, v in getattr(o, "__dict__", {}).items()
                     if not _derived(type(o), k)}
            for cls in type(o).__mro__:
                for slot in getattr(cls, "__slots__", ()):
                    if hasattr(o, slot):
                        attrs[slot] = getattr(o, slot)
            out.append((path, type(o).__qualname__, tuple(sorted(attrs))))
            stack.extend((f"{path}.{k}", v) for k, v in attrs.items())
    return out


def _analyses(model):
    """(name, callable) of every analysis that applies to the model."""
    short = 0.004
    c = model.coordinate_names[0]
    values = None if model.coord_is_angle[0] else model.q_sketch[0] + np.linspace(0, 1e-3, 5)
    yield "sweep", lambda: mechdyn.sweep(model, c, values)
    if model.n_q == 1:
        yield "kinetostatics", lambda: mechdyn.kinetostatics(model, speed=2 * np.pi)
        yield "reduce_model", lambda: mechdyn.reduce_model(model, steps=37)
        yield "study kinetostatics", lambda: KinetostaticExtremes("60 rpm", steps=24)(model)
    for name in INTEGRATORS:
        opts = {"steps": 8} if name in ("wilson", "rk4") else {}
        yield f"simulate {name}", lambda n=name, o=opts: mechdyn.simulate(
            model, short, integrator=n, progress=False, **o)
    ws = Workspace()
    yield "simulate twice with a workspace", lambda: [
        mechdyn.simulate(model, short, progress=False, workspace=ws) for _ in range(2)]
    yield "study simulation", lambda: SimulationMetrics(
        lambda tr: {"t_s": tr.t[-1]}, "4 ms")(model)


@pytest.mark.parametrize("name", mechdyn.examples.names())
def test_no_analysis_writes_to_the_compiled_model(name):
    model = mechdyn.examples.load(name).compile()
    before = fingerprint(model)
    for what, run in _analyses(model):
        run()
        assert fingerprint(model) == before, f"{what} changed the compiled model of {name}"
