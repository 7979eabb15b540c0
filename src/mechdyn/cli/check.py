"""``mechdyn check``: validate a model file without running an analysis.

Examples::

    mechdyn check press.toml
    mechdyn check press.toml --json

The whole model is checked -- the file's structure, units, names, the switchable
elements, and the compiled mechanism (assembly of the sketch, degrees of freedom,
loads, drives, switches) -- and every problem is reported at once.  Exit codes: 0 the
model is valid, 2 it is not (or the file cannot be read).
"""

from __future__ import annotations

import json

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
                   "switchable": bool(model.has_switching)}
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
    return 2 if problems else 0
