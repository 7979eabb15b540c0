"""``mechdyn kinematics``: sweep one coordinate and write positions, velocities, accelerations.

Example::

    mechdyn kinematics slider_crank --from 0deg --to 360deg --steps 361 \\
        --speed 1500rpm -o crank.csv --plot crank.png

Exit codes: 0 done; 1 the sweep stopped at a dead position (the positions
before it are written); 2 bad input (one line on stderr).
"""

from __future__ import annotations

from ..kinematics.sweep import sweep
from ..results.animate import _trace_spec
from ..results.plot import plot_kinematic_sweep
from ..results.table import deg_or_mm, rate_text
from .options import (
    add_files,
    add_model,
    add_plot_columns,
    add_range,
    check_plot_columns,
    finish,
    open_model,
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
    p.add_argument("--speed", metavar="RATE",
                   help="constant rate of the coordinate, e.g. 100rpm (default 1 rad/s or "
                        "1 m/s: velocities are then the velocity analogs)")
    add_files(p, plot="write a plot of the guided points")
    p.add_argument("--points", nargs="+", metavar="BODY.POINT",
                   help="points to plot (default: the sliders' points)")
    p.add_argument("--trace", metavar="BODY.POINT",
                   help="plot the coupler curve of this point (default: a coupler point of a "
                        "four-bar loop, if any)")
    add_plot_columns(p)


def run(args) -> int:
    """Run ``mechdyn kinematics``; returns the exit code."""
    check_plot_columns(args)
    mech, model = open_model(args)
    _trace_spec(model, args.trace)
    over, values, speed = sweep_values(model, args, only=True)
    sw = sweep(model, over, values, speed=speed)
    ends, unit = deg_or_mm(values[[0, -1]], sw.over_is_angle)
    print(f"{mech.name}: {len(sw)} of {values.size} positions, {over} from "
          f"{ends[0]:.6g} {unit} to {ends[1]:.6g} {unit} at "
          f"{rate_text(1.0 if speed is None else speed, sw.over_is_angle)}")
    for line in sw.summary().lines():
        print("  " + line)
    write_files(args, sw, plot_kinematic_sweep, points=args.points, trace=args.trace)
    return finish(args, sw.status == "success", sw.message)
