"""``mechdyn report``: one self-contained HTML report of a model for an engineer.

Examples::

    mechdyn report slider_crank --speed 1500rpm -o slider_crank.html
    mechdyn report four_bar --trace coupler.P -o four_bar.html
    mechdyn report press_cycle --simulate --t-end 0.5s -o run.html

The report holds the model (bodies, joints, coordinates, loads and drives in
tables with units), the kinematic sweep summary (strokes, dead centres,
transmission angles, extreme speeds and accelerations) with its interactive plot
and the animation beside it, the kinetostatic cycle (driving torque, peak joint
forces; the other coordinates of a machine with several degrees of freedom held
at their initial values) and the loads on the building (frame force and moment,
their harmonics, and the peak load of every support when the model has a
foundation); with ``--simulate``, the run summary, energy balance, events and
the loads on the building of the run instead.

Exit codes: 0 done; 1 an analysis stopped early (the report says where); 2 bad input.
The analyses are composed here and written by :mod:`mechdyn.results.report`.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from ..errors import MechdynError, ModelError, Status
from ..kinematics.sweep import initial_coordinates
from ..kinematics.sweep import sweep as run_sweep
from ..kinetostatics.inverse import KinetostaticsWarning, kinetostatics
from ..model import as_model
from ..progress import stage
from ..results.report import report_trajectory, write_report
from .options import (
    add_motion_arguments,
    finish,
    model_speed,
    open_model,
    simulate_from_args,
    speed_from_args,
    speed_line,
    sweep_values,
)

__all__ = ["register", "run", "report", "report_records", "foundation_loads", "mounted_loads"]


def register(sub) -> None:
    """Add the ``report`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "report",
        help="self-contained HTML report: model, kinematics, kinetostatics, loads on the "
             "building (or a simulation)",
        description="Write one HTML file that works offline (tables, interactive plots, the "
                    "animation) describing the model, its kinematics over one turn, its "
                    "kinetostatic cycle (other coordinates held at their initial values) and "
                    "the loads it sends into the building; with --simulate, a forward-dynamics "
                    "run.",
        epilog="Quantities take units: 60rpm, 0deg, 360 deg, 0.05s (a bare number is SI). "
               "Exit codes: 0 done, 1 an analysis stopped early, 2 bad input.")
    d = add_motion_arguments(p, "HTML", "report to write", steps=361, verb="report",
                             title="title of the report")
    d.add_argument("--animation", action=argparse.BooleanOptionalAction, default=True,
                   help="embed an animated GIF of the motion beside the plots (default; "
                        "--no-animation: its first frame only, a smaller file)")
    p.add_argument("--speed", metavar="RATE",
                   help="constant rate of the swept coordinate, e.g. 60rpm (default: the "
                        "model's initial rate, else 1 rad/s)")


def run(args) -> int:
    """Run ``mechdyn report``; returns the exit code."""
    t0 = time.perf_counter()  # the stage running once the run has taken 2 s is named
    mech, model = open_model(args)
    if args.simulate:
        traj = simulate_from_args(model, args, 401)
        supports = foundation_loads(mech, traj)
        mounted, modes = mounted_loads(mech, supports)
        with stage(f"report: writing {args.output}", args.progress, since=t0):
            out = report_trajectory(traj, args.output, title=args.title,
                                    animation=args.animation, trace=args.trace,
                                    supports=supports, mounted=mounted, modes=modes)
        print(f"{mech.name}: simulation {traj.status}; report: {out}")
        return finish(args, traj.success, f"{traj.status}: {traj.message}")

    over, values, _ = sweep_values(model, args)
    speed, why = speed_from_args(model, over, args)
    model, sw, ks = report_records(model, speed=speed, over=over, values=values,
                                   progress=args.progress, since=t0)
    with stage(f"report: writing {args.output} (plots"
               + (", animation)" if args.animation else ")"), args.progress, since=t0):
        out = write_report(model, args.output, sweep=sw, kinetostatics=ks, title=args.title,
                           animation=args.animation, trace=args.trace,
                           supports=foundation_loads(mech, ks))
    print(f"{mech.name}: report: {out}")
    print(speed_line(speed, bool(model.coord_is_angle[model.coordinate_index(over)]), why))
    for line in sw.summary().lines() if len(sw) else ():
        print("  " + line)
    problems = [] if sw.ok else [sw.message]
    if ks is not None and ks.status == Status.SINGULAR_POSITION:
        problems.append(ks.message)
    return finish(args, not problems, "; ".join(problems))


def report_records(mech_or_model, *, speed: float | None = None, over: str | None = None,
                   values=None, steps: int = 361, point=(0.0, 0.0),
                   progress: bool | None = False, since: float | None = None):
    """The analyses a :func:`report` shows: a sweep and the kinetostatic cycle.

    Runs a kinematic sweep of ``over`` and the kinetostatic cycle at that speed; the
    other independent coordinates of a mechanism with several degrees of freedom are
    held at their initial values (the report says so, with their holding torques).

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    speed : float, optional
        Constant rate of ``over``, rad/s (m/s for a travel).  Default: the model's own
        speed of ``over`` (:func:`mechdyn.cli.options.model_speed`: its initial rate if
        not zero, else the rated speed of its drive, else 1 with velocities then the
        velocity analogs).
    over : str, optional
        The coordinate to sweep (default the first).
    values : array_like, optional
        Its values, rad or m (default one full turn from its initial value for an
        angle, in ``steps`` positions; required for a travel).
    steps : int
        Number of positions of the default range (ends included).
    point : (float, float)
        Point of the frame moments (shaking moment), m.
    progress : bool or None
        Name each analysis on stderr while it runs: at once (True), never (False, the
        default) or once it has taken longer than 2 s (None, as the command does).
    since : float, optional
        The ``time.perf_counter()`` of the start of the run those 2 s count from
        (default the call).

    Returns
    -------
    model : Model
    sweep : KinematicSweep
    kinetostatics : Kinetostatics

    Raises
    ------
    ModelError
        Unknown coordinate, or a travel coordinate without ``values``.
    """
    model = as_model(mech_or_model)
    over = over if over is not None else model.coordinate_names[0]
    k = model.coordinate_index(over)
    if values is None:
        if not model.coord_is_angle[k]:
            raise ModelError(f"coordinate {over!r} is a travel: give its values")
        start = float(initial_coordinates(model)[k])
        values = np.linspace(start, start + 2 * np.pi, int(steps))
    values = np.asarray(values, dtype=float)
    if speed is None:
        speed = model_speed(model, over)[0]
    with stage(f"report: kinematics, {values.size} positions of {over}", progress,
               since=since):
        sw = run_sweep(model, over, values, speed=float(speed))
    q0 = initial_coordinates(model)
    hold = {c: float(q0[i]) for i, c in enumerate(model.coordinate_names) if c != over}
    with (warnings.catch_warnings(),
          stage(f"report: kinetostatics, {values.size} positions of {over}", progress,
                since=since)):
        warnings.simplefilter("ignore", KinetostaticsWarning)  # shown in the report
        try:  # the other coordinates held at their initial values
            ks = kinetostatics(model, over=over, speed=float(speed), values=values,
                               point=point, hold=hold or None)
        except ModelError:  # a coordinate that the mode fixes cannot be held: the sketch's
            ks = kinetostatics(model, over=over, speed=float(speed), values=values,
                               point=point)
    return model, sw, ks


def foundation_loads(mech, record):
    """The loads of the supports of ``mech.foundation`` (a
    :class:`~mechdyn.foundation.Foundation`, if the mechanism has one) over a run or a
    kinetostatic cycle, or None (no foundation, or a record without frame loads).

    The frame loads are taken as the machine exerts them (the weight of the frame and
    base is not added)."""
    fnd = getattr(mech, "foundation", None)
    if fnd is None or record is None:
        return None
    from ..foundation import support_loads

    try:
        return support_loads(fnd, record)
    except MechdynError as exc:
        warnings.warn(f"report: no support loads: {exc}", stacklevel=2)
        return None


def mounted_loads(mech, supports):
    """For a foundation with ``mass`` and ``inertia``: the base's response on its elastic
    mounts to the frame-load history of ``supports`` (a run's SupportLoads) and its natural
    frequencies, ``(MountedResponse, Modes)``; else ``(None, None)``."""
    fnd = getattr(mech, "foundation", None)
    if fnd is None or supports is None or fnd.mass is None or fnd.inertia is None:
        return None, None
    from ..foundation import mounted_response, natural_frequencies

    try:
        a = supports.applied
        return (mounted_response(fnd, supports.t, a[:, 0], a[:, 1], a[:, 2],
                                 point=supports.point), natural_frequencies(fnd))
    except MechdynError as exc:
        warnings.warn(f"report: no response of the mounted base: {exc}", stacklevel=2)
        return None, None


def report(mech_or_model, path, *, speed: float | None = None, over: str | None = None,
           values=None, steps: int = 361, title: str | None = None, animation: bool = True,
           trace=None, point=(0.0, 0.0)) -> Path:
    """Analyse a model over one turn and write an HTML report.

    :func:`report_records` runs the analyses (a sweep of ``over``; the kinetostatic
    cycle, other coordinates held), :func:`write_report` writes them, with the support
    loads of the mechanism's ``foundation`` when it has one.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    path : str or Path
        The HTML file to write.
    speed, over, values, steps, point
        As for :func:`report_records`.
    title : str, optional
    animation : bool
        Embed an animated GIF of the motion beside the plots (else its first frame).
    trace : "BODY.POINT" or (body, point), optional
        Draw this point's path.

    Returns
    -------
    Path
        The file written.
    """
    model, sw, ks = report_records(mech_or_model, speed=speed, over=over, values=values,
                                   steps=steps, point=point)
    return write_report(model, path, sweep=sw, kinetostatics=ks, title=title,
                        animation=animation, trace=trace,
                        supports=foundation_loads(model.mechanism, ks))
