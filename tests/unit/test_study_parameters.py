"""Study parameters by model-file path, ranges with units, designs."""

import numpy as np
import pytest

from mechdyn.errors import ModelError, UnitError
from mechdyn.study.designs import design, parse_range
from mechdyn.study.parameters import BaseModel


@pytest.fixture(scope="module")
def base():
    return BaseModel("slider_crank")


@pytest.mark.parametrize("path, kind, column", [
    ("bodies.crank.points.A.x", "length", "bodies.crank.points.A.x_m"),
    ("bodies.rod.mass", "mass", "bodies.rod.mass_kg"),
    ("bodies.rod.inertia", "inertia", "bodies.rod.inertia_kg_m2"),
    ("bodies.crank.pose.theta", "angle", "bodies.crank.pose.theta_deg"),
    ("initial.phi", "angle", "initial.phi_deg"),
    ("initial_speed.phi", "angular_velocity", "initial_speed.phi_rpm"),
])
def test_a_path_names_a_value_and_its_kind(base, path, kind, column):
    p = base.parameter(path)
    assert (p.kind, p.column) == (kind, column)


def test_a_variant_is_built_with_the_value_written_with_its_unit(base):
    p, q = base.parameter("bodies.crank.points.A.x"), base.parameter("initial.phi")
    doc = base.document({p: 0.045, q: 0.0})
    assert doc["bodies"]["crank"]["points"]["A"] == ["0.045 m", "0 mm"]
    mech = base.build({p: 0.045})
    assert mech.bodies["crank"].points["A"][0] == pytest.approx(0.045)
    assert base.doc["bodies"]["crank"]["points"]["A"][0] == "50 mm"  # the base is untouched


@pytest.mark.parametrize("path, listed", [
    ("bodies.crnk.mass", "'crank', 'piston', 'rod'"),
    ("bodies.crank.points.A.z", "x, y"),
    ("bodies.crank.points", "A"),
    ("drives.motr.coordinate", "'motor'"),
    ("bodies.crank.mas", "'com', 'inertia', 'mass'"),
])
def test_an_unknown_path_lists_the_valid_keys_at_that_level(base, path, listed):
    with pytest.raises(ModelError, match=listed):
        base.parameter(path)


def test_an_array_of_tables_is_indexed_by_name():
    base = BaseModel("slider_crank")
    base.doc["drives"][0]["gear_ratio"] = 3.0
    p = base.parameter("drives.motor.gear_ratio", "2.5")
    assert p.kind == "dimensionless" and p.column == "drives.motor.gear_ratio"
    assert base.document({p: 2.5})["drives"][0]["gear_ratio"] == 2.5  # a TOML number


def test_a_range_of_the_wrong_dimension_is_refused(base):
    with pytest.raises(ModelError):
        parse_range(base, "bodies.rod.mass=40mm..60mm")
    with pytest.raises(ModelError, match="KEY=LOW..HIGH"):
        parse_range(base, "bodies.rod.mass=1kg")
    with pytest.raises(UnitError):
        parse_range(base, "bodies.rod.mass=1kg..2mm")


def test_designs_are_seeded_and_fill_the_ranges(base):
    r = [parse_range(base, "bodies.crank.points.A.x=40mm..60mm"),
         parse_range(base, "bodies.rod.mass=1kg..2kg")]
    g = design(r, 9, "grid")
    assert len(g) == 9 and sorted(set(g["bodies.rod.mass"])) == [1.0, 1.5, 2.0]
    a, b = design(r, 20, "lhs", seed=3), design(r, 20, "lhs", seed=3)
    assert a.equals(b) and not a.equals(design(r, 20, "lhs", seed=4))
    # a Latin hypercube: one sample in each of the 20 strata of every parameter
    strata = np.floor((a["bodies.rod.mass"] - 1.0) * 20).astype(int)
    assert sorted(strata) == list(range(20))
    u = design(r, 50, "random", seed=1)["bodies.crank.points.A.x"]
    assert u.between(0.04, 0.06).all()
    with pytest.raises(ModelError, match="unknown design"):
        design(r, 5, "sobol")


def test_a_variant_copies_only_the_tables_on_its_paths(base):
    p = base.parameter("bodies.crank.points.A.x")
    doc = base.document({p: 0.045})
    assert doc["bodies"]["rod"] is base.doc["bodies"]["rod"]  # shared, never changed
    new, old = doc["bodies"]["crank"]["points"]["A"], base.doc["bodies"]["crank"]["points"]["A"]
    assert new is not old and new[1] == old[1] and old[0] == "50 mm"
    assert doc["drives"] is base.doc["drives"]


def test_a_variant_is_compiled_once_without_the_schema_pass(monkeypatch):
    import mechdyn.compiler
    from mechdyn.modelfile import loader

    base = BaseModel("slider_crank")
    p = base.parameter("bodies.rod.mass")
    assert base.structure_known([p])
    calls = []
    real = mechdyn.compiler.compile_mechanism
    monkeypatch.setattr(mechdyn.compiler, "compile_mechanism",
                        lambda m: calls.append(m) or real(m))
    monkeypatch.setattr(loader, "schema_problems", None)  # would fail if called
    model = base.compile({p: 2.5})
    assert len(calls) == 1 and model.mechanism.bodies["rod"].mass == 2.5


def test_a_bad_value_is_still_named_without_the_schema_pass(base):
    p = base.parameter("bodies.rod.mass")
    assert base.structure_known([p])
    with pytest.raises(ModelError, match=r"\[bodies\.rod\] mass: '-1\.0 kg': mass must be >= 0"):
        base.compile({p: -1.0})


def test_a_base_document_of_a_bad_structure_is_checked_for_every_variant():
    base = BaseModel("slider_crank")
    base.doc["bodies"]["rod"]["colour"] = "red"
    p = base.parameter("bodies.rod.mass")
    assert not base.structure_known([p])
    with pytest.raises(ModelError, match=r"\[bodies\.rod\]: unknown key 'colour'"):
        base.compile({p: 1.0})
