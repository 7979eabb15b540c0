"""``mechdyn simulate``: forward dynamics of a model over a time interval.

Examples::

    mechdyn simulate andrews_squeezer --t-end 0.03 --rtol 1e-10 -o andrews.csv
    mechdyn simulate clutchless_press --t-end "0.05 s" --integrator wilson --fixed-steps 40 \\
        --drive phi="34.5 N*m" -o press.csv --plot press.png

Exit codes: 0 done; 1 the run stopped early (dead position, assembly failure,
singular mass matrix ...; the samples computed so far are written); 2 bad input;
130 interrupted by Ctrl-C (the samples computed so far are written).
"""

from __future__ import annotations

import argparse
import copy
import sys
from pathlib import Path

import numpy as np

from ..dynamics.lagrange import FORMULATIONS
from ..errors import ModelError, Status, did_you_mean
from ..mechanism import Drive
from ..results import spectrum
from ..results.events import events_table
from ..results.frame_geometry import trace_spec
from ..results.plot_columns import check_columns
from ..results.plot_dynamics import plot_trajectory
from ..results.plot_spectrum import plot_spectrum
from ..results.table import CsvStream, deg_or_mm, written
from ..simulate.run import simulate
from ..simulate.segments import format_events
from ..units import parse_quantity
from .options import (
    add_engage,
    add_files,
    add_model,
    add_moment_point,
    add_plot_columns,
    add_points,
    add_progress,
    add_run,
    check_plot_columns,
    draw_plot,
    engage_from_args,
    load_model,
    moment_point,
    numeric_columns,
    preview_record,
    quantity,
    with_lock_poses,
)

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``simulate`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "simulate",
        help="forward dynamics: integrate the equations of motion over time",
        description="Integrate Lagrange's equations A(q) q'' + c = Q from the model's "
                    "initial state; write q, q', q'', body poses and the energy balance "
                    "(CSV, columns with unit suffixes), optionally a plot; print the status, "
                    "counters and the energy balance.",
        epilog="Quantities take units: 0.05 s, 20 ms, 34.5 N*m, -64.1 deg, 43.5 rad/s (a bare "
               "number is SI). Exit codes: 0 done, 1 stopped early (data so far written), "
               "2 bad input, 130 interrupted by Ctrl-C (data so far written).")
    add_model(p)
    add_run(p, required=True)
    p.add_argument("--t0", default="0", metavar="TIME", help="start time (default 0 s)")
    p.add_argument("--fixed-steps", type=int, metavar="N",
                   help="number of steps of the fixed-step integrators wilson / rk4")
    p.add_argument("--steps", dest="fixed_steps", type=int, help=argparse.SUPPRESS)
    p.add_argument("--dt", metavar="TIME", help="step size of wilson / rk4")
    p.add_argument("--atol", type=float, help="absolute tolerance (default 1e-3 rtol)")
    p.add_argument("--theta", type=float, help="Wilson theta (1 or >= 1.37)")
    p.add_argument("--iterations", type=int, help="corrector passes of wilson (default 4)")
    p.add_argument("--formulation", default="exact", choices=FORMULATIONS,
                   help="exact analogs (default) or the paper's finite-difference analogs")
    p.add_argument("--d", metavar="ANGLE", help="virtual displacement of --formulation "
                   "analogs (default 0.1deg)")
    p.add_argument("--drive", action="append", default=[], metavar="COORD=TORQUE",
                   help="add a constant drive torque (force) on a coordinate, e.g. "
                        "phi=34.5N*m (repeatable)")
    p.add_argument("--q0", action="append", default=[], metavar="COORD=VALUE",
                   help="initial value of a coordinate, e.g. phi=-64.1deg (repeatable)")
    p.add_argument("--qdot0", action="append", default=[], metavar="COORD=RATE",
                   help="initial rate of a coordinate, e.g. phi=43.5rad/s (repeatable)")
    add_engage(p, "locks engaged at the start")
    add_moment_point(p)
    out = p.add_mutually_exclusive_group()
    out.add_argument("--samples", type=int, metavar="N",
                     help="write N equally spaced samples from the dense output (default "
                          "1001 for the adaptive integrators; wilson and rk4 write their "
                          "uniform steps)")
    out.add_argument("--every-step", action="store_true",
                     help="write one row per integrator step instead")
    add_points(p, "whose positions, velocities and accelerations the table adds", "none")
    add_files(p, plot="write a plot of q, q', q'' and the energies")
    add_plot_columns(p)
    p.add_argument("--spectrum", metavar="COLUMN",
                   help="frequency content of a column of the table, e.g. Fy_frame_N: print "
                        "its peak, RMS and dominant components; with -o also write "
                        "NAME_spectrum.csv, with --plot NAME_spectrum.png")
    p.add_argument("--chunk", type=int, default=2000, metavar="N",
                   help="with -o: rows computed and appended to NAME.csv.partial at a time "
                        "(default 2000); the file becomes NAME.csv when the run ends, so a "
                        "crashed run leaves NAME.csv.partial, readable up to its last chunk")
    p.add_argument("--backend", default="auto", choices=("auto", "numpy", "numba"),
                   help="right-hand side evaluation (default auto: compiled when possible)")
    add_progress(p)


def _pairs(items, model, what, kinds):
    """``COORD=VALUE`` items as {coordinate: SI value}; ``kinds`` = (angle kind, travel kind)."""
    out = {}
    for item in items:
        if "=" not in item:
            raise ModelError(f"{what}: expected COORD=VALUE, got {item!r}")
        name, value = (s.strip() for s in item.split("=", 1))
        if name not in model.coordinates:
            raise ModelError(f"{what}: " + did_you_mean(name, model.coordinates, "coordinate"))
        kind = kinds[0] if model.coordinates[name].is_angle else kinds[1]
        out[name] = quantity(value, kind, f"{what} {name}")
    return out


def run(args) -> int:
    """Run ``mechdyn simulate``; returns the exit code."""
    check_plot_columns(args)
    engaged, poses = engage_from_args(args)
    mech = with_lock_poses(load_model(args.model), poses)
    t_end = parse_quantity(args.t_end, "time", where="--t-end")
    t0 = parse_quantity(args.t0, "time", where="--t0")
    dt = parse_quantity(args.dt, "time", where="--dt") if args.dt is not None else None
    for name, value in _pairs(args.drive, mech, "--drive", ("torque", "force")).items():
        mech.add(Drive(f"drive_{name}", name, value))
    q0 = _pairs(args.q0, mech, "--q0", ("angle", "length")) or None
    qdot0 = _pairs(args.qdot0, mech, "--qdot0", ("angular_velocity", "velocity")) or None
    d = quantity(args.d, "angle", "--d") if args.d is not None else None
    model = mech.compile()
    for point in args.points or ():  # unknown names before the run
        trace_spec(model, point, "--points")
    fixed = args.integrator.lower() in ("wilson", "rk4")
    run = dict(t0=t0, integrator=args.integrator, rtol=args.rtol, atol=args.atol, q0=q0,
               qdot0=qdot0, formulation=args.formulation, d=d, backend=args.backend,
               theta=args.theta, iterations=args.iterations if fixed else None,
               mode=engaged, **_moment_point(args))
    _check_columns(args, model, run, fixed)
    t_eval = None
    if args.samples is None and not (fixed or args.every_step):
        args.samples = 1001
    if args.samples is not None:
        if args.samples < 2:
            raise ModelError(f"--samples must be >= 2, got {args.samples}")
        t_eval = np.linspace(t0, t_end, args.samples)
    stream = None
    if args.output:  # rows written as computed; the whole run kept only for plots
        stream = CsvStream(args.output, table=lambda part: _with_points(
            part, args.points).to_dataframe(points=args.points is not None))
    try:
        traj = simulate(model, t_end, steps=args.fixed_steps, dt=dt, t_eval=t_eval,
                        progress=args.progress, sink=stream, chunk=args.chunk,
                        keep=bool(args.plot or args.spectrum), **run)
    except BaseException:
        if stream is not None:
            stream.abort()  # NAME.csv.partial stays as written so far
        raise
    print(traj.summary())
    if traj.events:
        print(format_events(traj.events, traj.coordinate_names, limit=40))
    if traj.t.size:
        last = ", ".join("{} = {:.9g} {}".format(n, *deg_or_mm(v, a)) for n, v, a in zip(
            traj.coordinate_names, traj.q[-1], traj.coordinate_is_angle, strict=True))
        print(f"at t = {traj.t[-1]:.9g} s: {last}")
    if args.output:
        # its last lines say the status (an interrupted run is marked so)
        stream.close(traj)
        print(f"wrote {args.output} ({stream.rows} rows)")
        if traj.events:
            ev_path = _beside(args.output, "_events.csv")
            with written(ev_path) as tmp:
                events_table(traj.events, traj.coordinate_names).to_csv(tmp, index=False)
            print(f"wrote {ev_path} ({len(traj.events)} events)")
    if args.plot:
        print(f"wrote {draw_plot(args, traj, plot_trajectory)}")
    if args.spectrum and traj.t.size >= 8:
        _spectrum(traj, args)
    if not traj.success:
        print(f"mechdyn simulate: stopped early: {traj.status}: {traj.message}", file=sys.stderr)
        return 130 if traj.status == Status.INTERRUPTED else 1
    return 0


def _check_columns(args, model, run: dict, fixed: bool) -> None:
    """``--plot-columns`` and ``--spectrum`` name columns of the table: checked before the
    run against a preview of it (the same run over 1 us, two samples)."""
    if args.plot_columns is None and args.spectrum is None:
        return
    t0 = run["t0"]
    traj = preview_record(lambda: simulate(
        model, t0 + 1e-6, steps=1 if fixed else None, progress=False,
        t_eval=None if fixed else np.array([t0, t0 + 1e-6]), **run))
    if traj is None or traj.t.size == 0:
        return  # the run itself says why it cannot start
    check_plot_columns(args, traj)
    if args.spectrum is not None:
        check_columns([args.spectrum], numeric_columns(traj.to_dataframe()), "--spectrum")


def _moment_point(args) -> dict:
    """``point=`` of :func:`mechdyn.simulate` when ``--moment-point`` is given."""
    return {} if args.moment_point is None else {"point": moment_point(args)}


def _with_points(traj, points):
    """The trajectory whose table keeps the point columns of ``points`` ("BODY.POINT")
    only; itself when ``points`` lists none (every point, or no point columns)."""
    if not points:
        return traj
    keep = {"_".join(p.split(".", 1)) for p in points}
    drop = [f"{what}{axis}_{b}_{n}_{unit}" for b, n in traj.model.named_points()
            if f"{b}_{n}" not in keep
            for what, unit in (("", "m"), ("v", "m_s"), ("a", "m_s2")) for axis in "xy"]
    full = traj.to_dataframe
    view = copy.copy(traj)  # the same record (its header, status, model), fewer columns
    object.__setattr__(view, "to_dataframe",
                       lambda **kw: full(**kw).drop(columns=drop, errors="ignore"))
    return view


def _beside(path, tail: str) -> Path:
    """The file ``NAME<tail>`` beside ``path`` (``NAME.csv``)."""
    return Path(path).with_name(Path(path).stem + tail)


def _spectrum(traj, args) -> None:
    """Print and write the frequency content of the column ``--spectrum``."""
    col = args.spectrum
    try:
        t, y = spectrum.history(traj, col)
    except KeyError as exc:
        raise ModelError(f"--spectrum: {exc.args[0]}") from None
    summ = spectrum.summary(t, y, n=5)
    print(f"{col}: peak {summ['peak']:.6g} at t = {summ['peak_t']:.6g} s, RMS "
          f"{summ['rms']:.6g}, mean {summ['mean']:.6g}; dominant components:")
    for _, row in summ["dominant"].iterrows():
        print(f"  {row['f_Hz']:10.6g} Hz  amplitude {row['amplitude']:.6g}")
    if args.output:
        out = _beside(args.output, "_spectrum.csv")
        with written(out) as tmp:
            spectrum.spectrum(t, y).to_csv(tmp, index=False)
        print(f"wrote {out}")
    if args.plot:
        print(f"wrote {plot_spectrum(traj, col, _beside(args.plot, '_spectrum.png'))}")
