"""A cyclic-automaton example: a bolt driven against a buffer and a stop.

A bolt slides in its guide, pushed by a preloaded driving spring; it meets a
buffer held back by a stiff spring through a unilateral contact with impacts,
separates and touches again, all found by the event loop.  The model is the
bundled ``bolt_buffer.toml``.  Use :func:`build` and :func:`run`.
"""

from __future__ import annotations

from ..mechanism import Mechanism
from ..simulate.segments import simulate_events
from . import load

__all__ = ["build", "run"]


def build() -> Mechanism:
    """The bolt-buffer mechanism (the bundled ``bolt_buffer``; gravity off)."""
    return load("bolt_buffer")


def run(t_end: float = 0.2, **options):
    """Simulate the bolt-buffer cycle; returns the Trajectory."""
    options.setdefault("dt_out", 2e-4)
    return simulate_events(build(), t_end, **options)
