"""``mechdyn supports``: the forces of k supports by influence coefficients
(:mod:`mechdyn.contact.compliance`), with supports that lift off: a beam (``--at``), or
any body given by its compliance matrix and equilibrium equations as CSV files
(``--compliance``)."""

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
        help="forces of elastic supports that may lift off (influence coefficients)",
        description="Share the loads of a beam (--at: rigid, or flexible with --EI), or of "
                    "any body given by its influence-coefficient matrix (--compliance), among "
                    "k supports: supports that only push lift off where the load would pull "
                    "on them; clearances close under load (docs/indeterminacy.md).",
        epilog="Values take units (1.5m, 2e6N/m, 10kN, 2e6N*m^2; a bare number is SI); "
               "the CSV files of --compliance, --load-gaps and --equilibrium hold SI numbers. "
               "Loads and deflections are positive downwards. Exit codes: 0 done, 2 bad "
               "input or no support set holds the body.")
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--at", metavar="X,X,...",
                      help="support positions along the beam, e.g. 0m,1.5m,4m")
    what.add_argument("--compliance", metavar="CSV",
                      help="the general problem: the k x k influence coefficients C, m/N "
                           "(C[i,j]: gap change at support i per newton at j), one row per "
                           "line, comma-separated, SI numbers; '#' starts a comment")
    p.add_argument("--stiffness", metavar="K,K,...",
                   help="support stiffnesses, e.g. 2e6N/m,5N/um,rigid (default all rigid)")
    p.add_argument("--EI", dest="EI", metavar="EI",
                   help="bending stiffness of a flexible beam, e.g. 2e6N*m^2 (default: rigid)")
    p.add_argument("--load", action="append", default=[], metavar="X:P",
                   help="a downward point load on the beam, e.g. 2m:10kN (repeatable; "
                        "required with --at)")
    p.add_argument("--gap", metavar="G,G,...",
                   help="clearances between the unloaded beam and the supports, e.g. "
                        "0mm,1mm,0mm (default 0)")
    p.add_argument("--bilateral", action="store_true",
                   help="supports hold the body down as well (no lift-off)")
    p.add_argument("--load-gaps", metavar="CSV",
                   help="with --compliance: the gaps q (m) that the active loads open at the k "
                        "supports, one value per line (default 0); --gap adds clearances")
    p.add_argument("--equilibrium", metavar="CSV",
                   help="with --compliance: A (k x m), the gap change per unit rigid-body "
                        "motion u of the supported body is -A u (omit for a body held "
                        "otherwise)")
    p.add_argument("--resultant", metavar="F,F,...",
                   help="with --equilibrium: the m resultants f of the active loads, "
                        "A^T lambda = f, e.g. 10kN,2kN*m (a bare number is SI)")
    p.add_argument("-o", "--output", metavar="CSV", help="write the table to this CSV file")


def _list(text: str, kind: str, flag: str, n: int | None = None, rigid: bool = False):
    parts = [t.strip() for t in str(text).split(",")]
    if n is not None and len(parts) != n:
        raise UnitError(f"{flag} {text!r}: expected {n} value(s), one per support, got "
                        f"{len(parts)}")
    return [float("inf") if rigid and t.lower() in _RIGID else quantity(t, kind, flag)
            for t in parts]


def _matrix(path: str, flag: str, shape: tuple):
    """A numeric CSV file as an array of ``shape`` (None: any size along that axis)."""
    import numpy as np

    try:
        with open(path, encoding="utf-8") as fh:
            a = np.loadtxt(fh, delimiter=",", comments="#", ndmin=2)
    except OSError as exc:
        raise UnitError(f"{flag} {path}: cannot read it ({exc.strerror})") from None
    except ValueError as exc:
        raise UnitError(f"{flag} {path}: not a table of numbers ({exc})") from None
    if shape[1] == 1 and a.shape[0] == 1:
        a = a.T  # a column written as one line
    want = "x".join("m" if n is None else str(n) for n in shape)
    if a.size == 0 or any(n is not None and n != s for n, s in zip(shape, a.shape, strict=True)):
        raise UnitError(f"{flag} {path}: expected a {want} table, got {a.shape[0]} x "
                        f"{a.shape[1]}")
    if not np.all(np.isfinite(a)):
        raise UnitError(f"{flag} {path}: every value must be a finite number")
    return a


