"""Design studies against the plain loop over mechdyn.kinetostatics, failing variants,
and the same study on a Dask cluster."""

import numpy as np
import pandas as pd
import pytest

from mechdyn import kinetostatics
from mechdyn.kinematics.sweep import sweep
from mechdyn.modelfile.loader import build
from mechdyn.study.analyses import KinematicSummary, KinetostaticExtremes
from mechdyn.study.designs import design, parse_range
from mechdyn.study.execute import run_study
from mechdyn.study.parameters import BaseModel

RANGES = ("bodies.crank.points.A.x=40mm..60mm", "bodies.rod.points.B.x=140mm..200mm")
ANALYSIS = KinetostaticExtremes("1000 rpm", steps=120)


@pytest.fixture(scope="module")
def base():
    return BaseModel("slider_crank")


@pytest.fixture(scope="module")
def variants(base):
    return design([parse_range(base, r) for r in RANGES], 12, "lhs", seed=1)


@pytest.fixture(scope="module")
def study(base, variants):
    return run_study(base, variants, ANALYSIS, workers=1, batch_size=3, progress=False)


def reference_figures(base, values: dict, analysis) -> dict:
    """The figures of one cold mechdyn.kinetostatics call: the plain loop's (the variant
    read with every check of the loader, then compiled)."""
    model = build(base.document(values), base.name).compile()
    over, positions = analysis.values(model)
    record = kinetostatics(model, over=over, speed=analysis.speed, values=positions)
    return KinetostaticExtremes.figures(record).figures


def test_study_equals_the_plain_loop_over_kinetostatics(base, variants, study):
    assert (study["status"] == "success").all()
    assert study["variant"].tolist() == list(range(len(variants)))
    np.testing.assert_allclose(study["bodies.crank.points.A.x_m"],
                               variants["bodies.crank.points.A.x"], rtol=1e-15)
    params = variants.attrs["parameters"]
    reference = [reference_figures(base, dict(zip(params, row, strict=True)), ANALYSIS)
                 for row in variants.to_numpy()[:5]]
    for k, ref in enumerate(reference):
        for col, value in ref.items():
            assert study.loc[k, col] == pytest.approx(value, rel=1e-9, abs=1e-9), col


def test_non_assemblable_variants_are_rows_that_name_the_open_loop(base):
    rods = [0.16, 0.01, 0.045, 0.18]  # 10 mm: no sketch; 45 mm < 50 mm crank: no full turn
    df = run_study(base, {"bodies.rod.points.B.x": rods}, ANALYSIS, workers=1,
                   progress=False)
    assert df["status"].tolist()[0] == "success" and df["status"].tolist()[3] == "success"
    assert df.loc[1, "status"] == "assembly-failed"
    assert "loop through joints" in df.loc[1, "message"]
    assert "does not close" in df.loc[1, "message"]
    assert df.loc[2, "status"] in ("assembly-failed", "singular-position")
    assert np.isnan(df.loc[1, "M_drive_phi_peak_Nm"])


def test_a_variant_with_a_value_out_of_range_is_a_row_that_names_it(base):
    df = run_study(base, {"bodies.rod.mass": [1.0, -1.0]}, ANALYSIS, workers=1,
                   progress=False)
    assert df["status"].tolist() == ["success", "failed"]
    assert "[bodies.rod] mass: '-1.0 kg': mass must be >= 0 kg" in df.loc[1, "message"]
    assert np.isnan(df.loc[1, "M_drive_phi_peak_Nm"])


def test_kinematic_summary_gives_the_stroke_of_the_slider(base):
    df = run_study(base, {"bodies.crank.points.A.x": [0.04, 0.05]}, KinematicSummary(steps=73),
                   workers=1, progress=False)
    assert df["stroke_cylinder_m"].tolist() == pytest.approx([0.08, 0.10], rel=1e-6)
    model = base.build({base.parameter("bodies.crank.points.A.x"): 0.05}).compile()
    assert sweep(model, "phi", np.linspace(0, 2 * np.pi, 73, endpoint=False)).status == "success"


