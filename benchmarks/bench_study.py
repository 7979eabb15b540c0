"""Design study of the slider-crank: variants per second of :func:`mechdyn.study.run_study`
vs the plain loop over :func:`mechdyn.kinetostatics`.

200 variants (crank radius 40-60 mm, rod length 140-200 mm, Latin hypercube, seed 1),
each a 360-position kinetostatic cycle at 1000 rpm.  The loop builds each variant
from the model file (every check of the loader, then a compile) and analyses it from its
own sketch (the continuation); the study analyses the variants as batches
(:mod:`mechdyn.study.batch`: the numbers of each batch from a few compiled probes, the
continuation and the kinetostatic solve over a variant axis), in this process and in
local worker processes.  Wall times; the one-process runs also give their CPU time,
steadier than wall time on a shared machine, and the large study its CPU time with its
worker processes' (a CPU ratio: the wall ratio counts the worker processes' parallelism).

The acceptance figures of issue 13 (same run): 10 000 variants of the same design in
local worker processes under 60 s of wall time, at least 50x the plain loop's variants
per second (its 200 variants), and the batch's figures equal to the loop's to 1e-9
relative (every figure of the 200 variants).
"""

from __future__ import annotations

import os
import time

import numpy as np

from mechdyn import kinetostatics
from mechdyn.modelfile.loader import build
from mechdyn.study.analyses import KinetostaticExtremes
from mechdyn.study.designs import design, parse_range
from mechdyn.study.execute import run_study
from mechdyn.study.parameters import BaseModel

N_VARIANTS = 200
#: the acceptance's large study
N_LARGE = 10_000
RANGES = ("bodies.crank.points.A.x=40mm..60mm", "bodies.rod.points.B.x=140mm..200mm")


def plain_loop(base, variants, analysis) -> list[dict]:
    """The figures of each variant, one cold kinetostatics call each (the variant read
    with every check of the loader, then compiled)."""
    params = variants.attrs["parameters"]
    out = []
    for row in variants.to_numpy():
        doc = base.document(dict(zip(params, row, strict=True)))
        model = build(doc, base.name).compile()
        over, values = analysis.values(model)
        rec = kinetostatics(model, over=over, speed=analysis.speed, values=values)
        out.append(KinetostaticExtremes.figures(rec).figures)
    return out


def largest_difference(table, figures: list[dict]) -> float:
    """The largest relative difference between a study's figures and the loop's."""
    worst = 0.0
    for k, ref in enumerate(figures):
        for col, want in ref.items():
            worst = max(worst, abs(float(table.loc[k, col]) - want) / max(abs(want), 1e-300))
    return worst


def run(quick: bool = False) -> list[dict]:
    n = 40 if quick else N_VARIANTS
    n_large = 1000 if quick else N_LARGE
    base = BaseModel("slider_crank")
    ranges = [parse_range(base, r) for r in RANGES]
    variants = design(ranges, n, "lhs", seed=1)
    analysis = KinetostaticExtremes("1000 rpm", steps=360)
    run_study(base, variants.iloc[:4], analysis, workers=1, progress=False)  # warm-up

    t0, c0 = time.perf_counter(), time.process_time()
    figures = warnings_off(plain_loop, base, variants, analysis)
    t_loop, c_loop = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    one = run_study(base, variants, analysis, workers=1, progress=False)
    t_one, c_one = time.perf_counter() - t0, time.process_time() - c0
    t0 = time.perf_counter()
    many = run_study(base, variants, analysis, progress=False)
    t_many = time.perf_counter() - t0
    rel = largest_difference(one, figures)
    same = bool(np.allclose(many["M_drive_phi_peak_Nm"], one["M_drive_phi_peak_Nm"],
                            rtol=1e-9, atol=0.0))
    large = design(ranges, n_large, "lhs", seed=2)
    t0, c0 = time.perf_counter(), cpu_with_workers()
    big = run_study(base, large, analysis, progress=False)
    t_big, c_big = time.perf_counter() - t0, cpu_with_workers() - c0
    ratio = (n_large / t_big) / (n / t_loop)
    cpu_ratio = (n_large / c_big) / (n / c_loop)
    batched = int((big["evaluated"] == "batch").sum())
    ok = int((big["status"] == "success").sum())
    return [
        {"name": f"plain loop, {n} variants", "value": n / t_loop, "unit": "variants/s",
         "note": f"{1e3 * t_loop / n:.1f} ms per variant ({1e3 * c_loop / n:.1f} ms CPU)"},
        {"name": "study, one process", "value": n / t_one, "unit": "variants/s",
         "note": f"{t_loop / t_one:.2f}x the loop ({c_loop / c_one:.2f}x in CPU); "
                 f"{1e3 * t_one / n:.2f} ms per variant ({1e3 * c_one / n:.2f} ms CPU); "
                 f"largest relative difference of the figures {rel:.1e}"},
        {"name": "study, local processes", "value": n / t_many, "unit": "variants/s",
         "note": f"{t_loop / t_many:.2f}x the loop; same as one process to 1e-9: {same}"},
        {"name": f"study of {n_large} variants, local processes", "value": t_big, "unit": "s",
         "note": f"{ratio:.1f}x the plain loop's variants/s (acceptance: < 60 s, >= 50x, "
                 f"figures to 1e-9: {rel:.1e}); {cpu_ratio:.1f}x in CPU "
                 f"({1e3 * c_big / n_large:.2f} ms CPU per variant, the workers' included); "
                 f"{batched} as batches, {ok} succeeded"},
    ]


def cpu_with_workers() -> float:
    """CPU seconds of this process and of its finished worker processes."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def warnings_off(fn, *args):
    """fn(*args) without warnings (the loop's records carry theirs)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args)
