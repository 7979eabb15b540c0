"""Plots of result records, written to PNG files.

One function per kind of record (``plot_<record>``, in the ``plot_*`` modules beside this
one, all importable from here), and :func:`plot`, which picks the function for a record.
Figures are drawn with matplotlib's Agg canvas directly (:mod:`mechdyn.results.figure`),
so nothing here needs a screen or changes pyplot's backend.

:func:`plot_columns` draws chosen table columns of any record, and
:func:`plot_joint_force_polar` the polar diagram of a joint force.  Given ``path=None``
the plotting functions return the matplotlib figure instead of writing it.

Add a record kind by writing ``plot_<kind>(record, path, ...) -> Path`` and an entry in
``PLOTTERS``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from .plot_columns import plot_columns
from .plot_dynamics import plot_trajectory
from .plot_kinematics import plot_kinematic_sweep
from .plot_kinetostatics import plot_joint_force_polar, plot_kinetostatics
from .plot_reduction import plot_motor, plot_reduction, plot_startup, plot_steady_cycle
from .plot_spectrum import plot_spectrum

__all__ = ["plot", "PLOTTERS", "plot_kinematic_sweep", "plot_trajectory", "plot_kinetostatics",
           "plot_reduction", "plot_steady_cycle", "plot_startup", "plot_motor",
           "plot_spectrum", "plot_columns", "plot_joint_force_polar"]


#: record class name -> plotting function
PLOTTERS: dict[str, Callable] = {
    "KinematicSweep": plot_kinematic_sweep,
    "Trajectory": plot_trajectory,
    "Kinetostatics": plot_kinetostatics,
    "Reduction": plot_reduction,
    "SteadyCycle": plot_steady_cycle,
    "StartupResult": plot_startup,
}


def plot(record, path, **kwargs) -> Path:
    """Plot any result record with the function registered for its kind.

    Parameters
    ----------
    record
        A :class:`~mechdyn.kinematics.sweep.KinematicSweep`, ``Trajectory``,
        ``Kinetostatics``, ``Reduction``, ``SteadyCycle`` or ``StartupResult``.
    path : str or Path or None
        The image file (PNG, PDF, SVG ... by its suffix); its folder is created.  None
        returns the figure.
    **kwargs
        Options of the record's plotting function (``PLOTTERS[kind]``).

    Returns
    -------
    Path or Figure
        The file written (the figure when ``path`` is None).

    Raises
    ------
    TypeError
        No plot for records of that kind (the message lists the kinds).

    Examples
    --------
    >>> import tempfile, pathlib, mechdyn
    >>> tr = mechdyn.simulate(mechdyn.examples.load("four_bar"), 0.05, progress=False)
    >>> plot(tr, pathlib.Path(tempfile.mkdtemp()) / "run.png").suffix
    '.png'
    """
    kind = type(record).__name__
    try:
        fn = PLOTTERS[kind]
    except KeyError:
        raise TypeError(f"no plot for records of kind {kind!r}; kinds with plots: "
                        + ", ".join(sorted(PLOTTERS))) from None
    return fn(record, path, **kwargs)
