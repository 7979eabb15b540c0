"""Quantities with units -> SI floats: conversions, bare numbers, and clear errors."""

import math

import pytest

from mechdyn.errors import ModelError, UnitError
from mechdyn.units import KINDS, format_quantity, parse_quantity, parse_vector, registry


@pytest.mark.parametrize(
    ("text", "kind", "si"),
    [
        ("15 mm", "length", 0.015),
        ("-64.1 deg", "angle", math.radians(-64.1)),
        ("0.034 kg*m^2", "inertia", 0.034),
        ("0.034 kg m^2", "inertia", 0.034),
        ("43.5 rad/s", "angular_velocity", 43.5),
        ("100 rpm", "angular_velocity", 100 * 2 * math.pi / 60),
        ("1.5 kW", "power", 1500.0),
        ("4.6 kg", "mass", 4.6),
        ("1.2 kN", "force", 1200.0),
        ("0.033 N*m", "torque", 0.033),
        ("4.53 N/mm", "stiffness", 4530.0),
        ("20 N*s/m", "damping", 20.0),
        ("12 N*m/rad", "rotational_stiffness", 12.0),
        ("12 N*m", "rotational_stiffness", 12.0),
        ("1 N*m/deg", "rotational_stiffness", 180 / math.pi),
        ("20 ms", "time", 0.02),
        ("-9.81 m/s^2", "acceleration", -9.81),
        ("0.5 m/s", "velocity", 0.5),
        ("30 %", "ratio", 0.3),
        ("30 percent", "dimensionless", 0.3),
        ("50 Hz", "frequency", 50.0),
        ("3000 rpm", "frequency", 50.0),
        ("1 turn", "angle", 2 * math.pi),
        ("1 rev", "angle", 2 * math.pi),
        ("10 rad/s^2", "angular_acceleration", 10.0),
    ],
)
def test_quantity_is_converted_to_si(text, kind, si):
    assert parse_quantity(text, kind, where="t") == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize(("value", "kind"), [(0.015, "length"), (3, "mass"), ("0.015", "length"),
                                             (1.2, "angle"), (43.5, "angular_velocity"),
                                             ("-0.5", "angle")])
def test_bare_numbers_are_si_even_for_angles(value, kind):
    assert parse_quantity(value, kind, where="t") == float(value)


def test_wrong_dimension_names_where_value_expected_dimension_and_example():
    with pytest.raises(UnitError, match=r"f\.toml: \[bodies\.rod\] com: '15 kg': the unit kg is "
                                        r"a mass unit; expected a length \(m\), e\.g\. \"15 mm\""):
        parse_quantity("15 kg", "length", where="f.toml: [bodies.rod] com")


def test_unit_error_is_a_model_error():
    with pytest.raises(ModelError):
        parse_quantity("15 kg", "length", where="x")


@pytest.mark.parametrize(("text", "why"), [("15 mmm", "unknown unit"),
                                           ("abc", "unknown unit"),
                                           ("2*", "cannot be read"),
                                           ("1,2 mm", "one quantity expected"),
                                           ("", "empty text"),
                                           ("nan m", "not a finite value")])
def test_unparsable_text_is_reported(text, why):
    with pytest.raises(UnitError, match=f"here: .*{why}.*expected a length"):
        parse_quantity(text, "length", where="here")


def test_hertz_is_not_taken_for_an_angular_velocity():
    with pytest.raises(UnitError, match="no angle unit"):
        parse_quantity("10 Hz", "angular_velocity", where="w")


def test_angle_unit_is_refused_for_a_ratio():
    with pytest.raises(UnitError, match="carries an angle unit"):
        parse_quantity("15 deg", "ratio", where="w")


@pytest.mark.parametrize("value", [True, None, [1, 2], {"a": 1}, float("inf")])
def test_non_numbers_are_refused(value):
    with pytest.raises(UnitError, match="expected a mass"):
        parse_quantity(value, "mass", where="w")


def test_unknown_kind_lists_the_kinds():
    with pytest.raises(ValueError, match="valid kinds: .*length"):
        parse_quantity("1 m", "lenght", where="w")


def test_vectors_as_lists_and_as_one_string():
    assert parse_vector(["10 mm", "0 mm"], "length", "w") == (0.01, 0.0)
    assert parse_vector("(10, 0) mm", "length", "w") == (0.01, 0.0)
    assert parse_vector([0.01, 0], "length", "w") == (0.01, 0.0)
    pose = parse_vector("(10 mm, 0 mm, 30 deg)", ("length", "length", "angle"), "w")
    assert pose == pytest.approx((0.01, 0.0, math.pi / 6))


@pytest.mark.parametrize(("value", "why"), [(["10 mm"], "expected 2 components, got 1"),
                                            ("(1, 2, 3) mm", "expected 2 components, got 3"),
                                            ("10 mm", "cannot be read as a vector"),
                                            (5, "expected a list of 2 components")])
def test_bad_vectors_are_reported(value, why):
    with pytest.raises(UnitError, match=why):
        parse_vector(value, "length", "f.toml: [ground.points] O")


def test_vector_component_error_names_the_component():
    with pytest.raises(UnitError, match=r"O\[1\]: '0 kg'"):
        parse_vector(["10 mm", "0 kg"], "length", "O")


def test_format_quantity():
    assert format_quantity(0.015, "length", "mm") == "15 mm"
    assert format_quantity(math.pi, "angle", "deg") == "180 deg"
    assert format_quantity(50.0, "frequency", "rpm") == "3000 rpm"
    assert format_quantity(3.0, "force") == "3 N"
    with pytest.raises(UnitError, match="cannot show"):
        format_quantity(1.0, "length", "kg")


def test_one_shared_registry():
    assert registry() is registry()


def test_every_kind_example_parses_to_its_own_kind():
    for name, kind in KINDS.items():
        example = kind.example.split(" or ")[0].strip('"')
        parse_quantity(example, name, where=name)


def test_pint_quantities_convert_as_their_unit_text():
    pint = pytest.importorskip("pint")
    for reg in (registry(), pint.UnitRegistry()):  # ours or the caller's registry
        assert parse_quantity(reg.Quantity(60, "rpm"), "angular_velocity") == pytest.approx(
            2 * math.pi, rel=1e-14)
        assert parse_quantity(reg.Quantity(0.5, "mm/s"), "velocity") == pytest.approx(5e-4)
        assert parse_quantity(reg.Quantity(30, "deg"), "angle") == pytest.approx(
            math.pi / 6, rel=1e-14)
    other = pint.UnitRegistry()
    with pytest.raises(UnitError, match="speed: 10 hertz: .*no angle unit"):
        parse_quantity(other.Quantity(10, "Hz"), "angular_velocity", where="speed")
    with pytest.raises(UnitError, match="velocity unit; expected an angular velocity"):
        parse_quantity(other.Quantity(1, "m/s"), "angular_velocity")
    with pytest.raises(UnitError, match="one quantity expected"):
        parse_quantity(other.Quantity([1.0, 2.0], "m/s"), "velocity")
