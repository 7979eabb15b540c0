"""``mechdyn kinematics``: sweep one coordinate and write positions, velocities, accelerations.

Example::

    mechdyn kinematics slider_crank --from 0deg --to 360deg --steps 361 \\
        --speed 1500rpm -o crank.csv --plot crank.png

Exit codes: 0 done; 1 the sweep stopped at a dead position (the positions
before it are written); 2 bad input (one line on stderr).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from .. import examples
from ..errors import ModelError
from ..kinematics.sweep import initial_coordinates, sweep
from ..modelfile import load
from ..results.plot import plot_kinematic_sweep
from ..results.table import write_csv
from ..units import parse_quantity

__all__ = ["register", "run", "load_model"]


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
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example "
                        "(see `mechdyn examples`)")
    p.add_argument("--over", metavar="COORD",
                   help="coordinate to sweep (default: the only one); the others stay at "
                        "their initial values")
    p.add_argument("--from", dest="start", metavar="VALUE",
                   help="first value, e.g. 0deg (default: the initial value)")
    p.add_argument("--to", dest="stop", metavar="VALUE",
                   help="last value (default: one full turn after --from)")
    p.add_argument("--steps", type=int, default=361, metavar="N",
                   help="number of positions, ends included (default 361)")
    p.add_argument("--speed", metavar="RATE",
                   help="constant rate of the coordinate, e.g. 100rpm (default 1 rad/s or "
                        "1 m/s: velocities are then the velocity analogs)")
    p.add_argument("-o", "--output", metavar="CSV", help="write the table to this CSV file")
    p.add_argument("--plot", metavar="PNG", help="write a plot of the guided points")
    p.add_argument("--points", nargs="+", metavar="BODY.POINT",
                   help="points to plot (default: the sliders' points)")
    p.set_defaults(func=run)


def load_model(spec: str):
    """A :class:`~mechdyn.mechanism.Mechanism` from a file path or a bundled example name."""
    path = Path(spec)
    if path.is_file():
        return load(path)
    if path.suffix == ".toml" or path.parent != Path("."):
        raise FileNotFoundError(f"no model file {spec!r}")
    return examples.load(spec)  # a ModelError lists the bundled examples


def _fmt(value: float, angle: bool) -> str:
    return f"{np.rad2deg(value):.6g} deg" if angle else f"{value * 1e3:.6g} mm"


def run(args) -> int:
    """Run ``mechdyn kinematics``; returns the exit code."""
    mech = load_model(args.model)
    model = mech.compile()
    if args.over is None:
        if model.n_q != 1:
            raise ModelError("the model has several coordinates; choose one with --over: "
                             + ", ".join(model.coordinate_names))
        over = model.coordinate_names[0]
    else:
        over = args.over
    k = model.coordinate_index(over)
    angle = bool(model.coord_is_angle[k])
    kind = "angle" if angle else "length"
    if args.steps < 1:
        raise ModelError(f"--steps must be at least 1, got {args.steps}")
    start = (parse_quantity(args.start, kind, where="--from") if args.start is not None
             else float(initial_coordinates(model)[k]))
    if args.stop is not None:
        stop = parse_quantity(args.stop, kind, where="--to")
    elif angle:
        stop = start + 2 * np.pi
    else:
        raise ModelError(f"coordinate {over!r} is a travel: give the range with --from and --to")
    speed = None
    if args.speed is not None:
        speed = parse_quantity(args.speed, "angular_velocity" if angle else "velocity",
                               where="--speed")
    values = np.linspace(start, stop, args.steps)
    sw = sweep(model, over, values, speed=speed)

    rate = float(speed) if speed is not None else 1.0
    rate_txt = (f"{rate:.6g} rad/s = {rate * 30 / np.pi:.6g} rpm" if angle
                else f"{rate:.6g} m/s")
    print(f"{mech.name}: {len(sw)} of {values.size} positions, {over} from "
          f"{_fmt(start, angle)} to {_fmt(stop, angle)} at {rate_txt}")
    for line in sw.summary().lines():
        print("  " + line)
    if args.output:
        print(f"  table: {write_csv(sw, args.output)}")
    if args.plot:
        print(f"  plot: {plot_kinematic_sweep(sw, args.plot, points=args.points)}")
    if sw.status != "success":
        print(f"mechdyn kinematics: warning: {sw.message}", file=sys.stderr)
        return 1
    return 0
