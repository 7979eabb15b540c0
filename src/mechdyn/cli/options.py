"""Options the subcommands share, and their reading: the model, the swept range, the
speed, the output files, the mode and drive of a reduction, a simulation, the exit."""

from __future__ import annotations

import argparse
import dataclasses
import re
import sys
import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .. import examples
from ..errors import ModelError, UnitError, did_you_mean
from ..integrate.base import DEFAULT_RTOL
from ..integrate.driver import INTEGRATORS
from ..kinematics.sweep import initial_coordinates
from ..mechanism.joint import Lock
from ..modelfile import load
from ..modelfile.drives import drive_from_table
from ..reduction.reduce import mode_mechanism
from ..results.plot_columns import check_columns, plot_columns, table_of
from ..results.table import rate_text, write_csv
from ..simulate.run import simulate
from ..units import parse_quantity, parse_vector

__all__ = ["quantity", "vector", "add_model", "add_files", "add_range", "add_start",
           "add_speed", "add_points", "add_engage", "add_moment_point", "engage_from_args",
           "engage_locks", "with_lock_poses", "moment_point", "add_motion_arguments",
           "add_model_arguments", "add_run",
           "load_model", "open_model", "prepare_model", "sweep_values", "model_speed",
           "speed_from_args", "speed_line", "simulate_from_args", "write_files", "finish",
           "add_plot_columns", "check_plot_columns", "draw_plot", "SPEED_DEFAULT",
           "numeric_columns", "preview_record"]


#: kinds whose bare numbers are SI radians, easily mistaken for degrees or rpm
_ANGULAR = {"angle": ("rad", 180 / np.pi, "deg"),
            "angular_velocity": ("rad/s", 30 / np.pi, "rpm"),
            "angular_acceleration": ("rad/s^2", 180 / np.pi, "deg/s^2")}


