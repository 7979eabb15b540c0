"""``mechdyn supports``: the forces of a beam on k supports by influence coefficients
(:mod:`mechdyn.dynamics.compliance`), with supports that lift off."""

from __future__ import annotations

import csv

from ..errors import UnitError
from ..results.table import written
from .options import quantity

__all__ = ["register", "run"]

_RIGID = ("inf", "rigid")


def register(sub) -> None:
    """Add the ``supports`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "supports",
        help="forces of a beam on elastic supports that may lift off (influence coefficients)",
        description="Share the loads of a beam (rigid, or flexible with --EI) among k "
                    "supports by the full influence-coefficient matrix: supports that only "
                    "push lift off where the load would pull on them; clearances close under "
                    "load (docs/indeterminacy.md).",
        epilog="Values take units (1.5m, 2e6N/m, 10kN, 2e6N*m^2; a bare number is SI). "
               "Loads and deflections are positive downwards. Exit codes: 0 done, 2 bad "
               "input or no support set holds the beam.")
    p.add_argument("--at", required=True, metavar="X,X,...",
                   help="support positions along the beam, e.g. 0m,1.5m,4m")
    p.add_argument("--stiffness", metavar="K,K,...",
                   help="support stiffnesses, e.g. 2e6N/m,5N/um,rigid (default all rigid)")
    p.add_argument("--EI", dest="EI", metavar="EI",
                   help="bending stiffness of a flexible beam, e.g. 2e6N*m^2 (default: rigid)")
    p.add_argument("--load", action="append", default=[], required=True, metavar="X:P",
                   help="a downward point load, e.g. 2m:10kN (repeatable)")
    p.add_argument("--gap", metavar="G,G,...",
                   help="clearances between the unloaded beam and the supports, e.g. "
                        "0mm,1mm,0mm (default 0)")
    p.add_argument("--bilateral", action="store_true",
                   help="supports hold the beam down as well (no lift-off)")
    p.add_argument("-o", "--output", metavar="CSV", help="write the table to this CSV file")


def _list(text: str, kind: str, flag: str, n: int | None = None, rigid: bool = False):
    parts = [t.strip() for t in str(text).split(",")]
    if n is not None and len(parts) != n:
        raise UnitError(f"{flag} {text!r}: expected {n} value(s), one per support, got "
                        f"{len(parts)}")
    return [float("inf") if rigid and t.lower() in _RIGID else quantity(t, kind, flag)
            for t in parts]


def run(args) -> int:
    import numpy as np

    from ..dynamics.compliance import beam_on_supports

    x = _list(args.at, "length", "--at")
    k = len(x)
    stiff = (_list(args.stiffness, "stiffness", "--stiffness", k, rigid=True)
             if args.stiffness else None)
    gaps = _list(args.gap, "length", "--gap", k) if args.gap else None
    loads = []
    for spec in args.load:
        where, sep, force = spec.partition(":")
        if not sep:
            raise UnitError(f"--load {spec!r}: expected POSITION:FORCE, e.g. 2m:10kN")
        loads.append((quantity(where, "length", "--load"), quantity(force, "force", "--load")))
    EI = quantity(args.EI, "bending_stiffness", "--EI") if args.EI else np.inf
    # the checks of beam_on_supports, in the terms of this command (supports numbered
    # from 1 as in the table, "rigid" rather than np.inf)
    bad = [i + 1 for i, v in enumerate(stiff or ()) if not v > 0]
    if bad:
        raise UnitError(f"--stiffness {args.stiffness!r}: support(s) {bad} (numbered from 1) "
                        "must be > 0 N/m, or 'rigid'")
    if not EI > 0:
        raise UnitError(f"--EI {args.EI!r}: must be > 0 (leave --EI out for a rigid beam)")
    prob = beam_on_supports(x, stiff, EI=EI, loads=loads, gaps=gaps,
                            bilateral=[True] * k if args.bilateral else None)
    s = prob.solve()
    beam = "rigid beam" if not np.isfinite(EI) else f"flexible beam, EI = {EI:.6g} N m^2"
    print(f"{k} supports, {beam}, total load {prob.f[0]:.6g} N")
    print(f"  {'support':>7}  {'x [m]':>10}  {'force [N]':>14}  {'gap [mm]':>12}  state")
    rows = []
    for i in range(k):
        state = "closed" if s.closed[i] else "open (lifted off)"
        print(f"  {i + 1:>7}  {x[i]:>10.6g}  {s.forces[i]:>14.6g}  {1e3 * s.gaps[i]:>12.6g}  "
              f"{state}")
        rows.append((i + 1, x[i], s.forces[i], 1e3 * s.gaps[i], int(s.closed[i])))
    print(f"  beam: w0 = {1e3 * s.motion[0]:.6g} mm, phi = {s.motion[1]:.6g} rad "
          "(w = w0 + phi x, downwards)")
    if args.output:
        with written(args.output) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["support", "x_m", "force_N", "gap_mm", "closed"])
            w.writerows(rows)
        print(f"  table: {args.output}")
    return 0
