"""``mechdyn reduce``: reduced moment of inertia and reduced torque over a cycle.

Example::

    mechdyn reduce slider_crank --steps 361 -o reduced.csv --plot reduced.png
    mechdyn reduce clutchless_press --engage rocker_lock=0mm,0mm,0deg --drop psi \\
        --motor 4A80B4U3 --gear-ratio 3.4 --efficiency 0.95 --speed 43.5rad/s

Exit codes: 0 done; 1 the reduced quantities are infinite somewhere (a link of
reduction that stops); 2 bad input (one line on stderr).
"""

from __future__ import annotations

import sys

import numpy as np

from ..dynamics.reduction import mode_mechanism, reduce_model
from ..errors import ModelError
from ..modelfile.drives import drive_from_table
from ..results.plot_reduction import plot_reduction
from ..results.table import write_csv
from ..units import parse_quantity, parse_vector
from .kinematics import load_model

__all__ = ["register", "run", "add_model_arguments", "prepare_model"]


def add_model_arguments(p) -> None:
    """Arguments shared by ``reduce`` and ``flywheel``: the model, its mode and its drive."""
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example "
                        "(see `mechdyn examples`)")
    p.add_argument("--engage", action="append", default=[], metavar="LOCK[=X,Y,THETA]",
                   help="engage a lock (repeatable), optionally with the pose it holds, "
                        "e.g. rocker_lock=0mm,0mm,0deg")
    p.add_argument("--drop", action="append", default=[], metavar="COORD",
                   help="remove a coordinate frozen by the engaged locks (repeatable)")
    p.add_argument("--motor", metavar="DESIGNATION",
                   help="replace the drives by a catalogue induction motor, e.g. 4A80B4U3")
    p.add_argument("--characteristic", choices=("kloss", "extended"), default="kloss",
                   help="form of the motor characteristic (default kloss)")
    p.add_argument("--gear-ratio", metavar="I",
                   help="ratio omega_motor/omega_crank of a gear stage after the motor")
    p.add_argument("--efficiency", metavar="ETA", help="efficiency of the gear stage (0..1]")


def prepare_model(args):
    """(mechanism, model) from the common arguments: load, mode, drive; compiled."""
    mech = load_model(args.model)
    engage, offsets = [], {}
    for spec in args.engage:
        name, sep, pose = spec.partition("=")
        engage.append(name)
        if sep:
            parts = pose.split(",")
            if len(parts) != 3:
                raise ModelError(f"--engage {spec!r}: give the pose as X,Y,THETA, e.g. "
                                 f"{name}=0mm,0mm,0deg")
            offsets[name] = parse_vector(parts, ("length", "length", "angle"),
                                         where=f"--engage {name}")
    if engage or args.drop:
        mech = mode_mechanism(mech, engage=engage, offsets=offsets, drop=args.drop)
    if args.motor is None and (args.gear_ratio is not None or args.efficiency is not None):
        raise ModelError("--gear-ratio and --efficiency need --motor")
    if args.motor is not None:
        coords = list(mech.coordinates)
        if len(coords) != 1:
            raise ModelError(f"--motor: the model has coordinates {', '.join(coords)}; "
                             f"reduce it to one (--engage LOCK --drop COORD)")
        table = {"type": "induction_motor", "name": "motor", "coordinate": coords[0],
                 "catalogue": args.motor, "characteristic": args.characteristic}
        if args.gear_ratio is not None:
            table["gear_ratio"] = args.gear_ratio
        if args.efficiency is not None:
            table["efficiency"] = args.efficiency
        mech.drives[:] = [drive_from_table(table, "--motor")]
    return mech, mech.compile()


def register(sub) -> None:
    """Add the ``reduce`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "reduce",
        help="reduced moment of inertia and reduced torque of a 1-DOF mechanism",
        description="Tabulate over one cycle the reduced moment of inertia J_red = 2T/omega^2, "
                    "its derivative dJ_red/dphi and the reduced torque M_red of all forces and "
                    "drives (equal power), for the coordinate or a chosen link; CSV columns "
                    "carry units.",
        epilog="Quantities take units: 43.5rad/s, 415rpm (a bare number is SI). Exit codes: "
               "0 done, 1 infinite reduced quantities (the link of reduction stops), "
               "2 bad input.")
    add_model_arguments(p)
    p.add_argument("--link", metavar="BODY",
                   help="link of reduction (default: the generalized coordinate itself)")
    p.add_argument("--point", metavar="BODY.POINT", help="also give the reduced mass at a point")
    p.add_argument("--steps", type=int, default=361, metavar="N",
                   help="positions over one turn, ends included (default 361)")
    p.add_argument("--start", metavar="ANGLE", default="0deg",
                   help="first position (default 0deg)")
    p.add_argument("--speed", metavar="RATE",
                   help="speed of the link at which drives and velocity-dependent loads are "
                        "evaluated (default 1 rad/s; give the working speed for motors)")
    p.add_argument("-o", "--output", metavar="CSV", help="write the table to this CSV file")
    p.add_argument("--plot", metavar="PNG", help="write a plot of J_red, dJ_red/dphi, M_red")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``mechdyn reduce``; returns the exit code."""
    mech, model = prepare_model(args)
    if args.steps < 2:
        raise ModelError(f"--steps must be at least 2, got {args.steps}")
    point = None
    if args.point:
        body, sep, name = args.point.partition(".")
        if not sep:
            raise ModelError(f"--point {args.point!r}: write it as BODY.POINT, e.g. crank.A")
        point = (body, name)
    speed = 1.0 if args.speed is None else parse_quantity(args.speed, "angular_velocity",
                                                          where="--speed")
    start = parse_quantity(args.start, "angle", where="--start")
    red = reduce_model(model, link=args.link, point=point, steps=args.steps, start=start,
                       omega=speed)
    J = red.J_total
    fin = np.isfinite(J)
    where = f"link {red.link!r}" if red.link else f"coordinate {red.coordinate!r}"
    print(f"{mech.name}: reduction to {where}, {red.phi.size} positions from "
          f"{np.degrees(red.phi[0]):.6g} deg")
    if np.any(fin):
        print(f"  J_red     min {np.min(red.J_red[fin]):.6g}  max {np.max(red.J_red[fin]):.6g}  "
              f"mean {np.mean(red.J_red[fin][:-1] if fin.all() else red.J_red[fin]):.6g} kg m^2")
        if np.any(red.J_extra):
            print(f"  J_extra   {red.J_extra[fin][0]:.6g} kg m^2 (drives: rotor and gear, "
                  f"reduced)")
        print(f"  M_red     min {np.min(red.M_red[fin]):.6g}  max {np.max(red.M_red[fin]):.6g} "
              f"N m at {speed:.6g} rad/s (forces {np.min(red.M_forces[fin]):.6g} .. "
              f"{np.max(red.M_forces[fin]):.6g}, drive {np.min(red.M_drive[fin]):.6g} .. "
              f"{np.max(red.M_drive[fin]):.6g})")
        if red.m_red is not None:
            print(f"  m_red at {args.point}: min {np.min(red.m_red[fin]):.6g}  max "
                  f"{np.max(red.m_red[fin]):.6g} kg")
    if args.output:
        print(f"  table: {write_csv(red, args.output)}")
    if args.plot:
        print(f"  plot: {plot_reduction(red, args.plot, title=f'{mech.name}: reduction')}")
    if red.status != "success":
        print(f"mechdyn reduce: warning: {red.message}", file=sys.stderr)
        return 1
    return 0
