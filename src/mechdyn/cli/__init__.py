"""The ``mechdyn`` command line: it composes analyses, it does not compute.

Each subcommand lives in its own module of this package exposing
``register(subparsers)``; the module adds its parser and sets ``func`` to a
function ``run(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .._version import __version__
from ..errors import MechdynError

__all__ = ["main", "SUBCOMMAND_MODULES"]

#: modules of this package that define subcommands, in the order of ``mechdyn --help``
SUBCOMMAND_MODULES = ("demo", "examples", "kinematics", "simulate", "kinetostatics", "reduce",
                      "flywheel", "animate", "report")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="mechdyn", description="Kinematics, dynamics and kinetostatics of planar mechanisms.")
    parser.add_argument("--version", action="version", version=f"mechdyn {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in SUBCOMMAND_MODULES:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0 ok, 1 analysis stopped, 2 bad input,
    130 interrupted by Ctrl-C)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except (MechdynError, FileNotFoundError, IsADirectoryError, PermissionError) as exc:
        print(f"mechdyn {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # outside a run (a run keeps its data and says so itself)
        print(f"mechdyn {args.command}: interrupted", file=sys.stderr)
        return 130
