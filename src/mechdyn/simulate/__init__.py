"""The segment loop of a run: integrate a mode, locate the event on the step's dense
output, apply the switch or impact, go on.

:mod:`~mechdyn.simulate.run` holds :func:`simulate`, the user's entry;
:mod:`~mechdyn.simulate.segments` the loop over segments, each run in the compiled
loop of its mode's kernel where it can (:mod:`~mechdyn.simulate.compiled_loop`);
:mod:`~mechdyn.simulate.run_start` the state a run starts from;
:mod:`~mechdyn.simulate.switching` what happens at a switching instant, with
:mod:`~mechdyn.simulate.gaps` (stops and contacts) and :mod:`~mechdyn.simulate.impact`;
:mod:`~mechdyn.simulate.samples` the samples a run records and hands over.
"""

from .run import simulate

__all__ = ["simulate"]
