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
"""

from __future__ import annotations

import sys

from ..errors import Status

__all__ = ["register", "run"]


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
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example")
    p.add_argument("-o", "--output", required=True, metavar="HTML", help="report to write")
    p.add_argument("--speed", metavar="RATE",
                   help="constant rate of the swept coordinate, e.g. 60rpm (default: the "
                        "model's initial rate, else 1 rad/s)")
    p.add_argument("--over", metavar="COORD", help="coordinate to sweep (default: the first)")
    p.add_argument("--from", dest="start", metavar="VALUE",
                   help="first value (default: the initial value)")
    p.add_argument("--to", dest="stop", metavar="VALUE",
                   help="last value (default: one full turn after --from)")
    p.add_argument("--steps", type=int, default=361, metavar="N",
                   help="number of positions, ends included (default 361)")
    p.add_argument("--animation", action="store_true", help="embed an animated GIF")
    p.add_argument("--trace", metavar="BODY.POINT", help="draw the path of this point")
    p.add_argument("--title", help="title of the report")
    p.add_argument("--simulate", action="store_true",
                   help="report a forward-dynamics run from the initial state instead")
    p.add_argument("--t-end", metavar="TIME", help="end time of the run, e.g. 0.05s")
    p.add_argument("--integrator", default="dop853", metavar="NAME",
                   help="integrator of --simulate (default dop853)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``mechdyn report``; returns the exit code."""
    from ..errors import ModelError
    from ..units import parse_quantity
    from .animate import sweep_values
    from .kinematics import load_model

    mech = load_model(args.model)
    model = mech.compile()
    if args.simulate:
        import numpy as np

        from ..results.report import report_trajectory
        from ..simulate import simulate

        if args.t_end is None:
            raise ModelError("--simulate needs --t-end, e.g. --t-end 0.05s")
        t_end = parse_quantity(args.t_end, "time", where="--t-end")
        traj = simulate(model, t_end, integrator=args.integrator, progress=False,
                        t_eval=np.linspace(0.0, t_end, 401))
        out = report_trajectory(traj, args.output, title=args.title, animation=args.animation,
                                trace=args.trace)
        print(f"{mech.name}: simulation {traj.status}; report: {out}")
        if not traj.success:
            print(f"mechdyn report: warning: {traj.status}: {traj.message}", file=sys.stderr)
            return 1
        return 0

    from ..results.report import report_records, write_report

    over, values = sweep_values(model, args.over, args.start, args.stop, args.steps)
    k = model.coordinate_index(over)
    speed = None
    if args.speed is not None:
        angle = bool(model.coord_is_angle[k])
        speed = parse_quantity(args.speed, "angular_velocity" if angle else "velocity",
                               where="--speed")
    model, sw, ks = report_records(model, speed=speed, over=over, values=values)
    out = write_report(model, args.output, sweep=sw, kinetostatics=ks, title=args.title,
                       animation=args.animation, trace=args.trace)
    print(f"{mech.name}: report: {out}")
    for line in sw.summary().lines() if len(sw) else ():
        print("  " + line)
    problems = [] if sw.ok else [sw.message]
    if ks is not None and ks.status == Status.SINGULAR_POSITION:
        problems.append(ks.message)
    for msg in problems:
        print(f"mechdyn report: warning: {msg}", file=sys.stderr)
    return 1 if problems else 0
