"""``mechdyn flywheel``: the steady cycle of a machine and a flywheel for a target delta.

Example::

    mechdyn flywheel slider_crank --delta 0.05
    mechdyn flywheel clutchless_press --engage rocker_lock=0mm,0mm,0deg --drop psi \\
        --motor 4A80B4U3 --characteristic extended --gear-ratio 3.4 --efficiency 0.95 \\
        --delta 0.05 --plot cycle.png

The machine is the reduced 1-DOF machine of the model (reduced inertia
interpolated from a table of ``--steps`` positions, drives evaluated live).
With a speed-dependent drive (a motor) the mean speed comes from the steady
cycle; with a constant driving torque give it with ``--speed``.

Exit codes: 0 done; 1 the simulated delta misses the target by more than 5 %;
2 bad input (one line on stderr).
"""

from __future__ import annotations

import warnings

from ..errors import ModelError
from ..friction.ignored import FrictionIgnoredWarning
from ..progress import stage
from ..reduction.flywheel import FLYWHEEL_METHODS, size_flywheel
from ..reduction.machine import ReducedMachine
from ..reduction.reduce import reduce_model
from ..results.plot_reduction import plot_steady_cycle
from ..results.table import rate_text
from ..units import parse_quantity
from .options import (
    add_files,
    add_model_arguments,
    add_progress,
    finish,
    model_speed,
    prepare_model,
    quantity,
    write_files,
)

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``flywheel`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "flywheel",
        help="steady cycle, coefficient of speed fluctuation and flywheel sizing",
        description="Find the periodic steady motion of a 1-DOF machine (speed extremes, mean "
                    "speed, coefficient of speed fluctuation delta) and size a flywheel on the "
                    "crank (and on the motor shaft through the gear) for a target delta by the "
                    "energy method, confirmed by simulating the steady cycle with it.",
        epilog="Quantities take units: 43.5rad/s, 415rpm (a bare number is SI). Exit codes: "
               "0 done, 1 the simulated delta misses the target by more than 5 %, "
               "2 bad input.")
    add_model_arguments(p)
    p.add_argument("--delta", required=True, metavar="DELTA",
                   help="target coefficient of speed fluctuation, e.g. 0.05 or 5%%")
    p.add_argument("--speed", metavar="RATE",
                   help="mean speed of the crank for a constant driving torque (default: the "
                        "model's speed -- the crank's initial speed, else the rated speed of "
                        "its drive); with a motor only the start of the search for the steady "
                        "cycle, whose mean speed the motor sets")
    p.add_argument("--method", choices=FLYWHEEL_METHODS,
                   help="energy method (basic or refined for a variable J_red) or iterate on "
                        "the simulated steady cycle (default: simulation with a motor, whose "
                        "slope smooths the speed; refined with a constant torque)")
    p.add_argument("--steps", type=int, default=721, metavar="N",
                   help="positions of the reduction table over one turn (default 721)")
    p.add_argument("--exact", action="store_true",
                   help="evaluate the mechanism exactly at every step instead of interpolating "
                        "the table (slower; needed for time- or speed-dependent loads)")
    add_files(p, plot="plot the steady cycle with the flywheel",
              table="write the steady cycle with the flywheel to this CSV file")
    add_progress(p)


def run(args) -> int:
    """Run ``mechdyn flywheel``; returns the exit code."""
    mech, model = prepare_model(args)
    delta = parse_quantity(args.delta, "ratio", where="--delta")
    if args.steps < 9:
        raise ModelError(f"--steps must be at least 9, got {args.steps}")
    given = None if args.speed is None else quantity(args.speed, "angular_velocity", "--speed")
    with stage("flywheel: reduction table and steady cycle", args.progress):
        if args.exact:
            machine = ReducedMachine.from_model(model)
        else:
            machine = reduce_model(model, steps=args.steps, omega=given or 1.0).machine(model)
        dependent = machine.speed_dependent()
        speed, why = given, "given with --speed"
        if not dependent and speed is None:
            speed, why = model_speed(model, model.coordinate_names[0], fallback=None)
            if speed is None:
                raise ModelError(f"the driving torque does not depend on the speed, so the "
                                 f"steady speed is not determined by the machine, and {why}: "
                                 f"give the mean speed with --speed (e.g. --speed 43.5rad/s)")
            if not args.exact:  # the table's velocity-dependent loads at that speed
                with warnings.catch_warnings():  # the first reduction has said it
                    warnings.simplefilter("ignore", FrictionIgnoredWarning)
                    machine = reduce_model(model, steps=args.steps, omega=speed).machine(model)
        speed_kw = "omega_guess" if dependent else "omega_mean"  # a motor picks its own speed
        fs = size_flywheel(machine, delta, method=args.method, **{speed_kw: speed})
    print(f"{mech.name}: flywheel for delta = {delta:.4g} ({fs.method} method)")
    print(f"  mean speed            {rate_text(fs.omega_mean, True)}"
          + (f" ({why})" if not dependent else " (the steady cycle of the drive)"))
    if fs.delta_without is not None:
        print(f"  delta without flywheel {fs.delta_without:.6g}")
    print(f"  J_red (drive incl.)   mean {fs.J_red_mean:.6g}, min {fs.J_red_min:.6g}, "
          f"max {fs.J_red_max:.6g} kg m^2")
    print(f"  Delta E_max           {fs.delta_E_max:.6g} J (refined {fs.delta_E_refined:.6g} J)")
    print(f"  J_fly energy method   {fs.J_fly_energy:.6g} kg m^2 (refined "
          f"{fs.J_fly_refined:.6g} kg m^2)")
    if fs.J_fly_energy < 0:
        print("                        (negative: by the energy method alone the machine's own "
              "mean inertia already meets the target; the refined method, which accounts for "
              "the varying J_red, decides)")
    print(f"  J_fly on the crank    {fs.J_fly:.6g} kg m^2")
    if fs.J_fly_motor is not None:
        print(f"  J_fly on the motor    {fs.J_fly_motor:.6g} kg m^2 (gear ratio "
              f"{fs.gear_ratio:.6g})")
    if fs.delta_simulated is not None:
        print(f"  delta simulated       {fs.delta_simulated:.6g} (steady cycle with the "
              f"flywheel)")
    if fs.cycle is not None:
        c = fs.cycle
        print(f"  steady cycle          omega {c.omega_min:.6g} .. {c.omega_max:.6g} rad/s, "
              f"cycle time {c.cycle_time:.6g} s")
        write_files(args, c, plot_steady_cycle)
    if fs.message:
        print(f"  note: {fs.message}")
    missed = fs.delta_simulated is not None and fs.J_fly > 0 and \
        abs(fs.delta_simulated / delta - 1.0) > 0.05
    return finish(args, not missed, "the simulated delta misses the target by more than 5 %; "
                                    "try --method simulation")

