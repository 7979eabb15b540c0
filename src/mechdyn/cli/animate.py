"""``mechdyn animate``: an animated GIF (or MP4) of a mechanism's motion.

Examples::

    mechdyn animate four_bar --trace coupler.P -o four_bar.gif
    mechdyn animate slider_crank --over phi --from 0deg --to 360deg --steps 121 -o crank.gif
    mechdyn animate slider_crank --simulate --t-end 0.05s -o run.gif --snapshot start.png

Exit codes: 0 done; 1 the motion stopped early (dead position, or a simulation
that stopped; the frames computed so far are written); 2 bad input.
"""

from __future__ import annotations

import sys

import numpy as np

from ..errors import ModelError
from ..kinematics.sweep import initial_coordinates, sweep
from ..results.animate import _trace_spec, animate, check_animation_path, snapshot
from ..simulate import simulate
from ..units import parse_quantity
from .kinematics import load_model

__all__ = ["register", "run", "sweep_values"]


def register(sub) -> None:
    """Add the ``animate`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "animate",
        help="animated GIF of the motion (a sweep of one coordinate, or a simulation)",
        description="Draw the mechanism -- bodies through their points, joints, ground "
                    "anchors, slider guides, optionally the path of a point -- at every "
                    "position of a sweep of one coordinate (default: one turn of the first) "
                    "or of a forward-dynamics run (--simulate), and write a GIF (MP4 if "
                    "ffmpeg is installed).",
        epilog="Quantities take units: 0deg, 360 deg, 15 mm, 0.05s, 20 ms (a bare number is "
               "SI). Exit codes: 0 done, 1 the motion stopped early (frames so far written), "
               "2 bad input.")
    d = add_motion_arguments(p, "FILE", "animation to write: .gif (or .mp4 with ffmpeg)",
                             steps=121, verb="animate",
                             title="title above the drawing (default: the model's name)")
    d.add_argument("--fps", type=int, default=25, help="frames per second (default 25)")
    d.add_argument("--frames", type=int, metavar="N",
                   help="number of frames (default: all positions, at most 200)")
    d.add_argument("--snapshot", metavar="PNG", help="also write the first frame as a PNG")
    p.set_defaults(func=run)


def add_motion_arguments(p, metavar: str, output: str, *, steps: int, verb: str, title: str):
    """Add what ``mechdyn animate`` and ``report`` share: model, -o, sweep and simulation
    groups; returns the drawing group (``--trace``, ``--title``)."""
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example")
    p.add_argument("-o", "--output", required=True, metavar=metavar, help=output)
    g = p.add_argument_group("sweep (default)")
    g.add_argument("--over", metavar="COORD", help="coordinate to sweep (default: the first)")
    g.add_argument("--from", dest="start", metavar="VALUE",
                   help="first value, e.g. 0deg (default: the initial value)")
    g.add_argument("--to", dest="stop", metavar="VALUE",
                   help="last value (default: one full turn after --from)")
    g.add_argument("--steps", type=int, default=steps, metavar="N",
                   help=f"number of positions, ends included (default {steps})")
    s = p.add_argument_group("simulation")
    s.add_argument("--simulate", action="store_true",
                   help=f"{verb} a forward-dynamics run from the model's initial state")
    s.add_argument("--t-end", metavar="TIME", help="end time of the run, e.g. 0.05s")
    s.add_argument("--integrator", default="dop853", metavar="NAME",
                   help="integrator (default dop853; see `mechdyn simulate --help`)")
    s.add_argument("--rtol", type=float,
                   help="relative tolerance of the adaptive integrators (default 1e-10)")
    d = p.add_argument_group("drawing")
    d.add_argument("--trace", metavar="BODY.POINT", help="draw the path of this point")
    d.add_argument("--title", help=title)
    return d


def simulate_from_args(model, args, samples: int):
    """The forward-dynamics run of ``--simulate`` (needs ``--t-end``), ``samples`` samples."""
    if args.t_end is None:
        raise ModelError("--simulate needs --t-end, e.g. --t-end 0.05s")
    t_end = parse_quantity(args.t_end, "time", where="--t-end")
    return simulate(model, t_end, integrator=args.integrator, rtol=args.rtol, progress=False,
                    t_eval=np.linspace(0.0, t_end, samples))


def sweep_values(model, over: str | None, start: str | None, stop: str | None, steps: int):
    """The swept coordinate and its values from command-line text (units parsed).

    Returns
    -------
    (str, ndarray)
        The coordinate's name and ``steps`` values from ``start`` (default its
        initial value) to ``stop`` (default one turn later; required for a travel).
    """
    over = over if over is not None else model.coordinate_names[0]
    k = model.coordinate_index(over)
    angle = bool(model.coord_is_angle[k])
    kind = "angle" if angle else "length"
    if steps < 1:
        raise ModelError(f"--steps must be at least 1, got {steps}")
    a = (parse_quantity(start, kind, where="--from") if start is not None
         else float(initial_coordinates(model)[k]))
    if stop is not None:
        b = parse_quantity(stop, kind, where="--to")
    elif angle:
        b = a + 2 * np.pi
    else:
        raise ModelError(f"coordinate {over!r} is a travel: give the range with --from and --to")
    return over, np.linspace(a, b, steps)


def run(args) -> int:
    """Run ``mechdyn animate``; returns the exit code."""
    check_animation_path(args.output)  # before any computing
    mech = load_model(args.model)
    model = mech.compile()
    _trace_spec(model, args.trace)
    if args.simulate:
        n = args.frames if args.frames is not None else 200
        record = simulate_from_args(model, args, max(int(n), 2))
        ok, why = record.success, f"{record.status}: {record.message}"
        print(f"{mech.name}: simulated to t = {record.t[-1] if record.t.size else 0:.6g} s "
              f"({record.status})")
    else:
        over, values = sweep_values(model, args.over, args.start, args.stop, args.steps)
        record = sweep(model, over, values)
        ok, why = record.ok, record.message
        print(f"{mech.name}: {len(record)} of {values.size} positions of {over}")
    out = animate(record, args.output, fps=args.fps, frames=args.frames, trace=args.trace,
                  title=args.title)
    print(f"  animation: {out}")
    if args.snapshot:
        still = snapshot(record, args.snapshot, 0, trace=args.trace, title=args.title)
        print(f"  snapshot: {still}")
    if not ok:
        print(f"mechdyn animate: warning: the motion stopped early: {why}", file=sys.stderr)
        return 1
    return 0
