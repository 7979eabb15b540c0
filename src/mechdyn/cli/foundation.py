"""``mechdyn foundation``: the loads a machine sends into its supports.

Example::

    mechdyn foundation slider_crank --t-end 0.2s \\
        --support "bolt1: x=-0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m, preload=20kN" \\
        --support "bolt2: x=0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m, preload=20kN" \\
        -o loads.csv --plot loads.png
    mechdyn foundation press_cycle --t-end 1s    # the isolators of its [foundation]

Without ``--support`` and ``--isolator`` the supports are those of the model file's
``[foundation]`` table (docs/model-file.md), its mass, inertia and centre of mass too;
supports given on the command line replace the file's, and ``--mass``, ``--inertia``
and ``--com`` override its values.

The run's frame loads (the load the machine exerts on its frame, moment about the
ground origin) are shared among the supports of a rigid base by stiffness; with a mass
and an inertia (the model's, or ``--mass`` and ``--inertia``) the base is also taken as
a body on elastic supports: its natural frequencies beside the excitation orders of the
running speed, and its response to the frame loads (one way: the base's motion does not
act back on the machine).  With ``--coupled`` the frame also becomes a body on its
isolators in a second run with the machine (two-way, ``mechdyn.foundation.mounted``): the
force passed to the floor and the base's motion, rigid, one-way and coupled side by side.

Exit codes: 0 done; 1 the run stopped early (the samples so far are analysed);
2 bad input.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

from ..errors import ModelError, did_you_mean
from ..foundation import (
    AnchorBolt,
    FloorFrameWarning,
    Foundation,
    Isolator,
    compare_mounting,
    excitation_warnings,
    mounted_response,
    natural_frequencies,
    support_loads,
)
from ..foundation.plot import plot_support_loads
from ..modelfile.foundation import support_fields
from ..results.table import write_csv
from ..units import parse_quantity
from .options import (
    add_files,
    add_model,
    add_progress,
    add_run,
    finish,
    load_model,
    simulate_from_args,
    vector,
)

__all__ = ["register", "run", "parse_support"]

#: fields of a support text: kind of quantity, and whether it must be given (the model
#: file's [[foundation.bolts]] and [[foundation.isolators]] have the same)
_FIELDS = {cls: support_fields(cls) for cls in (AnchorBolt, Isolator)}


def register(sub) -> None:
    """Add the ``foundation`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "foundation",
        help="loads on anchor bolts and isolators; natural frequencies of the mounted base",
        description="Simulate the model, share the load its frame receives among the "
                    "supports (those of the model's [foundation] table, or --support and "
                    "--isolator) of a rigid base (bolt tension, shear and clamp force, the first "
                    "bolt joint to open); with --mass and --inertia also the base on elastic "
                    "supports: natural frequencies, excitation orders near them, and the force "
                    "passed to the floor.",
        epilog='A support is "NAME: key=value, ...": bolts x, y, k_axial, k_shear '
               '[, preload, load_factor]; isolators x, y, kx, ky [, cx, cy]; values take '
               "units (0.4m, 2e8N/m, 20kN, 2000N*s/m; a bare number is SI). Supports given "
               "here replace those of the model's [foundation] table; --mass, --inertia and "
               "--com override its values. Exit codes: 0 done, 1 the run stopped early, 2 bad "
               "input.")
    add_model(p)
    add_run(p, required=True)
    p.add_argument("--samples", type=int, default=2001, metavar="N",
                   help="equally spaced samples of the run (default 2001)")
    p.add_argument("--support", action="append", default=[], metavar="SPEC",
                   help='an anchor bolt, e.g. "b1: x=-0.4m, y=0m, k_axial=2e8N/m, '
                        'k_shear=1e8N/m, preload=20kN" (repeatable)')
    p.add_argument("--isolator", action="append", default=[], metavar="SPEC",
                   help='an isolator, e.g. "m1: x=0.5m, y=0m, kx=2e5N/m, ky=5e5N/m, '
                        'cy=2000N*s/m" (repeatable)')
    p.add_argument("--mass", metavar="MASS", help="mass of frame and base, e.g. 500kg")
    p.add_argument("--inertia", metavar="J",
                   help="their moment of inertia about their centre of mass, e.g. 80kg*m^2")
    p.add_argument("--com", metavar="X,Y",
                   help="their centre of mass (default: the model's [foundation] com, else "
                        "0m,0m)")
    p.add_argument("--weight", action="store_true",
                   help="add the weight of frame and base (--mass, the model's gravity) to "
                        "the loads of the rigid base")
    p.add_argument("--speed", metavar="RATE",
                   help="running speed for the excitation orders, e.g. 300rpm (default: the "
                        "mean speed of the first angle coordinate over the run)")
    p.add_argument("--rpm", dest="speed", help=argparse.SUPPRESS)  # the old spelling
    p.add_argument("--orders", default="1,2,3,4", metavar="K,...",
                   help="excitation orders to check (default 1,2,3,4)")
    p.add_argument("--coupled", action="store_true",
                   help="also run the machine with its frame as a body (mass, inertia) on "
                        "the isolators, two-way coupled, and compare the force to the floor "
                        "and the base's motion with the rigid frame and the one-way "
                        "prediction (writes NAME_coupled.csv with -o)")
    p.add_argument("--bed", nargs="+", default=(), metavar="LOAD",
                   help="with --coupled: force loads whose reaction the frame carries (a "
                        "cylinder or spring pack on the frame, a punch on the bed), put on the "
                        "base and added to the rigid frame's loads of the comparison")
    add_files(p, plot="plot the loads on the supports (kN)",
              table="write the support loads to this CSV file (and NAME_mounted.csv with "
                    "--mass/--inertia, NAME_coupled.csv with --coupled)")
    add_progress(p)


def parse_support(text: str, cls, flag: str):
    """An :class:`AnchorBolt` or :class:`Isolator` from ``"NAME: key=value, ..."``.

    Examples
    --------
    >>> parse_support("b1: x=-0.4m, y=0m, k_axial=2e8N/m, k_shear=100N/mm, preload=20kN",
    ...               AnchorBolt, "--support")
    AnchorBolt(name='b1', x=-0.4, y=0.0, k_axial=200000000.0, k_shear=100000.0, \
preload=20000.0, load_factor=None)
    """
    name, sep, rest = text.partition(":")
    name = name.strip()
    if not sep or not name:
        raise ModelError(f"{flag} {text!r}: expected NAME: key=value, ..., e.g. "
                         f"{_example(cls)!r}")
    fields = _FIELDS[cls]
    values = {}
    for item in filter(str.strip, rest.split(",")):
        key, eq, value = (s.strip() for s in item.partition("="))
        if not eq:
            raise ModelError(f"{flag} {name}: expected key=value, got {item.strip()!r}")
        if key not in fields:
            raise ModelError(f"{flag} {name}: " + did_you_mean(key, fields, "field"))
        values[key] = parse_quantity(value, fields[key][0], where=f"{flag} {name} {key}")
    missing = [k for k, (_, needed) in fields.items() if needed and k not in values]
    if missing:
        raise ModelError(f"{flag} {name}: missing {', '.join(missing)}, e.g. {_example(cls)!r}")
    return cls(name, **values)


def _example(cls) -> str:
    return ("b1: x=-0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m, preload=20kN"
            if cls is AnchorBolt else "m1: x=0.5m, y=0m, kx=2e5N/m, ky=5e5N/m, cy=2000N*s/m")


def build_foundation(args, given: Foundation | None = None) -> Foundation:
    """The :class:`Foundation` of ``--support``, ``--isolator``, ``--mass``, ``--inertia``,
    ``--com``; what they leave out is taken from ``given`` (the model's foundation)."""
    supports = ([parse_support(s, AnchorBolt, "--support") for s in args.support]
                + [parse_support(s, Isolator, "--isolator") for s in args.isolator])
    if not supports and given is None:
        raise ModelError("no supports: the model has no [foundation] table; give the supports "
                         "with --support (anchor bolts) or --isolator, at least two at distinct "
                         "points, or add [[foundation.bolts]] or [[foundation.isolators]] to "
                         "the model file (docs/model-file.md)")
    mass = given.mass if given is not None else None
    inertia = given.inertia if given is not None else None
    com = given.com if given is not None else (0.0, 0.0)
    if given is None and (args.mass is None) != (args.inertia is None):
        raise ModelError("--mass and --inertia go together (the elastic analysis needs both)")
    if args.mass is not None:
        mass = parse_quantity(args.mass, "mass", where="--mass")
    if args.inertia is not None:
        inertia = parse_quantity(args.inertia, "inertia", where="--inertia")
    if (mass is None) != (inertia is None):
        raise ModelError(f"{'--mass' if inertia is None else '--inertia'}: the model's "
                         f"[foundation] has no {'inertia' if inertia is None else 'mass'}; "
                         "give --mass and --inertia together (the elastic analysis needs "
                         "both)")
    if args.com is not None:
        com = vector(args.com, ("length", "length"), "--com", "two lengths X,Y, e.g. 0,0.3m")
    return Foundation(supports or given.supports, mass=mass, inertia=inertia, com=com)


def _rpm(args, traj) -> float | None:
    """``--speed``, else the mean speed of the first angle coordinate of the run, rpm."""
    if args.speed is not None:
        return parse_quantity(args.speed, "angular_velocity", where="--speed") * 30 / np.pi
    for k, angle in enumerate(traj.coordinate_is_angle):
        if angle and traj.t.size > 1:
            turn = traj.q[-1, k] - traj.q[0, k]
            return abs(turn / (traj.t[-1] - traj.t[0])) * 30 / np.pi
    return None


def run(args) -> int:
    """Run ``mechdyn foundation``; returns the exit code."""
    mech = load_model(args.model)
    foundation = build_foundation(args, mech.foundation)
    try:
        orders = tuple(int(k) for k in args.orders.split(","))
    except ValueError:
        raise ModelError(f"--orders: expected whole numbers such as 1,2,3,4, got "
                         f"{args.orders!r}") from None
    if args.samples < 2:
        raise ModelError(f"--samples must be >= 2, got {args.samples}")
    if args.bed and not args.coupled:
        raise ModelError("--bed goes with --coupled (the reactions are put on the mounted "
                         "base)")
    if args.coupled and (foundation.mass is None or any(foundation.bolts)):
        raise ModelError("--coupled needs isolators (not anchor bolts) and the frame's mass "
                         "and inertia (--mass, --inertia or the model's [foundation])")
    model = mech.compile()
    traj = simulate_from_args(model, args, args.samples)
    if args.weight and foundation.mass is None:
        raise ModelError("--weight needs --mass (and --inertia)")
    loads = support_loads(foundation, traj, gravity=model.gravity if args.weight else None)
    source = "the model's [foundation]" if not (args.support or args.isolator) else \
        "the command line"
    print(f"{mech.name}: loads on {len(foundation.supports)} supports ({source}) over t = "
          f"{loads.t[0]:.6g} .. {loads.t[-1]:.6g} s (rigid base)")
    print(loads.summary())
    mounted = None
    if foundation.mass is not None:
        modes = natural_frequencies(foundation)
        print("  natural frequencies of the mounted base: " + ", ".join(
            f"{f:.4g} Hz ({label})" for f, label in zip(modes.frequencies, modes.labels,
                                                         strict=True)))
        rpm = _rpm(args, traj)
        if rpm:
            warnings = excitation_warnings(foundation, rpm, orders)
            print(f"  running speed {rpm:.5g} rpm: orders {', '.join(map(str, orders))} at "
                  + ", ".join(f"{k * rpm / 60:.4g}" for k in orders) + " Hz")
            for w in warnings:
                print(f"  warning: {w}")
        a = loads.applied  # with --weight, a constant: a static deflection and floor force
        mounted = mounted_response(foundation, loads.t, a[:, 0], a[:, 1], a[:, 2],
                                   point=loads.point)
        print(f"  force to the floor: peak {np.max(np.hypot(a[:, 0], a[:, 1])) / 1e3:.4g} kN "
              f"rigid, {np.max(np.hypot(*mounted.floor[:, :2].T)) / 1e3:.4g} kN on the "
              f"mounts; base motion peak {np.max(np.abs(mounted.u[:, 0])) * 1e3:.4g} mm "
              f"in x, {np.max(np.abs(mounted.u[:, 1])) * 1e3:.4g} mm in y")
    coupled = _coupled(args, mech, foundation, traj) if args.coupled else None
    if args.output:
        print(f"  table: {write_csv(loads, args.output)}")
        out = Path(args.output)
        if mounted is not None:
            print(f"  table: {write_csv(mounted, out.with_name(out.stem + '_mounted.csv'))}")
        if coupled is not None:
            print(f"  table: {write_csv(coupled, out.with_name(out.stem + '_coupled.csv'))}")
    if args.plot:
        print(f"  plot: {plot_support_loads(loads, args.plot, mounted)}")
    ok = traj.success and (coupled is None or coupled.coupled_run.success)
    last = traj if traj.success else coupled.coupled_run
    return finish(args, ok, f"the run stopped early: {last.status}: {last.message}")


def _coupled(args, mech, foundation, traj):
    """``--coupled``: the machine on its isolators in one run beside the rigid run ``traj``;
    prints the comparison and returns it."""
    t_end = parse_quantity(args.t_end, "time", where="--t-end")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FloorFrameWarning)
        c = compare_mounting(mech, foundation, t_end, samples=args.samples, rigid_run=traj,
                             reacting=tuple(args.bed), integrator=args.integrator,
                             rtol=args.rtol, progress=args.progress)
    print("  coupled: the frame as a body on its isolators, one run with the machine")
    for w in caught:
        print(f"  note: {w.message}")
    run = c.coupled_run
    if not run.success:
        print(f"  the coupled run stopped at t = {run.t[-1]:.6g} s: {run.message}")
    print(c.summary())
    return c
