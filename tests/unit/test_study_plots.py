"""Study plots: labelled scatter, Pareto front."""

import numpy as np
import pandas as pd
import pytest

from mechdyn.errors import ModelError
from mechdyn.study.plots import pareto_front, plot_pareto, plot_scatter

TABLE = pd.DataFrame({
    "bodies.crank.points.A.x_m": [0.04, 0.045, 0.05, 0.055, 0.06],
    "M_drive_phi_peak_Nm": [15.0, 18.0, 20.0, 24.0, np.nan],
    "F_frame_peak_N": [900.0, 800.0, 850.0, 600.0, np.nan],
    "status": ["success"] * 4 + ["assembly-failed"],
})


def test_the_front_holds_the_rows_no_other_beats():
    assert pareto_front(TABLE, ["M_drive_phi_peak_Nm", "F_frame_peak_N"]).tolist() == \
        [True, True, False, True, False]


def test_plots_are_written_with_engineering_units(tmp_path):
    fig = plot_scatter(TABLE, "bodies.crank.points.A.x_m", "M_drive_phi_peak_Nm",
                       color="F_frame_peak_N")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "bodies.crank.points.A.x [mm]"
    assert ax.get_ylabel() == "M_drive_phi_peak [N m]"
    assert ax.get_legend().get_texts()[0].get_text() == "1 failed variants"
    out = plot_pareto(TABLE, "M_drive_phi_peak_Nm", "F_frame_peak_N", tmp_path / "p.png")
    assert out.stat().st_size > 1000


def test_an_unknown_column_is_named():
    with pytest.raises(ModelError, match="F_frame_peak_N"):
        plot_scatter(TABLE, "bodies.crank.points.A.x_m", "F_frame_peak")


def test_the_report_section_lists_ranges_best_and_failed_variants():
    from mechdyn.study.report import study_section

    table = TABLE.assign(variant=range(5), message=[""] * 4 + ["the loop does not close"])
    text = study_section(table, ["bodies.crank.points.A.x_m"],
                         pareto=("M_drive_phi_peak_Nm", "F_frame_peak_N"))
    assert "Design study: 5 variants" in text and "4 success, 1 assembly-failed" in text
    assert "bodies.crank.points.A.x [mm]" in text and "Smallest M_drive_phi_peak [N m]" in text
    assert text.count("<img") == 2 and "the loop does not close" in text
