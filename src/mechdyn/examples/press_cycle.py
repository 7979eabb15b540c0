"""The working cycle of the clutchless crank press (source paper, docs/references.md [1]).

Idle, engaging, locking, work stroke and release of the press, with its stops,
contact, lock and switches: the machine and every value the paper does not give
(with its reason) are in the bundled model file ``press_cycle.toml``.  The
cylinder command is a periodic table over the crank angle, so the machine locks
and releases once per command, indefinitely.  Use :func:`build` for the
mechanism and :func:`run` to simulate it.
"""

from __future__ import annotations

import numpy as np

from ..mechanism import Mechanism
from ..modelfile import load as load_file
from ..simulate.segments import simulate_events
from . import load

__all__ = ["build", "run", "run_time", "load_model_file"]


def build() -> Mechanism:
    """The press with its switches, stops, contact and loads (the bundled ``press_cycle``).

    Returns
    -------
    Mechanism
        With ``extras["initial"]`` set (idle, ram on its upper stop).
    """
    return load("press_cycle")


def load_model_file(path=None) -> Mechanism:
    """The press from a model file (default: the bundled ``press_cycle.toml``)."""
    return build() if path is None else load_file(path)


def run_time(cycles: int = 4, mechanism: Mechanism | None = None) -> float:
    """A simulated time (s) that covers ``cycles`` whole cycles, the last one back in idle.

    The ram is back on its upper stop about 2.25 revolutions after the command
    of its cycle (the ``cylinder_force`` table of ``mechanism``, default
    :func:`build`); the time is reckoned at the initial crank speed, the motor's
    nominal speed (slower than the mean crank speed, so the estimate is on the
    late side).
    """
    mech = build() if mechanism is None else mechanism
    (command,) = [ld.magnitude for ld in mech.loads if ld.name == "cylinder_force"]
    initial = mech.extras["initial"]
    end = command.x[1] + (cycles - 1) * command.period + 2.25 * 2 * np.pi
    return float((end - initial["q"]["phi"]) / initial["qdot"]["phi"])


def run(cycles: int = 4, t_end: float | None = None, **options):
    """Simulate ``cycles`` work cycles; returns the Trajectory.

    Parameters
    ----------
    cycles : int
        Whole cycles to cover (idle, engage, lock, stroke, release, idle);
        sets the end time by :func:`run_time`.
    t_end : float, optional
        End time, s, instead.
    **options
        Go to :func:`mechdyn.simulate.segments.simulate_events`, the segment loop of
        :func:`mechdyn.simulate` (here rtol 1e-9 and output every 0.5 ms unless given).

    Returns
    -------
    Trajectory
    """
    mech = build()
    if t_end is None:
        t_end = run_time(cycles, mech)
    options.setdefault("rtol", 1e-9)
    options.setdefault("dt_out", 5e-4)
    return simulate_events(mech, t_end, **options)
