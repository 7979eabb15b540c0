"""``mechdyn kinematics``: sweep one coordinate and write positions, velocities, accelerations.

Example::

    mechdyn kinematics slider_crank --from 0deg --to 360deg --steps 361 \\
        --speed 1500rpm -o crank.csv --plot crank.png

Exit codes: 0 done; 1 the sweep stopped at a dead position (the positions
before it are written); 2 bad input (one line on stderr).
"""

from __future__ import annotations

from ..kinematics.sweep import sweep
from ..progress import stage
from ..results.frame_geometry import trace_spec
from ..results.plot import plot_kinematic_sweep
from ..results.table import deg_or_mm
from .options import (
    add_files,
    add_model,
    add_plot_columns,
    add_points,
    add_progress,
    add_range,
    add_speed,
    check_plot_columns,
    finish,
    open_model,
    preview_record,
    speed_from_args,
    speed_line,
    sweep_values,
    write_files,
)

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``kinematics`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "kinematics",
        help="sweep one coordinate: positions, velocities, accelerations, dead centres",
        description="Drive one generalized coordinate through a range at constant speed and "
                    "write the positions, velocities and accelerations of every body and "
                    "named point (CSV, columns with unit suffixes), optionally a plot; "
                    "print the strokes, dead centres and transmission angles.",
        epilog="Quantities take units: 0deg, 360 deg, 1.2 rad, 15 mm, 100rpm, 43.5 rad/s "
               "(a bare number is SI: rad, m, rad/s). Exit codes: 0 done, 1 stopped at a "
               "dead position (positions before it are written), 2 bad input.")
    add_model(p)
    add_range(p, steps=361, over="coordinate to sweep (default: the only one); the others "
                                 "stay at their initial values")
    add_speed(p, "constant rate of the coordinate")
    add_files(p, plot="write a plot of the guided points")
    add_points(p, "to plot", "the sliders' points; the table has every named point")
    p.add_argument("--trace", metavar="BODY.POINT",
                   help="plot the coupler curve of this point (default: a coupler point of a "
                        "four-bar loop, if any)")
    add_plot_columns(p)
    add_progress(p)


def run(args) -> int:
    """Run ``mechdyn kinematics``; returns the exit code."""
    check_plot_columns(args)
    mech, model = open_model(args)
    trace_spec(model, args.trace)
    over, values, _ = sweep_values(model, args, only=True)
    speed, why = speed_from_args(model, over, args)
    if args.plot_columns is not None:  # the columns before the sweep
        check_plot_columns(args, preview_record(lambda: sweep(model, over, values[:2],
                                                              speed=speed)))
    with stage(f"kinematics: sweeping {over} over {values.size} positions", args.progress):
        sw = sweep(model, over, values, speed=speed)
    ends, unit = deg_or_mm(values[[0, -1]], sw.over_is_angle)
    print(f"{mech.name}: {len(sw)} of {values.size} positions, {over} from "
          f"{ends[0]:.6g} {unit} to {ends[1]:.6g} {unit}; status {sw.status}")
    print(speed_line(speed, sw.over_is_angle, why))
    for line in sw.summary().lines():
        print("  " + line)
    points = args.points if args.points != [] else [f"{b}.{n}" for b, n in model.named_points()]
    write_files(args, sw, plot_kinematic_sweep, points=points, trace=args.trace)
    return finish(args, sw.status == "success", sw.message)
