"""Fuzzing: seeded mutations of the bundled model files, each through load, compile, a short
sweep and a short simulation, in-process with a time budget per case.

Every outcome must be a success or a :class:`~mechdyn.errors.MechdynError` with a message
(an analysis that stops early returns a record with its status and message): no other
exception, no hang, no NaN in a result that says success.  A quick set runs in every
``make test``; the long set (1 500 cases) is marked slow.
"""

from __future__ import annotations

import random
import re
import signal
from contextlib import contextmanager

import numpy as np
import pytest

from mechdyn import examples, simulate
from mechdyn.errors import MechdynError
from mechdyn.kinematics.sweep import sweep
from mechdyn.modelfile import loads

#: seconds one case may take (load, sweep and simulation together)
BUDGET = 30
#: the files mutated
BASES = ["slider_crank", "four_bar", "clutchless_press", "toggle_press", "press_cycle",
         "bolt_buffer", "andrews_squeezer"]
#: values put in place of a value
GARBAGE = ['"-1 kg"', "0", '"0 m"', "1e400", '"nan m"', '"inf"', "9" * 60, '"2**2**2 mm"',
           "[1, 2, 3]", "{ a = 1 }", "true", '"ghost"', '""', '"250 \u339c"', '"' + "x" * 300 + '"',
           '"250.5.5 mm"', "-1", "1e-300", '"1e30 m"', '"1e-30 kg"', "[[[[1]]]]", '"15 kg"',
           '"10 Hz"', '"-64.1 deg"', '["1 mm"]', '["1 mm", "2 mm", "3 mm", "4 mm"]', "nan",
           '"dist(rod.B, ground.O)"', '"t"', '"phi_dot"', '"joint:nowhere"', "1e30", "-1e30"]


def _mutate(text: str, rng: random.Random) -> str:
    """One to three mutations of a model file's text."""
    lines = text.splitlines()
    for _ in range(rng.randint(1, 3)):
        kind = rng.random()
        values = [k for k, ln in enumerate(lines) if "=" in ln and not ln.lstrip().startswith("#")]
        if kind < 0.25 and values:  # a number scaled (a plausible but unusual model)
            k = rng.choice(values)
            key, val = lines[k].split("=", 1)
            factor = float(rng.choice(["1e-6", "1e-3", "0.5", "2", "1e3", "1e6", "-1"]))
            new = re.sub(r"(?<![\w.])(\d+\.?\d*(?:e-?\d+)?)",
                         lambda m, f=factor: f"{float(m[1]) * f:g}", val, count=1)
            lines[k] = f"{key}={new}"
        elif kind < 0.5 and values:  # a value replaced
            k = rng.choice(values)
            key = lines[k].split("=", 1)[0]
            lines[k] = f"{key}= {rng.choice(GARBAGE)}"
        elif kind < 0.6 and values:  # a key deleted
            del lines[rng.choice(values)]
        elif kind < 0.7:  # a table header deleted or duplicated
            heads = [k for k, ln in enumerate(lines) if ln.startswith("[")]
            if heads:
                k = rng.choice(heads)
                if rng.random() < 0.5:
                    del lines[k]
                else:
                    lines.insert(rng.randrange(len(lines) + 1), lines[k])
        elif kind < 0.78 and values:  # a name swapped for another one
            k = rng.choice(values)
            key, val = lines[k].split("=", 1)
            other = rng.choice(values)
            lines[k] = f"{key}={lines[other].split('=', 1)[1]}"
        elif kind < 0.86:  # truncated
            lines = lines[:rng.randrange(len(lines) + 1)]
        elif kind < 0.93:  # junk inserted
            junk = rng.choice(["[[", "= 1", "x = ", "\u0000", "[bodies.ghost]\nmass = 1",
                               "[joints.j]\ntype = \"revolute\"\nparent = \"x\"\nchild = \"x\"",
                               "[" + "a." * 200 + "a]", "\xff\xfe"])
            lines.insert(rng.randrange(len(lines) + 1), junk)
        elif values:  # a key renamed to an unknown one
            k = rng.choice(values)
            lines[k] = "ghost_key " + lines[k][lines[k].index("="):]
    return "\n".join(lines) + "\n"


@contextmanager
def _budget(seconds: int):
    def alarm(signum, frame):
        raise TimeoutError(f"case over its budget of {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _finite(*arrays) -> bool:
    return all(np.all(np.isfinite(np.asarray(a, float))) for a in arrays)


def _run_case(seed: int) -> str:
    """The outcome of one mutated file: "error", "stopped" or "ran"; raises on a defect."""
    rng = random.Random(seed)
    base = BASES[seed % len(BASES)]
    text = _mutate(examples.path(base).read_text(encoding="utf-8"), rng)
    try:
        with _budget(BUDGET):
            mech = loads(text, name=f"{base}-{seed}.toml")
            model = mech.compile()
            values = None  # a full turn of the first coordinate, or a short travel
            if model.n_q and not model.coord_is_angle[0]:
                values = np.linspace(0.0, 0.01 * model.length_scale, 5)
            sw = sweep(model, values=values) if model.n_q else None
            if sw is not None and sw.ok:
                assert _finite(sw.x, sw.B), f"seed {seed}: NaN in a successful sweep"
            tr = simulate(model, 0.005, progress=False, max_wall_time=10)
            if tr.success:
                assert _finite(tr.q, tr.qdot, tr.x), f"seed {seed}: NaN in a successful run"
            else:
                assert tr.message, f"seed {seed}: a stopped run without a message"
                return "stopped"
    except MechdynError as exc:
        assert str(exc).strip(), f"seed {seed}: an error without a message"
        return "error"
    return "ran"


@pytest.mark.parametrize("block", range(4))
def test_fuzz_quick(block):
    """200 cases: every outcome named."""
    outcomes = [_run_case(seed) for seed in range(50 * block, 50 * block + 50)]
    assert set(outcomes) <= {"error", "stopped", "ran"}


@pytest.mark.slow
@pytest.mark.parametrize("block", range(26))
def test_fuzz_long(block):
    """1 300 more cases (seeds 200 .. 1 499)."""
    start = 200 + 50 * block
    outcomes = [_run_case(seed) for seed in range(start, start + 50)]
    assert set(outcomes) <= {"error", "stopped", "ran"}
