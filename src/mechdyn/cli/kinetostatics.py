"""``mechdyn kinetostatics``: driving torque, joint reactions and frame loads over a cycle.

Example::

    mechdyn kinetostatics toggle_press --speed 40rpm --from 0deg --to 360deg \\
        --steps 361 --moment-point 0,0 -o forces.csv --plot forces.png

With friction in the pairs (``docs/friction.md``) it also prints the cycle efficiency
and the energy lost in each pair, and the table gets the loss and efficiency columns.

Exit codes: 0 done; 1 done with a warning that matters (singular or self-locking
positions); 2 bad input (one line on stderr).
"""

from __future__ import annotations

import warnings
from pathlib import Path

from ..errors import ModelError, Status
from ..kinetostatics.inverse import KinetostaticsWarning, kinetostatics
from ..progress import stage
from ..results.plot_kinetostatics import plot_joint_force_polar, plot_kinetostatics
from ..results.table import written
from .options import (
    add_engage,
    add_files,
    add_model,
    add_moment_point,
    add_plot_columns,
    add_progress,
    add_range,
    add_speed,
    check_plot_columns,
    draw_plot,
    engage_from_args,
    finish,
    load_model,
    moment_point,
    preview_record,
    speed_from_args,
    speed_line,
    sweep_values,
    with_lock_poses,
)

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
               "is SI: rad, m, rad/s). Joints with friction add the power lost per pair and the "
               "efficiency (docs/friction.md). Exit codes: 0 done, 1 singular or "
               "self-locking positions, 2 bad input.")
    add_model(p)
    add_range(p, steps=361, over="driven coordinate (default: the first); other independent "
                                 "coordinates are held at their initial values")
    add_speed(p, "constant speed of the driven coordinate (0rpm for statics)")
    add_moment_point(p, alias="--point")
    add_engage(p, alias="--mode")
    p.add_argument("--bed", nargs="+", default=(), metavar="LOAD",
                   help="force loads whose reaction the frame carries (e.g. the punch force "
                        "on a press bed)")
    add_files(p, plot="write a plot (torque, pin forces, shaking)")
    p.add_argument("--joints", nargs="+", metavar="JOINT",
                   help="joints whose forces are plotted (default: all)")
    add_plot_columns(p)
    add_progress(p)
    p.add_argument("--plot-polar", action="append", default=[], metavar="JOINT",
                   help="with --plot FILE: also the polar diagram of this joint's force, "
                        "written beside it as FILE_polar_JOINT (repeatable)")
    p.add_argument("--harmonics", type=int, default=6, metavar="K",
                   help="print the shaking-force harmonics up to order K (default 6; 0: none)")


def run(args) -> int:
    """Run ``mechdyn kinetostatics``; returns the exit code."""
    check_plot_columns(args)
    if args.plot_polar and not args.plot:
        raise ModelError("--plot-polar needs --plot FILE (the polar diagrams are written "
                         "beside it)")
    engaged, poses = engage_from_args(args)
    mech = load_model(args.model)
    model = with_lock_poses(mech, poses).compile()
    for joint in args.plot_polar:
        model.joint_kind(joint)  # an unknown joint is an error before the analysis
    over, values, _ = sweep_values(model, args)
    speed, why = speed_from_args(model, over, args)
    point = moment_point(args)
    if args.plot_columns is not None:  # the columns before the analysis
        check_plot_columns(args, preview_record(lambda: kinetostatics(
            model, over=over, speed=speed, values=values[:2], point=point, mode=engaged,
            reacting_loads=tuple(args.bed))))
    with (warnings.catch_warnings(),
          stage(f"kinetostatics: {values.size} positions of {over}", args.progress)):
        warnings.simplefilter("ignore", KinetostaticsWarning)  # printed below
        res = kinetostatics(model, over=over, speed=speed, values=values, point=point,
                            mode=engaged, reacting_loads=tuple(args.bed))
    angle = res.over_is_angle
    print(f"{mech.name}: kinetostatics; status {res.status}")
    print(speed_line(speed, angle, why))
    for line in res.summary().splitlines():
        print("  " + line if not line.startswith("  ") else line)
    if args.harmonics > 0 and angle and speed != 0:
        try:
            h = res.harmonics(args.harmonics)
        except ValueError:
            pass  # not one uniformly sampled turn
        else:
            print("  shaking harmonics (order: |Fx| |Fy| N, |M| N m):")
            for _, row in h.iterrows():
                print(f"    {int(row['order']):3d} ({row['f_Hz']:.4g} Hz): "
                      f"{row['Fx_frame_N']:.6g} {row['Fy_frame_N']:.6g} "
                      f"{row['M_frame_Nm']:.6g}")
    if res.losses:
        e = res.energies()
        print("  energy lost per pair: "
              + ", ".join(f"{j} {e[f'loss_{j}']:.6g} J" for j in res.losses)
              + " (columns P_loss_<joint>_W, P_loss_W, P_out_W, efficiency in the table)")
    if args.output:
        with written(args.output) as tmp:
            res.to_dataframe().to_csv(tmp, index=False)
        print(f"  table: {args.output}")
    if args.plot:
        print(f"  plot: {draw_plot(args, res, plot_kinetostatics, joints=args.joints)}")
        for joint in args.plot_polar:
            path = Path(args.plot)
            out = path.with_name(f"{path.stem}_polar_{joint}{path.suffix}")
            print(f"  polar plot of {joint}: {plot_joint_force_polar(res, joint, out)}")
    return finish(args, res.status not in (Status.SINGULAR_POSITION, Status.SELF_LOCKING),
                  res.message)
