"""The ``mechdyn`` command line: it composes analyses, it does not compute.

Each subcommand lives in its own module of this package exposing
``register(subparsers)``, which adds its parser, and ``run(args) -> int``; the
options several subcommands share are in :mod:`mechdyn.cli.options`.  Only the module
of the subcommand that runs is imported (``mechdyn --help`` lists the others from
:data:`SUBCOMMANDS`, without importing NumPy's heavier neighbours), so that the command
line starts fast.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import signal
import sys
import warnings
from pathlib import Path

from .._version import __version__

__all__ = ["main", "SUBCOMMANDS", "SUBCOMMAND_MODULES", "check_outputs", "PLOT_SUFFIXES",
           "warning_format"]

#: the subcommands, in the order of ``mechdyn --help``, each with the help line its module
#: registers (a test keeps the two the same)
SUBCOMMANDS = {
    "demo": "run a bundled example end to end (CSV + PNG)",
    "examples": "list the bundled example models",
    "check": "validate a model file (every problem at once)",
    "kinematics": "sweep one coordinate: positions, velocities, accelerations, dead centres",
    "simulate": "forward dynamics: integrate the equations of motion over time",
    "kinetostatics": "driving torque, every joint reaction, frame and foundation loads",
    "reduce": "reduced moment of inertia and reduced torque of a 1-DOF mechanism",
    "flywheel": "steady cycle, coefficient of speed fluctuation and flywheel sizing",
    "foundation": "loads on anchor bolts and isolators; natural frequencies of the mounted base",
    "supports": "forces of elastic supports that may lift off (influence coefficients)",
    "study": "design study: many variants of a model, one table row each",
    "animate": "animated GIF of the motion (a sweep of one coordinate, or a simulation)",
    "report": "self-contained HTML report: model, kinematics, kinetostatics, loads on the "
              "building (or a simulation)",
    "warmup": "compile the numba kernels now (once per machine) and report the time",
}

#: modules of this package that define subcommands, in the order of ``mechdyn --help``
SUBCOMMAND_MODULES = tuple(SUBCOMMANDS)


def build_parser(load=SUBCOMMAND_MODULES) -> argparse.ArgumentParser:
    """The argument parser with every subcommand.

    Parameters
    ----------
    load : iterable of str
        The subcommands whose modules are imported and registered in full (default
        all); the others are listed with their help line only.

    Examples
    --------
    >>> parser = build_parser(load=())
    >>> "simulate" in parser.format_help()
    True
    """
    parser = argparse.ArgumentParser(
        prog="mechdyn", description="Kinematics, dynamics and kinetostatics of planar mechanisms.")
    parser.add_argument("--version", action="version", version=f"mechdyn {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    load = set(load)
    for name, help_line in SUBCOMMANDS.items():
        if name not in load:
            sub.add_parser(name, help=help_line, add_help=False)
            continue
        module = importlib.import_module(f"{__name__}.{name}")
        module.register(sub)
        sub.choices[name].set_defaults(func=module.run)
    return parser


def _command(argv: list[str]) -> str | None:
    """The subcommand named in ``argv`` (its first word that is not an option), if any."""
    for arg in argv:
        if not arg.startswith("-"):
            return arg if arg in SUBCOMMANDS else None
    return None


def negative_values(argv: list[str]) -> list[str]:
    """``--from -46deg`` as ``--from=-46deg``: a value that starts with a minus sign and a
    digit is joined to the option before it (argparse would take it for an option).

    Examples
    --------
    >>> negative_values(["sweep", "--from", "-64.1deg", "--to", "30deg"])
    ['sweep', '--from=-64.1deg', '--to', '30deg']
    """
    out: list[str] = []
    for arg in argv:
        if (re.match(r"-\.?\d", arg) and out and out[-1].startswith("--")
                and "=" not in out[-1]):
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


#: image types the plots can be written as
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg")


def check_outputs(args) -> None:
    """Check every output path of a command before it runs: not empty, not a folder, an
    image type for plots, and a folder that can be written into (or created).

    Raises
    ------
    ModelError
        Naming the option, the path and what is wrong.
    """
    from ..errors import ModelError  # here, not at the top: ``--help`` needs no NumPy

    for attr, flag in (("output", "-o"), ("plot", "--plot"), ("snapshot", "--snapshot")):
        value = getattr(args, attr, None)
        if value is None:
            continue
        if not str(value).strip():
            raise ModelError(f"{flag}: the path is empty")
        path = Path(value)
        if path.is_dir():
            raise ModelError(f"{flag} {value}: is a folder, not a file")
        if attr != "output" and path.suffix.lower() not in PLOT_SUFFIXES:
            raise ModelError(f"{flag} {value}: unknown image type {path.suffix or '(none)'!r}; "
                             f"use one of {', '.join(PLOT_SUFFIXES)}")
        folder = path.resolve().parent
        while not folder.exists():
            folder = folder.parent
        if not os.access(folder, os.W_OK):
            raise ModelError(f"{flag} {value}: cannot write into {folder} (no permission or "
                             f"a read-only file system)")


#: the folder of the mechdyn package: a warning raised from a file in it is mechdyn's
_PACKAGE = str(Path(__file__).resolve().parent.parent)


def warning_format(command: str, fallback=None):
    """A :func:`warnings.formatwarning` that writes mechdyn's warnings as one line,
    ``mechdyn COMMAND: warning: MESSAGE``, as the command line's other warnings.

    Only the text changes: where the warnings go (stderr, or a log that records them)
    stays Python's.

    Parameters
    ----------
    command : str
        The subcommand, for the prefix.
    fallback : callable, optional
        Formats the warnings of other packages (NumPy, Matplotlib ...); default
        :func:`warnings.formatwarning` as it is when this is called.

    Returns
    -------
    callable
        ``format(message, category, filename, lineno, line=None) -> str``: a mechdyn
        warning (its class or the file that raised it in the package) on one line,
        without Python's ``file:line: Category:`` prefix; any other by ``fallback``.

    Examples
    --------
    >>> fmt = warning_format("reduce")
    >>> print(fmt(UserWarning("joint 'A' has friction"), UserWarning,
    ...           _PACKAGE + "/dynamics/x.py", 1), end="")
    mechdyn reduce: warning: joint 'A' has friction
    """
    fallback = warnings.formatwarning if fallback is None else fallback

    def format_warning(message, category, filename, lineno, line=None):
        ours = (getattr(category, "__module__", "").startswith("mechdyn")
                or str(Path(filename).resolve()).startswith(_PACKAGE))
        if not ours:
            return fallback(message, category, filename, lineno, line)
        return f"mechdyn {command}: warning: {' '.join(str(message).split())}\n"

    return format_warning


def _quiet_stdout() -> None:
    """Point stdout at the null device: its reader has gone, and Python's flush of it at
    exit would otherwise print an ignored ``BrokenPipeError``."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no real stdout (captured, closed)
        pass


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0 ok, 1 analysis stopped, 2 bad input,
    130 interrupted by Ctrl-C, 143 by SIGTERM; an interrupted run writes its data; 141,
    silently, where the reader of the output stopped reading, as ``| head`` does)."""
    argv = negative_values(sys.argv[1:] if argv is None else list(argv))
    command = _command(argv)
    parser = build_parser(load=() if command is None else (command,))
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    from ..errors import MechdynError

    terminated = []
    owner = os.getpid()

    def on_term(signum, frame):  # SIGTERM ends a run as Ctrl-C does: the data is kept
        if os.getpid() != owner:  # a child forked with this handler: ends as by default
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        terminated.append(signum)
        raise KeyboardInterrupt

    try:
        previous = signal.signal(signal.SIGTERM, on_term)
    except ValueError:  # not the main thread: no handler
        previous = None
    formatwarning = warnings.formatwarning  # mechdyn's warnings as the CLI's one-line form
    warnings.formatwarning = warning_format(args.command)
    try:
        check_outputs(args)
        code = int(args.func(args) or 0)
        return 143 if terminated and code == 130 else code
    except (MechdynError, FileNotFoundError, IsADirectoryError, PermissionError) as exc:
        print(f"mechdyn {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader of the output stopped (``| head``): no message
        _quiet_stdout()
        return 141  # as a command ended by SIGPIPE
    except OSError as exc:  # a full disk, a device that refuses the data ...
        print(f"mechdyn {args.command}: error: cannot write the output: {exc}",
              file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # outside a run (a run keeps its data and says so itself)
        print(f"mechdyn {args.command}: interrupted", file=sys.stderr)
        return 143 if terminated else 130
    finally:
        warnings.formatwarning = formatwarning
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
