"""``mechdyn report``: one self-contained HTML report of a model for an engineer.

Examples::

    mechdyn report slider_crank --speed 1500rpm -o slider_crank.html
    mechdyn report four_bar --animation --trace coupler.P -o four_bar.html
    mechdyn report slider_crank --simulate --t-end 0.05s -o run.html

The report holds the model (bodies, joints, coordinates, loads and drives in
tables with units), the kinematic sweep summary (strokes, dead centres,
transmission angles, extreme speeds and accelerations) with its plot and, for
one degree of freedom or a given ``--speed``, the kinetostatic cycle (peak and
RMS driving torque, peak joint forces, shaking-force harmonics) with its plot;
with ``--simulate``, the run summary, energy balance and events instead.

Exit codes: 0 done; 1 an analysis stopped early (the report says where); 2 bad input.
The analyses are composed here and written by :mod:`mechdyn.results.report`.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..dynamics.kinetostatics import KinetostaticsWarning, kinetostatics
from ..errors import ModelError, Status
from ..kinematics.sweep import initial_coordinates
from ..kinematics.sweep import sweep as run_sweep
from ..model import as_model
from ..results.report import report_trajectory, write_report
from .options import add_motion_arguments, finish, open_model, simulate_from_args, sweep_values

__all__ = ["register", "run", "report", "report_records"]


def register(sub) -> None:
    """Add the ``report`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "report",
        help="self-contained HTML report: model, kinematics, kinetostatics (or a simulation)",
        description="Write one HTML file (tables and embedded PNG plots) describing the model "
                    "and its kinematics over one turn and, for one degree of freedom or with "
                    "--speed, its kinetostatic cycle; with --simulate, a forward-dynamics run.",
        epilog="Quantities take units: 60rpm, 0deg, 360 deg, 0.05s (a bare number is SI). "
               "Exit codes: 0 done, 1 an analysis stopped early, 2 bad input.")
    d = add_motion_arguments(p, "HTML", "report to write", steps=361, verb="report",
                             title="title of the report")
    d.add_argument("--animation", action="store_true", help="embed an animated GIF")
    p.add_argument("--speed", metavar="RATE",
                   help="constant rate of the swept coordinate, e.g. 60rpm (default: the "
                        "model's initial rate, else 1 rad/s)")


def run(args) -> int:
    """Run ``mechdyn report``; returns the exit code."""
    mech, model = open_model(args)
    if args.simulate:
        traj = simulate_from_args(model, args, 401)
        out = report_trajectory(traj, args.output, title=args.title, animation=args.animation,
                                trace=args.trace)
        print(f"{mech.name}: simulation {traj.status}; report: {out}")
        return finish(args, traj.success, f"{traj.status}: {traj.message}")

    over, values, speed = sweep_values(model, args)
    model, sw, ks = report_records(model, speed=speed, over=over, values=values)
    out = write_report(model, args.output, sweep=sw, kinetostatics=ks, title=args.title,
                       animation=args.animation, trace=args.trace)
    print(f"{mech.name}: report: {out}")
    for line in sw.summary().lines() if len(sw) else ():
        print("  " + line)
    problems = [] if sw.ok else [sw.message]
    if ks is not None and ks.status == Status.SINGULAR_POSITION:
        problems.append(ks.message)
    return finish(args, not problems, "; ".join(problems))


def report_records(mech_or_model, *, speed: float | None = None, over: str | None = None,
                   values=None, steps: int = 361, point=(0.0, 0.0)):
    """The analyses a :func:`report` shows: a sweep and, when it applies, the kinetostatics.

    Runs a kinematic sweep of ``over`` and -- for a mechanism with one degree of
    freedom, or when ``speed`` is given -- the kinetostatic cycle at that speed.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    speed : float, optional
        Constant rate of ``over``, rad/s (m/s for a travel).  Default: the model's
        initial rate of ``over`` if it is not zero, else 1 (velocities are then the
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

    Returns
    -------
    model : Model
    sweep : KinematicSweep
    kinetostatics : Kinetostatics or None

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
    given_speed = speed is not None
    if speed is None:
        qd0 = (model.mechanism.extras.get("initial") or {}).get("qdot") or {}
        speed = (float(qd0.get(over, 0.0)) if isinstance(qd0, dict) else 0.0) or 1.0
    sw = run_sweep(model, over, values, speed=float(speed))
    ks = None
    if given_speed or model.mechanism.dof == 1:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", KinetostaticsWarning)  # shown in the report
            ks = kinetostatics(model, over=over, speed=float(speed), values=values,
                               point=point)
    return model, sw, ks


def report(mech_or_model, path, *, speed: float | None = None, over: str | None = None,
           values=None, steps: int = 361, title: str | None = None, animation: bool = False,
           trace=None, point=(0.0, 0.0)) -> Path:
    """Analyse a model over one turn and write an HTML report.

    :func:`report_records` runs the analyses (a sweep of ``over``; the kinetostatic
    cycle for one degree of freedom or a given ``speed``), :func:`write_report`
    writes them.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    path : str or Path
        The HTML file to write.
    speed, over, values, steps, point
        As for :func:`report_records`.
    title : str, optional
    animation : bool
        Embed an animated GIF of the motion.
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
                        animation=animation, trace=trace)
