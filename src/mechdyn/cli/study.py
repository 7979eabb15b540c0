"""``mechdyn study``: many variants of one model file, analysed, tabulated, optimised.

Example::

    mechdyn study slider_crank --vary bodies.crank.points.A.x=40mm..60mm \\
        --vary bodies.rod.points.B.x=140mm..200mm --samples 1000 --design lhs --seed 1 \\
        --analysis kinetostatics --speed 1000rpm --steps 360 -o s.csv
    mechdyn study slider_crank --vary bodies.crank.points.A.x=40mm..60mm \\
        --vary bodies.rod.com.x=-60mm..60mm --analysis kinetostatics,kinematics \\
        --speed 1000rpm --steps 72 --minimise M_drive_phi_peak_Nm \\
        --constraint stroke_cylinder_m=0.1 -o opt.csv

Each variant is a row of the table (``.csv`` or ``.parquet``), written batch by batch
as the variants finish, so an interrupted study keeps what is done and ``--resume``
goes on from there. ``--scheduler ADDRESS`` runs the batches on a Dask cluster
(``local``: a cluster of local processes).

Exit codes: 0 done (failed variants are rows of the table); 2 bad input; 130
interrupted (the variants done are written).
"""

from __future__ import annotations

import os
import sys
import time

from ..errors import ModelError
from ..study.analyses import (
    ANALYSES,
    Combined,
    FlywheelSize,
    KinematicSummary,
    KinetostaticExtremes,
    check_figures,
)
from ..study.designs import DESIGNS, design, parse_range
from ..study.execute import run_study
from ..study.optimise import optimise, parse_constraint
from ..study.parameters import BaseModel
from ..study.plots import axis_label, plot_scatter
from ..study.report import write_study_report
from ..units import parse_quantity
from .options import add_model, add_progress, model_speed, quantity, speed_line

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add the ``study`` subcommand to an argparse subparsers object."""
    p = sub.add_parser(
        "study", help="design study: many variants of a model, one table row each",
        description="Vary model-file values (by their path, with units) over a grid, random "
                    "or Latin-hypercube design, analyse every variant (kinetostatic extremes, "
                    "kinematic summary, flywheel) and write one table row per variant; or "
                    "minimise a figure subject to constraints.",
        epilog="Exit codes: 0 done (failed variants are rows with their status), 2 bad input, "
               "130 interrupted (the variants done are written; --resume goes on).")
    add_model(p)
    p.add_argument("--vary", action="append", required=True, metavar="KEY=LOW..HIGH",
                   help="a model-file value and its range, e.g. "
                        "bodies.crank.points.A.x=40mm..60mm (repeatable)")
    p.add_argument("--samples", type=int, default=100, metavar="N",
                   help="number of variants (grid: about N) (default 100)")
    p.add_argument("--design", choices=DESIGNS, default="lhs", help="default lhs")
    p.add_argument("--seed", type=int, metavar="S", help="seed of the random designs")
    p.add_argument("--analysis", default="kinetostatics", metavar="NAME[,NAME]",
                   help=f"one or more of {', '.join(ANALYSES)} (default kinetostatics)")
    p.add_argument("--speed", metavar="RATE",
                   help="crank speed, e.g. 1000rpm (default: the model's own speed)")
    p.add_argument("--steps", type=int, default=360, metavar="N",
                   help="positions over one turn (default 360)")
    p.add_argument("--over", metavar="COORD", help="driven coordinate (default the first)")
    p.add_argument("--delta", metavar="DELTA", help="flywheel: target speed fluctuation")
    p.add_argument("-o", "--output", required=True, metavar="TABLE",
                   help="the table, .csv or .parquet")
    p.add_argument("--resume", action="store_true",
                   help="keep the variants the output already holds, analyse the others")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on this Dask scheduler (tcp://host:8786), or 'local' for a "
                        "cluster of local processes")
    p.add_argument("--workers", type=int, metavar="N",
                   help="local worker processes (default: one per CPU)")
    p.add_argument("--batch", type=int, metavar="N", help="variants per task")
    p.add_argument("--figure", metavar="COLUMN",
                   help="the figure summarised and plotted (default the first)")
    p.add_argument("--plot", metavar="PNG", help="plot the first parameter against --figure")
    p.add_argument("--report", metavar="HTML",
                   help="write an HTML page: ranges, best and failed variants, plots")
    add_progress(p)
    o = p.add_argument_group("optimisation")
    o.add_argument("--minimise", metavar="COLUMN", help="minimise this figure instead")
    o.add_argument("--constraint", action="append", default=[], metavar="COLUMN>=VALUE",
                   help="bound on a figure, in its column's unit (repeatable)")
    o.add_argument("--method", default="cobyqa",
                   help="scipy.optimize.minimize method, or differential_evolution "
                        "(default cobyqa)")


def _analysis(args, base):
    given = None if args.speed is None else quantity(args.speed, "angular_velocity", "--speed")
    parts = []
    for name in [n.strip() for n in args.analysis.split(",") if n.strip()]:
        if name not in ANALYSES:
            raise ModelError(f"--analysis {name!r}: use one of {', '.join(ANALYSES)}")
        if name == "kinetostatics":
            speed = given
            if speed is None:  # the base model's own speed, as in every command
                model = base.compile({})
                over = args.over or model.coordinate_names[0]
                speed, why = model_speed(model, over)
                print(speed_line(speed, bool(model.coord_is_angle[
                    model.coordinate_index(over)]), why))
            parts.append(KinetostaticExtremes(speed, args.steps, args.over))
        elif name == "kinematics":
            parts.append(KinematicSummary(args.steps, args.over))
        else:
            if args.delta is None:
                raise ModelError("--analysis flywheel needs --delta, e.g. --delta 0.05")
            parts.append(FlywheelSize(parse_quantity(args.delta, "ratio", where="--delta"),
                                      given))
    if not parts:
        raise ModelError("--analysis: name at least one analysis")
    return parts[0] if len(parts) == 1 else Combined(tuple(parts))


def _client(address: str, workers: int | None):
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ModelError("--scheduler needs dask.distributed: pip install "
                         "'mechdyn[study]'") from None
    if address == "local":
        cluster = LocalCluster(processes=True, n_workers=workers or os.cpu_count() or 1,
                               threads_per_worker=1, dashboard_address=":0")
        return Client(cluster), cluster
    return Client(address), None


def _summary(df, args, ranges, seconds: float) -> None:
    n = len(df)
    now = df.attrs.get("analysed", n)
    counts = df["status"].value_counts().to_dict() if n else {}
    resumed = f", {n - now} resumed" if now != n else ""
    print(f"{args.model}: {n} variants ({now} analysed in {seconds:.1f} s, "
          f"{1e3 * seconds / max(now, 1):.1f} ms each of wall time{resumed}); "
          + ", ".join(f"{v} {k}" for k, v in counts.items()))
    if "evaluated" in df:  # as one batch (study.batch) or one by one
        how = df["evaluated"].value_counts().to_dict()
        why = df.attrs.get("one_by_one", "")
        print(f"  evaluated: {how.get('batch', 0)} as batches of variants, "
              f"{how.get('loop', 0)} one by one" + (f" ({why})" if why else ""))
    params = [r.parameter.column for r in ranges]
    figures = [c for c in df if c not in ("variant", "status", "message", "evaluated", "seconds",
                                          "objective", "feasible") and c not in params]
    if not figures:
        return
    fig = args.figure or args.minimise or figures[0]
    if fig not in df:
        raise ModelError(f"--figure {fig!r}: the table has {', '.join(figures)}")
    ok = df[df["status"].isin(("success", "redundant"))]
    if len(ok) == 0:
        return
    label, factor = axis_label(fig)
    best = ok.loc[ok[fig].idxmin()]
    print(f"  {label}: {ok[fig].min() * factor:.6g} .. {ok[fig].max() * factor:.6g}")
    where = ", ".join(f"{axis_label(c)[0]} = {best[c] * axis_label(c)[1]:.6g}" for c in params)
    print(f"  smallest {label}: {best[fig] * factor:.6g} at variant {int(best['variant'])}: "
          f"{where}")
    if args.plot:
        print(f"  plot: {plot_scatter(df, params[0], fig, args.plot)}")
    if getattr(args, "report", None):
        page = write_study_report(df, args.report, params, figure=fig,
                                  title=f"{args.model}: design study")
        print(f"  report: {page}")


def run(args) -> int:
    """Run ``mechdyn study``; returns the exit code."""
    base = BaseModel(args.model)
    ranges = [parse_range(base, spec) for spec in args.vary]
    analysis = _analysis(args, base)
    constraints = [parse_constraint(c) for c in args.constraint]
    check_figures(analysis, base.compile({}),  # the names, before the first variant
                  {"--minimise": args.minimise, "--figure": args.figure,
                   **{f"--constraint {c.column}": c.column for c in constraints}},
                  [r.parameter.column for r in ranges])
    t0 = time.perf_counter()
    if args.minimise:
        best = optimise(base, ranges, analysis, args.minimise, method=args.method,
                        constraints=constraints,
                        seed=args.seed, output=args.output)
        _summary(best.table, args, ranges, time.perf_counter() - t0)
        print(f"  optimum ({args.method}, {best.evaluations} evaluations, "
              f"{'converged' if best.success else 'not converged'}: {best.message})")
        print(f"  table: {args.output}")
        return 0
    variants = design(ranges, args.samples, args.design, args.seed)
    client = cluster = None
    if args.scheduler:
        client, cluster = _client(args.scheduler, args.workers)
    t0 = time.perf_counter()  # the study, not the start of its cluster
    try:
        df = run_study(base, variants, analysis, output=args.output, client=client,
                       workers=args.workers, batch_size=args.batch, resume=args.resume,
                       progress=args.progress)
    except KeyboardInterrupt:
        print(f"mechdyn study: interrupted; the variants done are in {args.output} "
              f"(run again with --resume to go on)", file=sys.stderr)
        return 130
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    _summary(df, args, ranges, time.perf_counter() - t0)
    print(f"  table: {args.output}")
    return 0