def _resultant(text: str) -> float:
    """One resultant: a bare SI number, a force ("10 kN") or a moment ("2 kN*m")."""
    try:
        return float(text)
    except ValueError:
        pass
    try:
        return quantity(text, "force", "--resultant")
    except UnitError:
        try:
            return quantity(text, "torque", "--resultant")
        except UnitError:
            raise UnitError(f"--resultant {text!r}: expected a force (e.g. 10kN), a moment "
                            "(e.g. 2kN*m) or a bare SI number") from None


def _beam(args):
    """The beam problem of ``--at``: (problem, positions, label of the body)."""
    import numpy as np

    from ..contact.compliance import beam_on_supports

    x = _list(args.at, "length", "--at")
    k = len(x)
    if not args.load:
        raise UnitError("--at: give the beam's loads with --load POSITION:FORCE, e.g. 2m:10kN")
    for flag in ("load_gaps", "equilibrium", "resultant"):
        if getattr(args, flag):
            raise UnitError(f"--{flag.replace('_', '-')} goes with --compliance, not --at")
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
    beam = "rigid beam" if not np.isfinite(EI) else f"flexible beam, EI = {EI:.6g} N m^2"
    return prob, x, f"{beam}, total load {prob.f[0]:.6g} N"


def _general(args):
    """The problem of ``--compliance``: (problem, None, label)."""
    import numpy as np

    from ..contact.compliance import SupportProblem, check_compliance

    for flag in ("load", "stiffness", "EI"):
        if getattr(args, flag):
            raise UnitError(f"--{flag} goes with --at (a beam), not --compliance: put the "
                            "supports' and the body's compliance into the matrix")
    C = check_compliance(_matrix(args.compliance, "--compliance", (None, None)),
                         name=f"--compliance {args.compliance}")
    k = C.shape[0]
    q = (_matrix(args.load_gaps, "--load-gaps", (k, 1))[:, 0] if args.load_gaps
         else np.zeros(k))
    if args.gap:
        q = q + np.array(_list(args.gap, "length", "--gap", k))
    if (args.equilibrium is None) != (args.resultant is None):
        raise UnitError("--equilibrium and --resultant go together (A and f of A^T lambda = f)")
    if args.equilibrium:
        f = np.array([_resultant(t.strip()) for t in args.resultant.split(",")])
        A = _matrix(args.equilibrium, "--equilibrium", (k, f.size))
    else:
        A, f = np.zeros((k, 0)), np.zeros(0)
    prob = SupportProblem(C, q, A, f, np.full(k, bool(args.bilateral)))
    rigid = f"{f.size} rigid-body motion(s)" if f.size else "no rigid-body motion"
    return prob, None, f"compliance matrix {args.compliance}, {rigid}"


def run(args) -> int:
    import numpy as np

    prob, x, label = (_beam if args.at else _general)(args)
    s = prob.solve()
    k = s.forces.size
    print(f"{k} supports, {label}")
    pos = "" if x is None else f"  {'x [m]':>10}"
    print(f"  {'support':>7}{pos}  {'force [N]':>14}  {'gap [mm]':>12}  state")
    rows = []
    for i in range(k):
        state = "closed" if s.closed[i] else "open (lifted off)"
        at = "" if x is None else f"  {x[i]:>10.6g}"
        print(f"  {i + 1:>7}{at}  {s.forces[i]:>14.6g}  {1e3 * s.gaps[i]:>12.6g}  {state}")
        rows.append((i + 1, *(() if x is None else (x[i],)), s.forces[i], 1e3 * s.gaps[i],
                     int(s.closed[i])))
    if x is not None:
        print(f"  beam: w0 = {1e3 * s.motion[0]:.6g} mm, phi = {s.motion[1]:.6g} rad "
              "(w = w0 + phi x, downwards)")
    elif s.motion.size:
        print("  body: u = " + ", ".join(f"{u:.6g}" for u in np.atleast_1d(s.motion))
              + " (the rigid-body motion, in the units of A's columns)")
    if args.output:
        with written(args.output) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["support", *(() if x is None else ("x_m",)), "force_N", "gap_mm",
                        "closed"])
            w.writerows(rows)
        print(f"  table: {args.output}")
    return 0
