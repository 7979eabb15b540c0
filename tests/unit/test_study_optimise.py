"""Optimisation over study parameters: constraints, the global method, the table."""

import pytest

from mechdyn.errors import ModelError
from mechdyn.study.analyses import KinetostaticExtremes
from mechdyn.study.designs import parse_range
from mechdyn.study.optimise import Constraint, optimise, parse_constraint
from mechdyn.study.output import read_table
from mechdyn.study.parameters import BaseModel


def test_constraints_read_from_text():
    assert parse_constraint("stroke_cylinder_m=0.1") == Constraint("stroke_cylinder_m", 0.1, 0.1)
    assert parse_constraint("F_A_peak_N<=2000").high == 2000.0
    with pytest.raises(ModelError, match="COLUMN>=VALUE"):
        parse_constraint("stroke is 0.1")


def test_differential_evolution_records_every_evaluation(tmp_path):
    base = BaseModel("slider_crank")
    ranges = [parse_range(base, "bodies.crank.com.x=-40mm..20mm")]
    out = tmp_path / "opt.parquet"
    best = optimise(base, ranges, KinetostaticExtremes("1000 rpm", steps=24),
                    "M_drive_phi_rms_Nm", constraints=[Constraint("F_A_peak_N", high=5000.0)],
                    method="differential_evolution", seed=2, maxiter=2, popsize=4,
                    output=out)
    table = read_table(out)
    assert len(table) == best.evaluations == len(best.table)
    assert table["feasible"].all()
    assert best.objective == table["objective"].min()
    assert -0.04 <= best.values["bodies.crank.com.x"] <= 0.02


def test_an_unknown_constraint_column_names_the_figures():
    base = BaseModel("slider_crank")
    # checked before the first variant, with the figures the analysis gives
    with pytest.raises(ModelError, match=r"constraints\[0\]: unknown column 'stroke_cylinder_m'; "
                                         r"valid column names: .*'M_drive_phi_peak_Nm'"):
        optimise(base, [parse_range(base, "bodies.rod.mass=1kg..2kg")],
                 KinetostaticExtremes("1000 rpm", steps=12), "M_drive_phi_peak_Nm",
                 constraints=[Constraint("stroke_cylinder_m", 0.1, 0.1)], maxiter=3)