def test_local_processes_give_the_same_table(base, variants, study):
    cols = [c for c in study if c != "seconds"]
    df = run_study(base, variants, ANALYSIS, workers=2, batch_size=3, progress=False)
    assert df[cols].equals(study[cols])  # the same batches: the same warm starts
    other = run_study(base, variants, ANALYSIS, workers=2, batch_size=5, progress=False)
    figures = [c for c in cols if c.endswith(("_N", "_Nm", "_W"))]
    np.testing.assert_allclose(other[figures], study[figures], rtol=1e-9)


@pytest.mark.slow  # a LocalCluster of two processes takes 10-20 s to start on 2 cores
def test_the_same_study_on_a_dask_cluster_is_identical(base, variants, study):
    distributed = pytest.importorskip("distributed",
                                      reason="dask.distributed is not installed")
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        df = run_study(base, variants, ANALYSIS, client=client, batch_size=3, progress=False)
    cols = [c for c in study if c != "seconds"]
    assert df[cols].equals(study[cols])


def test_optimum_with_a_fixed_stroke_is_found_from_three_starts_and_on_a_grid(base):
    from mechdyn.study.analyses import Combined
    from mechdyn.study.optimise import Constraint, optimise

    steps = 72
    ranges = [parse_range(base, "bodies.crank.points.A.x=40mm..60mm"),
              parse_range(base, "bodies.rod.com.x=-60mm..60mm")]
    analysis = Combined((KinetostaticExtremes("1000 rpm", steps=steps),
                         KinematicSummary(steps=steps)))
    stroke = Constraint("stroke_cylinder_m", 0.1, 0.1)
    optima = [optimise(base, ranges, analysis, "M_drive_phi_peak_Nm", constraints=[stroke],
                       start=s, maxiter=200)
              for s in [(0.042, 0.05), (0.058, -0.05), (0.05, 0.0)]]
    for o in optima:
        assert o.values["bodies.crank.points.A.x"] == pytest.approx(0.05, abs=1e-6)
        assert o.values["bodies.rod.com.x"] == pytest.approx(
            optima[0].values["bodies.rod.com.x"], abs=1e-5)
        assert o.objective == pytest.approx(optima[0].objective, rel=1e-5)
        assert o.table["feasible"].any() and len(o.table) == o.evaluations
    # a fine grid at the fixed stroke (crank radius 50 mm), 1 mm steps of the rod's centre
    grid = np.arange(-0.060, 0.0605, 0.001)
    df = run_study(base, {"bodies.crank.points.A.x": np.full(grid.size, 0.05),
                          "bodies.rod.com.x": grid},
                   KinetostaticExtremes("1000 rpm", steps=steps), workers=1, progress=False)
    k = int(df["M_drive_phi_peak_Nm"].idxmin())
    assert abs(grid[k] - optima[0].values["bodies.rod.com.x"]) <= 0.001
    assert optima[0].objective <= df["M_drive_phi_peak_Nm"].min() + 1e-9
    assert optima[0].objective == pytest.approx(df["M_drive_phi_peak_Nm"].min(), rel=0.02)


@pytest.mark.slow  # a LocalCluster of two processes, one of them killed mid-study
def test_a_worker_killed_mid_study_loses_no_variant(base, variants, study, tmp_path):
    distributed = pytest.importorskip("distributed",
                                      reason="dask.distributed is not installed")
    marker = tmp_path / "killed"

    class KillsItsWorkerOnce:
        """The study's analysis; the first worker to reach variant 7 dies there."""

        name = "kinetostatics"

        def __call__(self, model, warm=None):
            import os

            if abs(model.mechanism.bodies["crank"].points["A"][0] - kill_at) < 1e-15 \
                    and not marker.exists():
                marker.touch()
                os._exit(1)
            return ANALYSIS(model, warm)

    kill_at = float(variants.iloc[7, 0])
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        df = run_study(base, variants, KillsItsWorkerOnce(), client=client, batch_size=3,
                       progress=False)
    assert marker.exists()
    # its analysis is not the batched one: each variant on its own, the same figures
    assert (df["evaluated"] == "loop").all() and (study["evaluated"] == "batch").all()
    cols = [c for c in study if c not in ("seconds", "evaluated")]
    pd.testing.assert_frame_equal(df[cols], study[cols], rtol=1e-9, check_exact=False)
