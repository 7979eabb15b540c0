"""Design study of the slider-crank: variants per second of :func:`mechdyn.study.run_study`
vs the plain loop over :func:`mechdyn.kinetostatics`.

200 variants (crank radius 40-60 mm, rod length 140-200 mm, Latin hypercube, seed 1),
each a 360-position kinetostatic cycle at 1000 rpm.  The loop builds each variant
from the model file (every check of the loader, then a compile) and analyses it from its
own sketch (the continuation); the study builds each variant without the JSON-schema pass
(its structure is the base's), keeps the Model its validation compiled, and orders the
variants so that each starts from the previous one's poses (one batched Newton solve), in
this process and in local worker processes.  Wall times (the
worker processes' CPU is not this process's); the one-process runs also give their CPU
time, steadier than wall time on a shared machine.
"""

from __future__ import annotations

import time

import numpy as np

from mechdyn import kinetostatics
from mechdyn.modelfile.loader import build
from mechdyn.study.analyses import KinetostaticExtremes
from mechdyn.study.designs import design, parse_range
from mechdyn.study.execute import run_study
from mechdyn.study.parameters import BaseModel

N_VARIANTS = 200
RANGES = ("bodies.crank.points.A.x=40mm..60mm", "bodies.rod.points.B.x=140mm..200mm")


def plain_loop(base, variants, analysis) -> list[float]:
    """Peak driving torque of each variant, one cold kinetostatics call each (the variant
    read with every check of the loader, then compiled)."""
    params = variants.attrs["parameters"]
    peaks = []
    for row in variants.to_numpy():
        doc = base.document(dict(zip(params, row, strict=True)))
        model = build(doc, base.name).compile()
        over, values = analysis.values(model)
        rec = kinetostatics(model, over=over, speed=analysis.speed, values=values)
        peaks.append(float(np.max(np.abs(rec.driving[over]))))
    return peaks


def run(quick: bool = False) -> list[dict]:
    n = 40 if quick else N_VARIANTS
    base = BaseModel("slider_crank")
    variants = design([parse_range(base, r) for r in RANGES], n, "lhs", seed=1)
    analysis = KinetostaticExtremes("1000 rpm", steps=360)
    run_study(base, variants.iloc[:4], analysis, workers=1, progress=False)  # warm-up

    t0, c0 = time.perf_counter(), time.process_time()
    peaks = plain_loop(base, variants, analysis)
    t_loop, c_loop = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    one = run_study(base, variants, analysis, workers=1, progress=False)
    t_one, c_one = time.perf_counter() - t0, time.process_time() - c0
    t0 = time.perf_counter()
    many = run_study(base, variants, analysis, progress=False)
    t_many = time.perf_counter() - t0
    rel = float(np.max(np.abs(one["M_drive_phi_peak_Nm"] - peaks) / np.abs(peaks)))
    same = bool(np.allclose(many["M_drive_phi_peak_Nm"], one["M_drive_phi_peak_Nm"],
                            rtol=1e-9, atol=0.0))
    return [
        {"name": f"plain loop, {n} variants", "value": n / t_loop, "unit": "variants/s",
         "note": f"{1e3 * t_loop / n:.1f} ms per variant ({1e3 * c_loop / n:.1f} ms CPU)"},
        {"name": "study, one process", "value": n / t_one, "unit": "variants/s",
         "note": f"{t_loop / t_one:.2f}x the loop ({c_loop / c_one:.2f}x in CPU); "
                 f"{1e3 * t_one / n:.1f} ms per variant ({1e3 * c_one / n:.1f} ms CPU); "
                 f"largest relative difference of the peak torque {rel:.1e}"},
        {"name": "study, local processes", "value": n / t_many, "unit": "variants/s",
         "note": f"{t_loop / t_many:.2f}x the loop; same as one process to 1e-9: {same}"},
    ]
