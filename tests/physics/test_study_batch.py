"""Variants analysed as one batch (mechdyn.study.batch) against the plain loop over
mechdyn.kinetostatics, one cold call per variant; the variants the batch leaves."""

import warnings
from functools import partial

import numpy as np
import pytest

from mechdyn import kinetostatics
from mechdyn.kernels import rows_numpy
from mechdyn.modelfile.loader import build
from mechdyn.study.analyses import KinematicSummary, KinetostaticExtremes
from mechdyn.study.batch import batch_reason, kinetostatic_batch
from mechdyn.study.batch_numbers import affine_variants
from mechdyn.study.designs import design, parse_range
from mechdyn.study.evaluate import Task, attempt, evaluate_batch
from mechdyn.study.parameters import BaseModel

RANGES = ("bodies.crank.points.A.x=40mm..60mm", "bodies.rod.points.B.x=140mm..200mm",
          "bodies.rod.mass=0.8kg..1.6kg", "bodies.crank.com.x=-10mm..10mm")
ANALYSIS = KinetostaticExtremes("1000 rpm", steps=90)


@pytest.fixture(scope="module")
def base():
    return BaseModel("slider_crank")


def loop_figures(base, values: dict, analysis) -> dict:
    """The plain loop's figures: one cold mechdyn.kinetostatics call on the variant read
    with every check of the loader and compiled."""
    model = build(base.document(values), base.name).compile()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        over, positions = analysis.values(model)
        rec = kinetostatics(model, over=over, speed=analysis.speed, values=positions)
    return KinetostaticExtremes.figures(rec).figures


def test_the_batch_equals_the_plain_loop_to_1e_9(base):
    variants = design([parse_range(base, r) for r in RANGES], 20, "lhs", seed=3)
    params = variants.attrs["parameters"]
    values = [dict(zip(params, row, strict=True)) for row in variants.to_numpy()]
    models = [base.compile(v) for v in values]
    assert batch_reason(ANALYSIS, models) is None
    outcomes = kinetostatic_batch(models, ANALYSIS)
    assert all(o is not None for o in outcomes)
    worst = 0.0
    for v, outcome in zip(values, outcomes, strict=True):
        ref = loop_figures(base, v, ANALYSIS)
        assert outcome.status == "success" and set(outcome.figures) == set(ref)
        for col, want in ref.items():
            worst = max(worst, abs(outcome.figures[col] - want) / abs(want))
    assert worst < 1e-9


def test_a_study_batch_with_failing_variants(base):
    """A 10 mm rod has no sketch (its compile names the loop that does not close); a
    45 mm rod on a 50 mm crank assembles at the sketch but not over the whole turn: the
    batch leaves it to the single-model analysis, which says where the turn stops."""
    p = base.parameter("bodies.rod.points.B.x")
    task = Task(base, (p,), ANALYSIS)
    rows = evaluate_batch(task, [(0, (0.16,)), (1, (0.01,)), (2, (0.045,)), (3, (0.18,))])
    assert [r["status"] for r in rows[:2]] == ["success", "assembly-failed"]
    assert rows[2]["status"] in ("assembly-failed", "singular-position")
    assert rows[3]["status"] == "success"
    assert [r["evaluated"] for r in rows] == ["batch", "loop", "loop", "batch"]
    assert "loop through joints" in rows[1]["message"]
    assert "does not close" in rows[1]["message"]
    assert "phi" in rows[2]["message"]  # where the turn stops
    ref = loop_figures(base, {p: 0.18}, ANALYSIS)
    assert rows[3]["M_drive_phi_peak_Nm"] == pytest.approx(ref["M_drive_phi_peak_Nm"],
                                                           rel=1e-9)


def test_other_analyses_go_variant_by_variant(base):
    p = base.parameter("bodies.rod.mass")
    task = Task(base, (p,), KinematicSummary(steps=36))
    rows = evaluate_batch(task, [(0, (1.0,)), (1, (2.0,))])
    assert [r["evaluated"] for r in rows] == ["loop", "loop"]
    assert batch_reason(KinematicSummary(), [base.compile({})]).startswith("the kinematics")


def test_variant_rows_evaluate_each_variant_with_its_own_numbers(base):
    """rows_numpy over rows with a variant axis = the rows of each variant's own model."""
    p = base.parameter("bodies.crank.points.A.x")
    models = [base.compile({p: a}) for a in (0.04, 0.05, 0.06)]
    rows = [m.layout().position_rows for m in models]
    vr = rows_numpy.variant_rows(rows[0], np.stack([r.packed()[1] for r in rows]))
    x = np.random.default_rng(2).normal(size=(3, 4, models[0].n_x))
    v, J, quad = rows_numpy.evaluate(vr, x, 2 * x)
    for k, r in enumerate(rows):
        np.testing.assert_array_equal(v[k], rows_numpy.values(r, x[k]))
        np.testing.assert_array_equal(J[k], rows_numpy.jacobian(r, x[k]))
        np.testing.assert_array_equal(quad[k], rows_numpy.quad(r, x[k], 2 * x[k]))


def test_a_model_with_loads_batched_equals_the_loop():
    """Andrews' squeezer has a spring: each variant's loads are its own (every variant
    compiled), the continuation and the solve still one batch."""
    base = BaseModel("andrews_squeezer")
    model = base.compile({})
    body = model.body_names[-1]
    p = base.parameter(f"bodies.{body}.mass")
    analysis = KinetostaticExtremes("100 rpm", steps=72)
    values = [float(model.mass[-1]) * f for f in (0.8, 1.25)]
    rows = evaluate_batch(Task(base, (p,), analysis), [(0, (values[0],)), (1, (values[1],))])
    assert [r["evaluated"] for r in rows] == ["batch", "batch"]
    for row, v in zip(rows, values, strict=True):
        for col, want in loop_figures(base, {p: v}, analysis).items():
            assert row[col] == pytest.approx(want, rel=1e-9, abs=1e-9), col


def test_numbers_that_are_not_affine_in_the_parameter_compile_every_variant(base):
    """The slider's axis is normalised by the compiler (not affine in its y): the probes'
    fit fails, every variant is compiled, and the batch still equals the loop."""
    p = base.parameter("joints.cylinder.axis.y")
    task = Task(base, (p,), ANALYSIS)
    values = np.array([[0.0], [0.05], [0.1]])
    assert affine_variants(task, values, partial(attempt, task)) is None
    q = base.parameter("bodies.rod.mass")
    assert affine_variants(Task(base, (q,), ANALYSIS), values + 1.0,
                           partial(attempt, Task(base, (q,), ANALYSIS))) is not None
    rows = evaluate_batch(task, [(k, tuple(v)) for k, v in enumerate(values)])
    assert [r["evaluated"] for r in rows] == ["batch"] * 3
    for row, v in zip(rows, values[:, 0], strict=True):
        want = loop_figures(base, {p: v}, ANALYSIS)["M_drive_phi_peak_Nm"]
        assert row["M_drive_phi_peak_Nm"] == pytest.approx(want, rel=1e-9)
