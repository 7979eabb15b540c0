"""``mechdyn foundation``: the loads a machine sends into its supports.

Example::

    mechdyn foundation slider_crank --t-end 0.2s \\
        --support "bolt1: x=-0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m, preload=20kN" \\
        --support "bolt2: x=0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m, preload=20kN" \\
        -o loads.csv --plot loads.png
    mechdyn foundation press_cycle --t-end 1s --mass 500kg --inertia 80kg*m^2 \\
        --isolator "left: x=-0.5m, y=-0.3m, kx=2e5N/m, ky=5e5N/m, cy=2000N*s/m" \\
        --isolator "right: x=0.5m, y=-0.3m, kx=2e5N/m, ky=5e5N/m, cy=2000N*s/m"

The run's frame loads (the load the machine exerts on its frame, moment about the
ground origin) are shared among the supports of a rigid base by stiffness; with
``--mass`` and ``--inertia`` the base is also taken as a body on elastic supports: its
natural frequencies beside the excitation orders of the running speed, and its
response to the frame loads (one way: the base's motion does not act back on the
machine).

Exit codes: 0 done; 1 the run stopped early (the samples so far are analysed);
2 bad input.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError, did_you_mean
from ..foundation import (
    AnchorBolt,
    Foundation,
    Isolator,
    excitation_warnings,
    mounted_response,
    natural_frequencies,
    support_loads,
)
from ..foundation.plot import plot_support_loads
from ..results.table import write_csv
from ..units import parse_quantity, parse_vector
from .options import add_files, add_model, add_run, finish, open_model, simulate_from_args

__all__ = ["register", "run", "parse_support"]

#: fields of a support text: kind of quantity, and whether it must be given
_FIELDS = {
    AnchorBolt: {"x": ("length", True), "y": ("length", True),
                 "k_axial": ("stiffness", True), "k_shear": ("stiffness", True),
                 "preload": ("force", False), "load_factor": ("ratio", False)},
    Isolator: {"x": ("length", True), "y": ("length", True), "kx": ("stiffness", True),
               "ky": ("stiffness", True), "cx": ("damping", False),
               "cy": ("damping", False)},
}


def register(sub) -> None:
    """Add the ``foundation`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "foundation",
        help="loads on anchor bolts and isolators; natural frequencies of the mounted base",
        description="Simulate the model, share the load its frame receives among the "
                    "supports of a rigid base (bolt tension, shear and clamp force, the first "
                    "bolt joint to open); with --mass and --inertia also the base on elastic "
                    "supports: natural frequencies, excitation orders near them, and the force "
                    "passed to the floor.",
        epilog='A support is "NAME: key=value, ...": bolts x, y, k_axial, k_shear '
               '[, preload, load_factor]; isolators x, y, kx, ky [, cx, cy]; values take '
               "units (0.4m, 2e8N/m, 20kN, 2000N*s/m; a bare number is SI). Exit codes: 0 done,"
               " 1 the run stopped early, 2 bad input.")
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
    p.add_argument("--com", default="0m,0m", metavar="X,Y",
                   help="their centre of mass (default 0m,0m)")
    p.add_argument("--weight", action="store_true",
                   help="add the weight of frame and base (--mass, the model's gravity) to "
                        "the loads of the rigid base")
    p.add_argument("--rpm", metavar="SPEED",
                   help="running speed for the excitation orders, e.g. 300rpm (default: the "
                        "mean speed of the first angle coordinate over the run)")
    p.add_argument("--orders", default="1,2,3,4", metavar="K,...",
                   help="excitation orders to check (default 1,2,3,4)")
    add_files(p, plot="plot the loads on the supports (kN)",
              table="write the support loads to this CSV file (and NAME_mounted.csv with "
                    "--mass/--inertia)")


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


def build_foundation(args) -> Foundation:
    """The :class:`Foundation` of ``--support``, ``--isolator``, ``--mass``, ``--inertia``,
    ``--com``."""
    supports = ([parse_support(s, AnchorBolt, "--support") for s in args.support]
                + [parse_support(s, Isolator, "--isolator") for s in args.isolator])
    if not supports:
        raise ModelError("give the supports with --support (anchor bolts) or --isolator, "
                         "at least two at distinct points")
    if (args.mass is None) != (args.inertia is None):
        raise ModelError("--mass and --inertia go together (the elastic analysis needs both)")
    mass = None if args.mass is None else parse_quantity(args.mass, "mass", where="--mass")
    inertia = None if args.inertia is None else parse_quantity(args.inertia, "inertia",
                                                                where="--inertia")
    com = parse_vector(args.com.split(","), ("length", "length"), where="--com")
    return Foundation(supports, mass=mass, inertia=inertia, com=tuple(com))


def _rpm(args, traj) -> float | None:
    """``--rpm``, else the mean speed of the first angle coordinate of the run, rpm."""
    if args.rpm is not None:
        return parse_quantity(args.rpm, "angular_velocity", where="--rpm") * 30 / np.pi
    for k, angle in enumerate(traj.coordinate_is_angle):
        if angle and traj.t.size > 1:
            turn = traj.q[-1, k] - traj.q[0, k]
            return abs(turn / (traj.t[-1] - traj.t[0])) * 30 / np.pi
    return None


def run(args) -> int:
    """Run ``mechdyn foundation``; returns the exit code."""
    foundation = build_foundation(args)
    try:
        orders = tuple(int(k) for k in args.orders.split(","))
    except ValueError:
        raise ModelError(f"--orders: expected whole numbers such as 1,2,3,4, got "
                         f"{args.orders!r}") from None
    if args.samples < 2:
        raise ModelError(f"--samples must be >= 2, got {args.samples}")
    mech, model = open_model(args)
    traj = simulate_from_args(model, args, args.samples)
    if args.weight and foundation.mass is None:
        raise ModelError("--weight needs --mass (and --inertia)")
    loads = support_loads(foundation, traj, gravity=model.gravity if args.weight else None)
    print(f"{mech.name}: loads on {len(foundation.supports)} supports over t = "
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
              f"mounts; base motion peak {np.max(np.abs(mounted.u[:, 1])) * 1e3:.4g} mm "
              f"vertical, {np.max(np.abs(mounted.u[:, 0])) * 1e3:.4g} mm horizontal")
    if args.output:
        print(f"  table: {write_csv(loads, args.output)}")
        if mounted is not None:
            out = Path(args.output)
            print(f"  table: {write_csv(mounted, out.with_name(out.stem + '_mounted.csv'))}")
    if args.plot:
        print(f"  plot: {plot_support_loads(loads, args.plot, mounted)}")
    return finish(args, traj.success, f"the run stopped early: {traj.status}: {traj.message}")
