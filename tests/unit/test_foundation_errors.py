"""Bad supports and bad inputs of the foundation analyses: errors that name the support,
the field and what is wrong."""

import numpy as np
import pandas as pd
import pytest

from mechdyn.errors import ModelError
from mechdyn.foundation import (
    AnchorBolt,
    Foundation,
    Isolator,
    distribute,
    excitation_warnings,
    frame_loads,
    mounted_response,
    natural_frequencies,
    transmissibility,
)


def _bolt(name="b1", x=-0.4, **kw):
    args = {"k_axial": 2e8, "k_shear": 1e8, "preload": 1e4} | kw
    return AnchorBolt(name, x, 0.0, **args)


@pytest.mark.parametrize("field, value", [("k_axial", 0.0), ("k_shear", -1e8),
                                          ("k_axial", float("nan"))])
def test_bolt_stiffness_must_be_positive(field, value):
    with pytest.raises(ModelError, match=rf"anchor bolt 'b1': {field} must be a finite "
                                         r"positive number"):
        _bolt(**{field: value})


def test_negative_preload_and_load_factor_are_named_together():
    with pytest.raises(ModelError) as err:
        _bolt(preload=-5.0, load_factor=1.5)
    assert len(err.value.problems) == 2
    assert "anchor bolt 'b1': preload must be a finite force >= 0 N, got -5.0" in str(err.value)
    assert "load_factor must be in [0, 1]" in str(err.value)


@pytest.mark.parametrize("field", ["kx", "ky"])
def test_isolator_stiffness_must_be_positive(field):
    args = {"kx": 1e5, "ky": 1e5} | {field: 0}
    with pytest.raises(ModelError, match=rf"isolator 'm1': {field} must be"):
        Isolator("m1", 0.0, 0.0, **args)


def test_isolator_damping_must_not_be_negative():
    with pytest.raises(ModelError, match=r"isolator 'm1': cy must be a finite damping >= 0"):
        Isolator("m1", 0.0, 0.0, 1e5, 1e5, cy=-1.0)


def test_duplicate_support_names():
    with pytest.raises(ModelError, match=r"support name 'b1' is used twice"):
        Foundation([_bolt("b1"), _bolt("b1", x=0.4)])


def test_one_support_leaves_the_rotation_about_it_free():
    with pytest.raises(ModelError, match=r"nothing resists a rotation about \(-0\.4, 0\) m"):
        Foundation([_bolt()])


def test_supports_at_one_point_leave_the_rotation_free():
    iso = Isolator("m1", -0.4, 0.0, 1e5, 1e5)
    with pytest.raises(ModelError, match=r"b1, m1 cannot hold the base.*rotation about"):
        Foundation([_bolt(), iso])


def test_no_supports_and_wrong_types():
    with pytest.raises(ModelError, match="no supports"):
        Foundation([])
    with pytest.raises(ModelError, match="must be AnchorBolt or Isolator, got dict"):
        Foundation([{"name": "b1"}])


def test_mass_and_inertia_must_be_positive_and_are_needed_for_the_elastic_analysis():
    with pytest.raises(ModelError, match="foundation: mass must be a finite positive"):
        Foundation([_bolt(), _bolt("b2", 0.4)], mass=-1.0, inertia=1.0)
    f = Foundation([_bolt(), _bolt("b2", 0.4)], mass=500.0)
    with pytest.raises(ModelError, match="needs the inertia of the frame and base"):
        natural_frequencies(f)
    with pytest.raises(ModelError, match="needs the mass and inertia"):
        transmissibility(Foundation([_bolt(), _bolt("b2", 0.4)]), 10.0)


def test_bad_direction_and_frequency():
    f = Foundation([_bolt(), _bolt("b2", 0.4)], mass=500.0, inertia=80.0)
    with pytest.raises(ModelError, match="unknown direction 'z'"):
        transmissibility(f, 10.0, "z")
    with pytest.raises(ModelError, match=r"a load vector is \(Fx, Fy, M\)"):
        transmissibility(f, 10.0, (0.0, 0.0, 0.0))
    with pytest.raises(ModelError, match="omega must be finite and >= 0"):
        transmissibility(f, [-1.0, 2.0])
    with pytest.raises(ModelError, match="rpm must be finite"):
        excitation_warnings(f, float("nan"))


def test_load_histories_must_match():
    f = Foundation([_bolt(), _bolt("b2", 0.4)], mass=500.0, inertia=80.0)
    with pytest.raises(ModelError, match="same length"):
        distribute(f, [1.0, 2.0], [1.0], [0.0, 0.0])
    with pytest.raises(ModelError, match="weight of the base needs the foundation's mass"):
        distribute(Foundation([_bolt(), _bolt("b2", 0.4)]), [0.0], [0.0], [0.0],
                   gravity=(0.0, -9.81))
    with pytest.raises(ModelError, match="non-finite"):
        distribute(f, [np.nan], [1.0], [0.0])
    with pytest.raises(ModelError, match="times must not decrease"):
        mounted_response(f, [0.0, -1.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(ModelError, match="start must be 'static' or 'rest'"):
        mounted_response(f, [0.0], [0.0], [0.0], [0.0], start="moving")


def test_a_table_without_frame_loads_is_refused():
    with pytest.raises(ModelError, match="missing column.*M_frame_Nm"):
        frame_loads(pd.DataFrame({"t_s": [0.0], "Fx_frame_N": [0.0], "Fy_frame_N": [0.0]}))
