"""``mechdyn reduce``: reduced moment of inertia and reduced torque over a cycle.

Example::

    mechdyn reduce slider_crank --steps 361 -o reduced.csv --plot reduced.png
    mechdyn reduce clutchless_press --engage rocker_lock=0mm,0mm,0deg --drop psi \\
        --motor 4A80B4U3 --gear-ratio 3.4 --efficiency 0.95 --speed 43.5rad/s

Exit codes: 0 done; 1 the reduced quantities are infinite somewhere (a link of
reduction that stops); 2 bad input (one line on stderr).
"""

from __future__ import annotations

import argparse

import numpy as np

from ..errors import ModelError
from ..kinematics.sweep import initial_coordinates
from ..progress import stage
from ..reduction.reduce import reduce_model
from ..results.frame_geometry import trace_spec
from ..results.plot_reduction import plot_reduction
from .options import (
    add_files,
    add_model_arguments,
    add_progress,
    add_speed,
    add_start,
    finish,
    prepare_model,
    quantity,
    speed_from_args,
    speed_line,
    write_files,
)

__all__ = ["register", "run"]


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
    p.add_argument("--mass-at", metavar="BODY.POINT",
                   help="also give the reduced mass at this named point, e.g. crank.A")
    p.add_argument("--point", dest="mass_at", help=argparse.SUPPRESS)
    p.add_argument("--steps", type=int, default=361, metavar="N",
                   help="positions over one turn, ends included (default 361)")
    add_start(p, "first position of the turn")
    add_speed(p, "speed of the coordinate (with --link: of the link) at which drives and "
                 "velocity-dependent loads are evaluated")
    add_files(p, plot="write a plot of J_red, dJ_red/dphi, M_red")
    add_progress(p)


def run(args) -> int:
    """Run ``mechdyn reduce``; returns the exit code."""
    mech, model = prepare_model(args)
    if args.steps < 2:
        raise ModelError(f"--steps must be at least 2, got {args.steps}")
    point = trace_spec(model, args.mass_at, "--mass-at")
    coordinate = model.coordinate_names[0] if model.n_q == 1 else None
    if coordinate is None:  # reduce_model names the coordinates
        speed, why, start = 1.0, "", 0.0
    else:
        speed, why = speed_from_args(model, coordinate, args)
        if args.link is not None and args.speed is None:
            why += f", taken as the speed of link {args.link!r}"
        start = (float(initial_coordinates(model)[0]) if args.start is None
                 else quantity(args.start, "angle", "--from"))
    with stage(f"reduce: {args.steps} positions", args.progress):
        red = reduce_model(model, link=args.link, point=point, steps=args.steps,
                           start=start, omega=speed)
    fin = np.isfinite(red.J_total)
    where = f"link {red.link!r}" if red.link else f"coordinate {red.coordinate!r}"
    print(f"{mech.name}: reduction to {where}, {red.phi.size} positions from "
          f"{np.degrees(red.phi[0]):.6g} deg; status {red.status}")
    print(speed_line(speed, red.link is not None or bool(model.coord_is_angle[0]), why))
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
            print(f"  m_red at {args.mass_at}: min {np.min(red.m_red[fin]):.6g}  max "
                  f"{np.max(red.m_red[fin]):.6g} kg")
    write_files(args, red, plot_reduction, title=f"{mech.name}: reduction")
    return finish(args, red.status == "success", red.message)
