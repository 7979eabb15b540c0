"""``mechdyn kinetostatics``: driving torque, joint reactions and frame loads over a cycle.

Example::

    mechdyn kinetostatics toggle_press --speed 40rpm --from 0deg --to 360deg \\
        --steps 361 --point 0,0 -o forces.csv --plot forces.png

Exit codes: 0 done; 1 done with a warning that matters (singular positions);
2 bad input (one line on stderr).
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from ..dynamics.kinetostatics import KinetostaticsWarning, kinetostatics
from ..errors import ModelError, Status, UnitError
from ..results.plot_kinetostatics import plot_kinetostatics
from ..units import parse_quantity
from .kinematics import load_model

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``kinetostatics`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "kinetostatics",
        help="driving torque, every joint reaction, frame and foundation loads",
        description="Drive one coordinate at constant speed (0 for statics) and compute the "
                    "torque the drive must apply, the reaction of every joint (force on the "
                    "child from the parent, at the joint point) and the loads the frame "
                    "receives (shaking force and moment); write a CSV with unit-suffixed "
                    "columns and optionally a plot; print peaks, RMS torque and harmonics.",
        epilog="Quantities take units: 0deg, 360 deg, 40rpm, 4.2 rad/s, 15 mm (a bare number "
               "is SI: rad, m, rad/s). Exit codes: 0 done, 1 singular positions, 2 bad input.")
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example "
                        "(see `mechdyn examples`)")
    p.add_argument("--over", metavar="COORD",
                   help="driven coordinate (default: the first); other independent "
                        "coordinates are held at their initial values")
    p.add_argument("--speed", required=True, metavar="RATE",
                   help="constant speed of the driven coordinate, e.g. 60rpm (0 for statics)")
    p.add_argument("--from", dest="start", default=None, metavar="VALUE",
                   help="first position (default 0deg)")
    p.add_argument("--to", dest="stop", default=None, metavar="VALUE",
                   help="last position (default one full turn after --from)")
    p.add_argument("--steps", type=int, default=361, metavar="N",
                   help="number of positions, ends included (default 361)")
    p.add_argument("--point", default="0,0", metavar="X,Y",
                   help="point of the frame moments (shaking moment), e.g. 0,0 or "
                        "'100mm,-50mm' (default 0,0)")
    p.add_argument("--mode", default=None, metavar="LOCK[,LOCK...]",
                   help="engaged locks, comma separated (default: as in the model; "
                        "'none' releases all)")
    p.add_argument("--bed", nargs="+", default=(), metavar="LOAD",
                   help="force loads whose reaction the frame carries (e.g. the punch force "
                        "on a press bed)")
    p.add_argument("-o", "--output", metavar="CSV", help="write the table to this CSV file")
    p.add_argument("--plot", metavar="PNG", help="write a plot (torque, pin forces, shaking)")
    p.add_argument("--joints", nargs="+", metavar="JOINT",
                   help="joints whose forces are plotted (default: all)")
    p.add_argument("--harmonics", type=int, default=6, metavar="K",
                   help="print the shaking-force harmonics up to order K (default 6; 0: none)")
    p.set_defaults(func=run)


def _point(text: str):
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 2:
        raise UnitError(f"--point: {text!r}: expected two lengths X,Y, e.g. 0,0 or 100mm,-50mm")
    return tuple(parse_quantity(p, "length", where="--point") for p in parts)


def run(args) -> int:
    """Run ``mechdyn kinetostatics``; returns the exit code."""
    mech = load_model(args.model)
    model = mech.compile()
    over = args.over if args.over is not None else model.coordinate_names[0]
    k = model.coordinate_index(over)
    angle = bool(model.coord_is_angle[k])
    kind = "angle" if angle else "length"
    if args.steps < 1:
        raise ModelError(f"--steps must be at least 1, got {args.steps}")
    start = parse_quantity(args.start, kind, where="--from") if args.start is not None else 0.0
    if args.stop is not None:
        stop = parse_quantity(args.stop, kind, where="--to")
    elif angle:
        stop = start + 2 * np.pi
    else:
        raise ModelError(f"coordinate {over!r} is a travel: give the range with --from and --to")
    speed = parse_quantity(args.speed, "angular_velocity" if angle else "velocity",
                           where="--speed")
    point = _point(args.point)
    mode = None
    if args.mode is not None:
        mode = (frozenset() if args.mode.strip().lower() == "none"
                else frozenset(m.strip() for m in args.mode.split(",") if m.strip()))
    values = np.linspace(start, stop, args.steps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinetostaticsWarning)  # printed below
        res = kinetostatics(model, over=over, speed=speed, values=values, point=point,
                            mode=mode, reacting_loads=tuple(args.bed))
    rate = (f"{speed:.6g} rad/s = {speed * 30 / np.pi:.6g} rpm" if angle
            else f"{speed:.6g} m/s")
    print(f"{mech.name}: kinetostatics at {rate}")
    for line in res.summary().splitlines():
        print("  " + line if not line.startswith("  ") else line)
    if args.harmonics > 0 and angle and speed != 0:
        try:
            h = res.harmonics(args.harmonics)
        except ValueError:
            h = None
        if h is not None:
            print("  shaking harmonics (order: |Fx| |Fy| N, |M| N m):")
            for _, row in h.iterrows():
                print(f"    {int(row['order']):3d} ({row['f_Hz']:.4g} Hz): "
                      f"{row['Fx_frame_N']:.6g} {row['Fy_frame_N']:.6g} "
                      f"{row['M_frame_Nm']:.6g}")
    if args.output:
        res.to_dataframe().to_csv(args.output, index=False)
        print(f"  table: {args.output}")
    if args.plot:
        print(f"  plot: {plot_kinetostatics(res, args.plot, joints=args.joints)}")
    if res.status == Status.SINGULAR_POSITION:
        print(f"mechdyn kinetostatics: warning: {res.message}", file=sys.stderr)
        return 1
    return 0
