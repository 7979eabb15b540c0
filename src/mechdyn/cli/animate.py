"""``mechdyn animate``: an animated GIF (or MP4) of a mechanism's motion.

Examples::

    mechdyn animate four_bar --trace coupler.P -o four_bar.gif
    mechdyn animate slider_crank --over phi --from 0deg --to 360deg --steps 121 -o crank.gif
    mechdyn animate slider_crank --simulate --t-end 0.05s -o run.gif --snapshot start.png

Exit codes: 0 done; 1 the motion stopped early (dead position, or a simulation
that stopped; the frames computed so far are written); 2 bad input.
"""

from __future__ import annotations

import time

from ..kinematics.sweep import sweep
from ..progress import stage
from ..results.animate import animate, check_animation_path, snapshot, trace_spec
from ..results.frame_geometry import MAX_FRAMES
from .options import add_motion_arguments, finish, open_model, simulate_from_args, sweep_values

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``animate`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "animate",
        help="animated GIF of the motion (a sweep of one coordinate, or a simulation)",
        description="Draw the mechanism -- bodies through their points, joints, ground "
                    "anchors, slider guides, springs, stops and loads, with the names of "
                    "bodies and joints, optionally the path of a point -- at every "
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
    d.add_argument("--no-labels", dest="labels", action="store_false",
                   help="do not name the bodies, joints and loads on the drawing")


def run(args) -> int:
    """Run ``mechdyn animate``; returns the exit code."""
    t0 = time.perf_counter()  # the stage running once the run has taken 2 s is named
    check_animation_path(args.output)  # before any computing
    mech, model = open_model(args)
    trace_spec(model, args.trace)
    if args.simulate:
        n = args.frames if args.frames is not None else MAX_FRAMES
        record = simulate_from_args(model, args, max(int(n), 2))
        ok, why = record.success, f"{record.status}: {record.message}"
        print(f"{mech.name}: simulated to t = {record.t[-1] if record.t.size else 0:.6g} s "
              f"({record.status})")
    else:
        over, values, _ = sweep_values(model, args)
        with stage(f"animate: sweeping {over} over {values.size} positions", args.progress,
                   since=t0):
            record = sweep(model, over, values)
        ok, why = record.ok, record.message
        print(f"{mech.name}: {len(record)} of {values.size} positions of {over} "
              f"({record.status})")
    n = min(len(record.x), MAX_FRAMES) if args.frames is None else args.frames
    with stage(f"animate: drawing {n} frames into {args.output}", args.progress, since=t0):
        out = animate(record, args.output, fps=args.fps, frames=args.frames, trace=args.trace,
                      title=args.title, labels=args.labels)
    print(f"  animation: {out}")
    if args.snapshot:
        still = snapshot(record, args.snapshot, 0, trace=args.trace, title=args.title,
                         labels=args.labels)
        print(f"  snapshot: {still}")
    return finish(args, ok, f"the motion stopped early: {why}")
