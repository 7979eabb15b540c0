"""The study table: written as batches come, kept when interrupted, resumed."""

import pandas as pd
import pytest

from mechdyn.errors import ModelError
from mechdyn.study.analyses import Outcome
from mechdyn.study.execute import run_study
from mechdyn.study.output import StudyOutput, read_table

MASSES = {"bodies.rod.mass": [1.0, 1.2, 1.4, 1.6, 1.8, 2.0, 2.2]}


class Counting:
    """A cheap analysis that counts its calls and can stop the study at one of them."""

    name = "counting"

    def __init__(self, stop_at=None):
        self.calls, self.stop_at = 0, stop_at

    def __call__(self, model, warm=None):
        self.calls += 1
        if self.calls == self.stop_at:
            raise KeyboardInterrupt
        mass = sum(b.mass for b in model.mechanism.bodies.values())
        return Outcome({"mass_total_kg": mass})


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_an_interrupted_study_keeps_its_batches_and_resumes(tmp_path, suffix):
    out = tmp_path / f"s{suffix}"
    with pytest.raises(KeyboardInterrupt):
        run_study("slider_crank", MASSES, Counting(stop_at=6), output=out, workers=1,
                  batch_size=2, progress=False, order=False)
    kept = read_table(out)
    assert kept["variant"].tolist() == [0, 1, 2, 3]  # two whole batches
    assert not out.with_name(out.name + ".parts").exists()
    again = Counting()
    df = run_study("slider_crank", MASSES, again, output=out, workers=1, batch_size=2,
                   resume=True, progress=False)
    assert again.calls == 3
    assert df["variant"].tolist() == list(range(7))
    assert df["mass_total_kg"].tolist() == pytest.approx([2.8 + m for m in MASSES[
        "bodies.rod.mass"]])
    assert read_table(out)["message"].tolist() == [""] * 7


def test_resuming_another_design_is_refused(tmp_path):
    out = tmp_path / "s.csv"
    run_study("slider_crank", MASSES, Counting(), output=out, workers=1, progress=False)
    with pytest.raises(ModelError, match="another study"):
        run_study("slider_crank", {"bodies.rod.mass": [3.0, 4.0]}, Counting(), output=out,
                  workers=1, resume=True, progress=False)


def test_parts_left_by_a_killed_study_are_read_back(tmp_path):
    out = StudyOutput(tmp_path / "s.parquet")
    out.append([{"variant": 0, "x": 1.0, "status": "success", "message": ""}])
    out.append([{"variant": 1, "status": "assembly-failed", "message": "open"}])
    assert StudyOutput(tmp_path / "s.parquet").done() == {0, 1}
    df = out.finish()
    assert list(df.columns) == ["variant", "x", "status", "message"]
    assert pd.isna(df.loc[1, "x"])


def test_an_unknown_table_type_is_refused(tmp_path):
    with pytest.raises(ModelError, match="unknown table type"):
        StudyOutput(tmp_path / "s.xlsx")
