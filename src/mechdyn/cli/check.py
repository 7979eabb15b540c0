"""``mechdyn check``: validate a model file without running an analysis.

Examples::

    mechdyn check press.toml
    mechdyn check press.toml --json

The whole model is checked -- the file's structure, units, names, the switchable
elements, and the compiled mechanism (assembly of the sketch, degrees of freedom,
loads, drives, switches) -- and every problem is reported at once.  Exit codes: 0 the
model is valid, 2 it is not (or the file cannot be read).  Bodies given without a
pose are placed by the initial assembly; a valid model then lists the poses found
("poses found", x and y in mm, the angle in deg; ``poses_found`` in the JSON).
"""

from __future__ import annotations

import json
import math

from ..errors import MechdynError, ModelError
from .options import add_model, load_model

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``check`` subcommand to an argparse subparsers object."""
    p = sub.add_parser("check", help="validate a model file (every problem at once)",
                       description="Load and compile a model without running an analysis; "
                                   "print every problem found, or a summary of the model.",
                       epilog="Exit codes: 0 valid, 2 not valid.")
    add_model(p)
    p.add_argument("--json", action="store_true",
                   help="print the result as JSON: {model, valid, problems, summary}")


def run(args) -> int:
    """Run ``mechdyn check``; returns the exit code."""
    problems, summary = [], {}
    try:
        mech = load_model(args.model)
        model = mech.compile()
        summary = {"bodies": list(model.body_names), "joints": list(mech.joints),
                   "coordinates": list(model.coordinate_names),
                   "switchable": bool(model.has_switching),
                   "poses_found": {n: {"x_mm": 1e3 * x, "y_mm": 1e3 * y,
                                       "theta_deg": math.degrees(th)}
                                   for n, (x, y, th) in model.found_poses.items()}}
    except ModelError as exc:
        problems = list(exc.problems)
    except (MechdynError, OSError) as exc:
        problems = [str(exc)]
    if args.json:
        print(json.dumps({"model": args.model, "valid": not problems, "problems": problems,
                          "summary": summary}, indent=2))
    elif problems:
        print(f"{args.model}: {len(problems)} problem(s):")
        for p in problems:
            print(f"  - {p}")
    else:
        print(f"{args.model}: valid; {len(summary['bodies'])} bodies, "
              f"{len(summary['joints'])} joints, coordinates "
              f"{', '.join(summary['coordinates'])}"
              + ("; switchable elements" if summary["switchable"] else ""))
        if summary["poses_found"]:
            print(poses_table(summary["poses_found"]))
    return 2 if problems else 0


def poses_table(found: dict) -> str:
    """The "poses found" table of ``mechdyn check``: one line a body, mm and deg.

    Examples
    --------
    >>> print(poses_table({"rocker": {"x_mm": 100.0, "y_mm": 0.0, "theta_deg": 64.9435}}))
    poses found (bodies given without a pose, placed by the assembly):
      body       x [mm]      y [mm]  angle [deg]
      rocker        100           0      64.9435
    """
    width = max(6, *(len(n) for n in found))
    lines = ["poses found (bodies given without a pose, placed by the assembly):",
             f"  {'body':<{width}} {'x [mm]':>10}  {'y [mm]':>10}  {'angle [deg]':>11}"]
    for n, p in found.items():
        lines.append(f"  {n:<{width}} {p['x_mm']:>10.6g}  {p['y_mm']:>10.6g}  "
                     f"{p['theta_deg']:>11.6g}")
    return "\n".join(lines)