def quantity(value, kind: str, flag: str) -> float:
    """A command-line quantity in SI (:func:`mechdyn.units.parse_quantity`); a bare number
    for an angle or an angular speed is taken in rad (rad/s) and says so on stderr."""
    out = parse_quantity(value, kind, where=flag)
    text = str(value).strip()
    if kind in _ANGULAR and re.fullmatch(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", text):
        si, factor, other = _ANGULAR[kind]
        print(f"mechdyn: note: {flag} {text} has no unit: taken as {out:g} {si} "
              f"(= {out * factor:.6g} {other}); write the unit, e.g. {text}{other.split('^')[0]}",
              file=sys.stderr)
    return out


def vector(text: str, kinds, flag: str, hint: str) -> tuple:
    """Comma-separated quantities of ``kinds``, in SI; a wrong count names ``hint``."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != len(kinds):
        raise UnitError(f"{flag}: {text!r}: expected {hint}")
    return parse_vector(parts, kinds, where=flag)


def add_model(p) -> None:
    """Add the ``MODEL`` argument."""
    p.add_argument("model", metavar="MODEL",
                   help="model file (.toml) or the name of a bundled example "
                        "(see `mechdyn examples`)")


def add_files(p, plot: str, table: str = "write the table to this CSV file") -> None:
    """Add ``-o/--output CSV`` and ``--plot PNG`` with these help texts."""
    p.add_argument("-o", "--output", metavar="CSV", help=table)
    p.add_argument("--plot", metavar="PNG", help=plot)


#: the default of ``--speed`` in every command, as its help says it
SPEED_DEFAULT = ("default: the model's speed -- the coordinate's initial speed, else the rated "
                 "speed of its drive, else 1 rad/s (1 m/s), where velocities are the velocity "
                 "analogs; the command prints which")


def add_start(p, what: str = "first value") -> None:
    """Add ``--from VALUE`` (default: the coordinate's initial value); ``--start`` is a
    silent alias of it."""
    p.add_argument("--from", dest="start", metavar="VALUE",
                   help=f"{what}, e.g. 0deg (default: the coordinate's initial value)")
    p.add_argument("--start", dest="start", help=argparse.SUPPRESS)


def add_speed(p, what: str) -> None:
    """Add ``--speed RATE``, ``what`` it is; the default is the model's speed
    (:func:`model_speed`)."""
    p.add_argument("--speed", metavar="RATE", help=f"{what}, e.g. 60rpm ({SPEED_DEFAULT})")


def add_points(p, what: str, default: str) -> None:
    """Add ``--points [BODY.POINT ...]``: the named points ``what``; listed, or every named
    point when none is listed; ``default`` without the option."""
    p.add_argument("--points", nargs="*", metavar="BODY.POINT",
                   help=f"named points {what}: those listed, or every named point when the "
                        f"option is given alone (default: {default})")


def add_range(p, *, steps: int, over: str = "coordinate to sweep (default: the first)") -> None:
    """Add the swept range: ``--over``, ``--from`` (alias ``--start``), ``--to``,
    ``--steps``."""
    p.add_argument("--over", metavar="COORD", help=over)
    add_start(p)
    p.add_argument("--to", dest="stop", metavar="VALUE",
                   help="last value (default: one full turn after --from)")
    p.add_argument("--steps", type=int, default=steps, metavar="N",
                   help=f"number of positions, ends included (default {steps})")


def add_run(p, *, required: bool) -> None:
    """Add what a forward-dynamics run needs: ``--t-end``, ``--integrator``, ``--rtol``."""
    p.add_argument("--t-end", required=required, metavar="TIME",
                   help="end time of the run, e.g. 0.05s")
    p.add_argument("--integrator", default="dop853", metavar="NAME",
                   help=f"one of {', '.join(INTEGRATORS)} (default dop853: in the compiled "
                        "loop on the numba kernel, else the same method and step control "
                        "stepped from Python; scipy-dop853: SciPy's DOP853 everywhere)")
    p.add_argument("--rtol", type=float,
                   help=f"relative tolerance of the adaptive integrators (default "
                        f"{DEFAULT_RTOL:g})")


def add_progress(p) -> None:
    """Add ``--progress/--no-progress``: always (or never) show progress on stderr; by
    default once a run takes longer than :data:`mechdyn.progress.PROGRESS_AFTER` (2 s)."""
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="always (or never) show progress on stderr (default: once a run "
                        "takes more than 2 s)")


def add_motion_arguments(p, metavar: str, output: str, *, steps: int, verb: str, title: str):
    """Add what ``mechdyn animate`` and ``report`` share: model, -o, sweep and simulation
    groups; returns the drawing group (``--trace``, ``--title``)."""
    add_model(p)
    p.add_argument("-o", "--output", required=True, metavar=metavar, help=output)
    add_range(p.add_argument_group("sweep (default)"), steps=steps)
    s = p.add_argument_group("simulation")
    s.add_argument("--simulate", action="store_true",
                   help=f"{verb} a forward-dynamics run from the model's initial state")
    add_run(s, required=False)
    d = p.add_argument_group("drawing")
    d.add_argument("--trace", metavar="BODY.POINT", help="draw the path of this point")
    d.add_argument("--title", help=title)
    add_progress(p)
    return d


def add_engage(p, what: str = "engaged locks", *, alias: str | None = None) -> None:
    """Add ``--engage LOCK[,LOCK...]`` (repeatable; ``none`` releases every lock; a lock
    may carry the pose it holds, ``LOCK=X,Y,THETA``); ``alias`` is a hidden old
    spelling of it (``--mode`` in kinetostatics)."""
    p.add_argument("--engage", action="append", default=None, metavar="LOCK[,LOCK...]",
                   help=f"{what}, comma separated or repeated, each optionally with the pose "
                        f"it holds, e.g. rocker_lock=0mm,0mm,0deg; 'none' releases every "
                        f"lock (default: as declared in the model)")
    if alias:
        p.add_argument(alias, dest="engage", action="append", help=argparse.SUPPRESS)


def engage_from_args(args) -> tuple[frozenset | None, dict]:
    """The engaged locks of ``--engage`` (None when not given; empty for ``none``) and
    the poses given with them, {lock: (x m, y m, theta rad)}.

    Examples
    --------
    >>> ns = argparse.Namespace(engage=["a,b=1m,0,0", "c"])
    >>> names, poses = engage_from_args(ns)
    >>> sorted(names), poses
    (['a', 'b', 'c'], {'b': (1.0, 0.0, 0.0)})
    """
    if getattr(args, "engage", None) is None:
        return None, {}
    names, poses = [], {}
    for spec in args.engage:
        parts = [t.strip() for t in spec.split(",")]
        while parts:
            name, sep, first = parts.pop(0).partition("=")
            name = name.strip()
            if sep:  # the pose: this value and the next two
                pose, parts = [first, *parts[:2]], parts[2:]
                poses[name] = vector(",".join(pose), ("length", "length", "angle"),
                                     f"--engage {name}",
                                     f"the pose as X,Y,THETA, e.g. {name}=0mm,0mm,0deg")
            if name:
                names.append(name)
    if [n.lower() for n in names] == ["none"]:
        return frozenset(), {}
    if any(n.lower() == "none" for n in names):
        raise ModelError("--engage: 'none' releases every lock and is given alone")
    return frozenset(names), poses


def engage_locks(mech, engaged: frozenset | None, poses: dict, drop=()):
    """A copy of the mechanism with exactly the ``engaged`` locks engaged (at their
    ``poses``; the others released) and the coordinates ``drop`` removed; itself when
    ``engaged`` is None and nothing is dropped."""
    if engaged is None and not drop:
        return mech
    if engaged is not None:
        mech = dataclasses.replace(mech, joints={
            n: dataclasses.replace(j, engaged=False)
            if isinstance(j, Lock) and n not in engaged and j.engaged else j
            for n, j in mech.joints.items()})
    return mode_mechanism(mech, engage=sorted(engaged or ()), offsets=poses, drop=list(drop))


def with_lock_poses(mech, poses: dict):
    """A copy of the mechanism whose locks hold the ``poses`` given with ``--engage`` when
    engaged (their declared state unchanged: the analysis takes the mode); itself when
    there are none."""
    if not poses:
        return mech
    locks = [n for n, j in mech.joints.items() if isinstance(j, Lock)]
    bad = [did_you_mean(n, locks, "lock") for n in poses if n not in locks]
    if bad:
        raise ModelError([f"--engage: {b}" for b in bad])
    return dataclasses.replace(mech, joints={
        n: dataclasses.replace(j, offset=tuple(map(float, poses[n]))) if n in poses else j
        for n, j in mech.joints.items()})


def add_moment_point(p, *, alias: str | None = None) -> None:
    """Add ``--moment-point X,Y``: the point the frame moment is taken about; ``alias``
    a hidden old spelling of it."""
    p.add_argument("--moment-point", default=None, metavar="X,Y",
                   help="point the frame moment (shaking moment) is taken about, e.g. 0,0 or "
                        "'100mm,-50mm' (default 0,0, the ground origin)")
    if alias:
        p.add_argument(alias, dest="moment_point", help=argparse.SUPPRESS)


def moment_point(args) -> tuple[float, float]:
    """``--moment-point`` in m (default the ground origin)."""
    if args.moment_point is None:
        return (0.0, 0.0)
    return vector(args.moment_point, ("length", "length"), "--moment-point",
                  "two lengths X,Y, e.g. 0,0 or 100mm,-50mm")


def add_model_arguments(p) -> None:
    """Arguments shared by ``reduce`` and ``flywheel``: the model, its mode and its drive."""
    add_model(p)
    add_engage(p, "locks engaged in the mode reduced")
    p.add_argument("--drop", action="append", default=[], metavar="COORD",
                   help="remove a coordinate frozen by the engaged locks (repeatable)")
    p.add_argument("--motor", metavar="DESIGNATION",
                   help="replace the drives by a catalogue induction motor, e.g. 4A80B4U3")
    p.add_argument("--characteristic", choices=("kloss", "extended"), default="kloss",
                   help="form of the motor characteristic (default kloss)")
    p.add_argument("--gear-ratio", metavar="I",
                   help="ratio omega_motor/omega_crank of a gear stage after the motor")
    p.add_argument("--efficiency", metavar="ETA", help="efficiency of the gear stage (0..1]")


def load_model(spec: str):
    """A :class:`~mechdyn.mechanism.Mechanism` from a file path or a bundled example name."""
    path = Path(spec)
    if path.is_file():
        return load(path)
    if path.suffix == ".toml" or path.parent != Path("."):
        raise FileNotFoundError(f"no model file {spec!r}")
    return examples.load(spec)  # a ModelError lists the bundled examples


def open_model(args):
    """(mechanism, compiled model) of the ``MODEL`` argument."""
    mech = load_model(args.model)
    return mech, mech.compile()


def prepare_model(args):
    """(mechanism, model) from the arguments of :func:`add_model_arguments`: load, mode,
    drive; compiled."""
    mech = load_model(args.model)
    engaged, poses = engage_from_args(args)
    mech = engage_locks(mech, engaged, poses, args.drop)
    if args.motor is None and (args.gear_ratio is not None or args.efficiency is not None):
        raise ModelError("--gear-ratio and --efficiency need --motor")
    if args.motor is not None:
        coords = list(mech.coordinates)
        if len(coords) != 1:
            raise ModelError(f"--motor: the model has coordinates {', '.join(coords)}; "
                             f"reduce it to one (--engage LOCK --drop COORD)")
        table = {"type": "induction_motor", "name": "motor", "coordinate": coords[0],
                 "catalogue": args.motor, "characteristic": args.characteristic}
        if args.gear_ratio is not None:
            table["gear_ratio"] = args.gear_ratio
        if args.efficiency is not None:
            table["efficiency"] = args.efficiency
        mech.drives[:] = [drive_from_table(table, "--motor")]
    return mech, mech.compile()


def sweep_values(model, args, *, only: bool = False):
    """The swept coordinate, its values and its rate from ``--over/--from/--to/--steps``
    and ``--speed`` (units parsed).

    Without ``--from`` the range starts at the coordinate's initial value; with ``only``
    and no ``--over`` the model must have one coordinate.

    Returns
    -------
    (str, ndarray, float or None)
        The coordinate's name; ``steps`` values to ``--to`` (default one turn after the
        first; required for a travel); ``--speed`` in rad/s or m/s (None if not given).
    """
    if args.over is None and only and model.n_q != 1:
        raise ModelError("the model has several coordinates; choose one with --over: "
                         + ", ".join(model.coordinate_names))
    over = args.over if args.over is not None else model.coordinate_names[0]
    k = model.coordinate_index(over)
    angle = bool(model.coord_is_angle[k])
    kind = "angle" if angle else "length"
    if args.steps < 1:
        raise ModelError(f"--steps must be at least 1, got {args.steps}")
    if args.start is not None:
        start = quantity(args.start, kind, "--from")
    else:
        start = float(initial_coordinates(model)[k])
    if args.stop is not None:
        stop = quantity(args.stop, kind, "--to")
    elif angle:
        stop = start + 2 * np.pi
    else:
        raise ModelError(f"coordinate {over!r} is a travel: give the range with --from and --to")
    speed = getattr(args, "speed", None)  # animate has no --speed
    if speed is not None:
        speed = quantity(speed, "angular_velocity" if angle else "velocity", "--speed")
    return over, np.linspace(start, stop, args.steps), speed


def model_speed(model, over: str, fallback: float | None = 1.0) -> tuple[float | None, str]:
    """The model's own speed of a coordinate, and where it comes from.

    The coordinate's initial speed (the model file's ``initial_speed``) if it is not
    zero; else the rated speed of a drive on the coordinate (a motor's rated speed
    divided by the ratios of its gear stages, a constant-speed drive's speed); else 1
    (rad/s or m/s: velocities are then the velocity analogs).

    Parameters
    ----------
    model : Model
    over : str
        The coordinate's name.

    Returns
    -------
    (float, str)
        The speed, rad/s (m/s for a travel), and the reason, e.g. ``"the initial speed of
        phi in the model"``.

    Raises
    ------
    ModelError
        Unknown coordinate (the message lists the valid ones).

    Examples
    --------
    >>> from mechdyn import examples
    >>> model = examples.load("toggle_press").compile()
    >>> speed, why = model_speed(model, "phi")
    >>> round(speed * 30 / np.pi, 9), why
    (40.0, 'the initial speed of phi in the model')
    """
    k = model.coordinate_index(over)
    mech = model.mechanism
    qd0 = (mech.extras.get("initial") or {}).get("qdot")
    if isinstance(qd0, Mapping):
        rate = float(qd0.get(over, 0.0))
    else:
        rate = 0.0 if qd0 is None else float(np.asarray(qd0, float).reshape(-1)[k])
    if rate != 0.0:
        return rate, f"the initial speed of {over} in the model"
    for drive in mech.drives:
        if getattr(drive, "coordinate", None) != over:
            continue
        torque, ratio = getattr(drive, "torque", drive), 1.0
        while hasattr(torque, "ratio") and hasattr(torque, "motor"):  # gear stages
            ratio *= float(torque.ratio)
            torque = torque.motor
        for attr in ("rated_speed", "speed"):
            value = getattr(torque, attr, None)
            if isinstance(value, (int, float)) and value != 0:
                gear = f" through a gear of ratio {ratio:g}" if ratio != 1.0 else ""
                return float(value) / ratio, (f"the {attr.replace('_', ' ')} of drive "
                                              f"{drive.name!r} on {over}{gear}")
    why = f"the model gives {over} no speed (no initial speed, no drive with a rated speed)"
    if fallback is None:
        return None, why
    unit = "rad/s" if model.coord_is_angle[k] else "m/s"
    return float(fallback), f"{why}: {fallback:g} {unit}; give --speed"


def speed_from_args(model, over: str, args, fallback: float | None = 1.0):
    """``--speed`` (units parsed) and ``"given with --speed"``, else :func:`model_speed`."""
    if getattr(args, "speed", None) is None:
        return model_speed(model, over, fallback)
    angle = bool(model.coord_is_angle[model.coordinate_index(over)])
    return (quantity(args.speed, "angular_velocity" if angle else "velocity", "--speed"),
            "given with --speed")


def speed_line(speed: float, is_angle: bool, why: str) -> str:
    """The line every command prints about the speed it used: ``"  speed 4.18879 rad/s
    (40 rpm): the initial speed of phi in the model"``."""
    return f"  speed {rate_text(speed, is_angle)}: {why}"


def simulate_from_args(model, args, samples: int):
    """The forward-dynamics run of ``--simulate`` (needs ``--t-end``), ``samples`` samples;
    a progress bar once it takes more than 2 s."""
    if args.t_end is None:
        raise ModelError("--simulate needs --t-end, e.g. --t-end 0.05s")
    t_end = parse_quantity(args.t_end, "time", where="--t-end")
    return simulate(model, t_end, integrator=args.integrator, rtol=args.rtol,
                    progress=getattr(args, "progress", None),
                    t_eval=np.linspace(0.0, t_end, samples))


def write_files(args, record, plot, **kwargs) -> None:
    """Write the record's table (``-o``, CSV with a header of units) and ``--plot`` if given."""
    if args.output:
        print(f"  table: {write_csv(record, args.output)}")
    if args.plot:
        print(f"  plot: {draw_plot(args, record, plot, **kwargs)}")


def finish(args, ok: bool, message: str) -> int:
    """The exit code of a run: 0 if ``ok``, else 1 after a warning line on stderr."""
    if ok:
        return 0
    print(f"mechdyn {args.command}: warning: {message}", file=sys.stderr)
    return 1


def add_plot_columns(p) -> None:
    """Add ``--plot-columns``: the columns ``--plot`` draws instead of its default panels."""
    p.add_argument("--plot-columns", metavar="COL,COL...",
                   help="with --plot: draw these columns of the table instead (names as in "
                        "the CSV, e.g. phi_deg,omega_rod_rad_s; one panel per unit, angles "
                        "in deg, lengths in mm)")


def check_plot_columns(args, record=None) -> None:
    """``--plot-columns`` needs ``--plot``; every column it names is one of the numeric
    columns of ``record``'s table (else the error lists the valid columns).

    ``record`` is the result, or before the run a preview of it (the same analysis over
    two positions, :func:`preview_record`): its table has the columns of the run's.
    """
    columns = getattr(args, "plot_columns", None)
    if columns is None:
        return
    if not args.plot:
        raise ModelError("--plot-columns needs --plot FILE (the image to draw them in)")
    if record is not None:
        check_columns(columns, numeric_columns(table_of(record)), "--plot-columns")


def numeric_columns(table) -> list[str]:
    """The names of the numeric columns of a table (a pandas DataFrame)."""
    return [c for c in table.columns if table[c].dtype.kind in "iuf"]


def preview_record(run):
    """The record of ``run()``, the command's analysis over two positions or samples, whose
    table names the columns of the full run's; None when ``run`` raises (the full run then
    says why)."""
    try:
        with warnings.catch_warnings():  # the full run warns
            warnings.simplefilter("ignore")
            return run()
    except (ModelError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None


def draw_plot(args, record, plot, **kwargs):
    """Write ``--plot``: the chosen ``--plot-columns``, else ``plot(record, path, **kwargs)``."""
    if getattr(args, "plot_columns", None):
        check_plot_columns(args, record)
        return plot_columns(record, args.plot_columns, args.plot)
    return plot(record, args.plot, **kwargs)
