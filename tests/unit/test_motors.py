"""Motor characteristics, gear stages, the motor catalogue and the drive tables.

Oracles: the catalogue points themselves (rated torque at rated slip, breakdown torque
at critical slip, starting torque at standstill), the maximum of the curve found by
a dense scan, Kloss's closed-form critical slip s_k = s_n (lambda + sqrt(lambda^2 - 1)),
and power balance through a gear stage.
"""

import math
import warnings

import numpy as np
import pytest

from mechdyn.errors import ModelError, UnitError
from mechdyn.mechanism import Drive, Mechanism
from mechdyn.mechanism.catalogue import MOTORS, catalogue_entry, induction_motor, list_motors
from mechdyn.mechanism.motors import (
    ConstantSpeedDrive,
    DCMotor,
    GearStage,
    InductionMotor,
    TabulatedMotor,
    extra_inertia_by_coordinate,
    fit_extended_kloss,
    kloss_critical_slip,
)
from mechdyn.modelfile.drives import drive_from_table

W0 = 1500 * math.pi / 30  # synchronous speed of a 4-pole motor at 50 Hz, rad/s
DATA = dict(rated_power=1500.0, synchronous_speed=W0, rated_slip=0.058, breakdown_ratio=2.2,
            starting_ratio=2.0, rotor_inertia=0.0033)


@pytest.fixture(params=["kloss", "extended"])
def motor(request):
    return InductionMotor("4A80B4U3", characteristic=request.param, **DATA)


def test_rated_torque_at_rated_slip(motor):
    mn = 1500.0 / (W0 * (1 - 0.058))
    assert motor.rated_torque == pytest.approx(mn, rel=1e-15)
    assert motor.torque_at(motor.rated_speed) == pytest.approx(mn, rel=1e-12)
    assert motor.torque_at_slip(0.058) == pytest.approx(mn, rel=1e-12)


def test_breakdown_torque_at_critical_slip_is_the_maximum(motor):
    mk = 2.2 * motor.rated_torque
    assert motor.torque_at_slip(motor.critical_slip) == pytest.approx(mk, rel=1e-12)
    s = np.linspace(1e-4, 1.0, 200001)
    m = motor.torque_at_slip(s)
    assert m.max() <= mk * (1 + 1e-12)
    assert s[np.argmax(m)] == pytest.approx(motor.critical_slip, abs=1e-4)
    assert motor.torque_at(W0) == 0.0  # no torque at synchronous speed
    assert motor.torque_at(W0 * 1.01) < 0  # generator above it


def test_kloss_critical_slip_closed_form():
    m = InductionMotor("k", **DATA)
    assert m.critical_slip == pytest.approx(0.058 * (2.2 + math.sqrt(2.2**2 - 1)), rel=1e-15)
    assert kloss_critical_slip(0.058, 2.2) == m.critical_slip
    assert m.a == 0.0
    # Kloss's formula misses the catalogue starting torque (2.0 M_n): about 1.0 M_n
    assert m.starting_torque / m.rated_torque == pytest.approx(1.0031, abs=1e-4)


def test_extended_kloss_also_meets_the_starting_torque():
    m = InductionMotor("e", characteristic="extended", **DATA)
    assert m.starting_torque == pytest.approx(2.0 * m.rated_torque, rel=1e-10)
    assert m.a > 0  # stator resistance term of the right sign
    sk, a = fit_extended_kloss(0.058, 2.2, 2.0)
    assert (sk, a) == (m.critical_slip, m.a)
    assert 0.058 < sk < 1


@pytest.mark.parametrize("sn, lam, start", [(0.03, 3.0, 2.2), (0.051, 2.4, 2.1),
                                             (0.08, 2.0, 1.9)])
def test_extended_kloss_fits_other_catalogue_triples(sn, lam, start):
    m = InductionMotor("x", 1000.0, W0, rated_slip=sn, breakdown_ratio=lam, starting_ratio=start,
                       characteristic="extended")
    mn = m.rated_torque
    assert m.torque_at_slip(sn) == pytest.approx(mn, rel=1e-10)
    assert m.torque_at_slip(m.critical_slip) == pytest.approx(lam * mn, rel=1e-10)
    assert m.torque_at_slip(1.0) == pytest.approx(start * mn, rel=1e-10)


def test_extended_kloss_below_kloss_starting_torque_has_negative_a():
    # a catalogue starting torque below Kloss's own is met with a < 0 (1 + a s_k > 0 still)
    m = InductionMotor("low", characteristic="extended", **dict(DATA, starting_ratio=0.5))
    assert m.a < 0 < 1 + m.a * m.critical_slip
    assert m.starting_torque == pytest.approx(0.5 * m.rated_torque, rel=1e-10)


def test_extended_kloss_that_cannot_fit_says_so():
    # a soft motor (s_n = 0.3, lambda = 3) whose starting torque is far below Kloss's:
    # the curve would need 1 + a s_k <= 0, i.e. a pole inside the motoring range
    with pytest.raises(ModelError, match="no extended Kloss curve.*characteristic = 'kloss'"):
        fit_extended_kloss(0.3, 3.0, 1.0)
    with pytest.raises(ModelError, match="induction motor 'bad'.*no extended Kloss"):
        InductionMotor("bad", 1000.0, W0, rated_slip=0.3, breakdown_ratio=3.0,
                       starting_ratio=1.0, characteristic="extended")


def test_rated_speed_or_slip():
    by_speed = InductionMotor("s", 1500.0, W0, rated_speed=1415 * math.pi / 30,
                              breakdown_ratio=2.2)
    assert by_speed.rated_slip == pytest.approx(85 / 1500)
    assert by_speed.torque_at(1415 * math.pi / 30) == pytest.approx(by_speed.rated_torque)
    with pytest.raises(ModelError, match="exactly one of rated_slip and rated_speed"):
        InductionMotor("s", 1500.0, W0, rated_speed=140.0, rated_slip=0.05, breakdown_ratio=2)


@pytest.mark.parametrize("change, field", [
    ({"breakdown_ratio": 0.9}, "breakdown_ratio.*breakdown torque cannot be below the rated"),
    ({"rated_slip": 1.2}, r"rated_slip must lie in \(0, 1\)"),
    ({"rated_slip": 0.0}, r"rated_slip must lie in \(0, 1\)"),
    ({"rated_power": -5.0}, "rated_power must be > 0"),
    ({"synchronous_speed": 0.0}, "synchronous_speed must be > 0"),
    ({"starting_ratio": 2.5}, "starting_ratio 2.5 must be below breakdown_ratio"),
    ({"rotor_inertia": -1.0}, "rotor_inertia must be >= 0"),
    ({"characteristic": "linear"}, "characteristic must be one of"),
])
def test_bad_motor_data_names_the_field(change, field):
    with pytest.raises(ModelError, match=field):
        InductionMotor("m", **dict(DATA, **change))


def test_rated_speed_above_synchronous_is_refused():
    with pytest.raises(ModelError, match="rated_speed .* must be below the synchronous_speed"):
        InductionMotor("m", 1500.0, W0, rated_speed=W0 * 1.01, breakdown_ratio=2.2)


def test_all_problems_are_reported_at_once():
    with pytest.raises(ModelError) as err:
        InductionMotor("m", -1.0, W0, rated_slip=2.0, breakdown_ratio=0.5)
    assert len(err.value.problems) == 3


def test_extended_needs_a_starting_ratio():
    with pytest.raises(ModelError, match="extended' needs starting_ratio"):
        InductionMotor("m", 1500.0, W0, rated_slip=0.05, breakdown_ratio=2.2,
                       characteristic="extended")


def test_array_and_scalar_evaluation_agree(motor):
    w = np.linspace(0.0, W0, 11)
    m = motor.torque_at(w)
    assert isinstance(m, np.ndarray) and m.shape == (11,)
    for wi, mi in zip(w, m, strict=True):
        assert motor.torque_at(float(wi)) == pytest.approx(mi, rel=1e-14)


# ------------------------------------------------------------------ other drives
def test_dc_motor_linear_characteristic():
    m = DCMotor("dc", no_load_speed=300.0, stall_torque=12.0, rotor_inertia=1e-3)
    assert m.torque_at(0.0) == 12.0 and m.torque_at(300.0) == 0.0
    assert m.torque_at(150.0) == pytest.approx(6.0)
    r = DCMotor.from_rated("dc", rated_power=900.0, rated_speed=200.0, no_load_speed=300.0)
    assert r.torque_at(200.0) == pytest.approx(900.0 / 200.0)
    with pytest.raises(ModelError, match="stall_torque must be > 0"):
        DCMotor("dc", 300.0, -1.0)
    with pytest.raises(ModelError, match="rated_speed .* must be below no_load_speed"):
        DCMotor.from_rated("dc", 900.0, 400.0, 300.0)


def test_constant_speed_drive_needs_stiffness_for_dynamics():
    ideal = ConstantSpeedDrive("ideal", 43.5)
    with pytest.raises(ModelError, match="kinetostatics"):
        ideal.torque_at(40.0)
    stiff = ConstantSpeedDrive("gov", 43.5, stiffness=100.0)
    assert stiff.torque_at(43.0) == pytest.approx(50.0)
    assert stiff.extra_inertia() == 0.0


def test_tabulated_motor_interpolates_and_extrapolates():
    m = TabulatedMotor("t", (0.0, 100.0, 150.0), (20.0, 15.0, 0.0), rotor_inertia=0.01)
    assert m.torque_at(50.0) == pytest.approx(17.5)
    assert m.torque_at(160.0) == pytest.approx(-3.0)
    held = TabulatedMotor("t", (0.0, 100.0), (20.0, 10.0), extrapolate=False)
    assert held.torque_at(200.0) == 10.0
    with pytest.raises(ModelError, match="omega must increase strictly"):
        TabulatedMotor("t", (0.0, 0.0), (1.0, 2.0))


def test_gear_stage_torque_speed_and_inertia():
    motor = InductionMotor("m", **DATA)
    g = GearStage(motor, ratio=3.4, efficiency=0.95, input_inertia=1e-3, output_inertia=0.02)
    w = 43.5
    assert g.motor_speed(w) == pytest.approx(3.4 * w)
    assert g.torque_at(w) == pytest.approx(0.95 * 3.4 * motor.torque_at(3.4 * w), rel=1e-14)
    # power balance: output power = eta * motor power while the motor drives
    assert g.torque_at(w) * w == pytest.approx(0.95 * motor.torque_at(3.4 * w) * 3.4 * w)
    # above synchronous speed the machine drives the motor: losses still oppose the flow
    w_gen = 1.02 * W0 / 3.4
    assert g.torque_at(w_gen) == pytest.approx(3.4 * motor.torque_at(3.4 * w_gen) / 0.95)
    assert g.extra_inertia() == pytest.approx((0.0033 + 1e-3) * 3.4**2 + 0.02)
    arr = g.torque_at(np.array([w, w_gen]))
    assert arr[0] == pytest.approx(g.torque_at(w)) and arr[1] == pytest.approx(g.torque_at(w_gen))


@pytest.mark.parametrize("change, field", [({"ratio": 0.0}, "ratio"),
                                           ({"efficiency": 1.2}, r"efficiency must lie in"),
                                           ({"input_inertia": -1.0}, "input_inertia")])
def test_bad_gear_data_names_the_field(change, field):
    kw = dict(motor=InductionMotor("m", **DATA), ratio=3.4, efficiency=0.9)
    kw.update(change)
    with pytest.raises(ModelError, match=field):
        GearStage(**kw)


def test_source_paper_gear_ratio_matches_crank_speed():
    m = induction_motor("4A80B4U3")
    # the paper's initial crank speed 43.5 rad/s is the rated motor speed through ~3.4 : 1
    assert m.rated_speed / 43.5 == pytest.approx(3.4, abs=0.01)


# ------------------------------------------------------------------ catalogue
def test_catalogue_entry_of_the_source_paper_motor():
    e = catalogue_entry("4A80B4U3")
    assert (e.rated_power, e.synchronous_rpm, e.rated_slip) == (1500.0, 1500.0, 0.058)
    assert (e.breakdown_ratio, e.starting_ratio, e.quoted_rated_rpm) == (2.2, 2.0, 1415.0)
    assert e.confidence("rotor_inertia") == "unconfirmed"
    assert e.confidence("rated_slip") == "stated"
    assert catalogue_entry("4А80В4У3") is e  # Cyrillic letters accepted
    for entry in MOTORS.values():  # every value names its source and confidence
        for fld in ("rated_power", "rated_slip", "breakdown_ratio", "starting_ratio",
                    "rotor_inertia"):
            src, conf = entry.sources[fld]
            assert src and conf in ("stated", "medium", "unconfirmed", "unknown")


def test_unknown_catalogue_motor_lists_the_known_ones():
    with pytest.raises(ModelError, match="unknown catalogue motor '4A71A4U3'.*4A80B4U3"):
        catalogue_entry("4A71A4U3")
    assert "4A80B4U3" in list_motors()


def test_catalogue_motor_without_rotor_inertia_warns():
    with pytest.warns(UserWarning, match="rotor inertia is not in the catalogue"):
        m = induction_motor("4A90L4U3")
    assert m.rotor_inertia == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = induction_motor("4A90L4U3", rotor_inertia=0.0056)
    assert m.rotor_inertia == 0.0056


# ------------------------------------------------------------------ model-file tables
def test_drive_table_with_catalogue_motor_and_gear():
    d = drive_from_table({"type": "induction_motor", "name": "motor", "coordinate": "phi",
                          "catalogue": "4A80B4U3", "characteristic": "extended",
                          "gear_ratio": 3.4, "efficiency": "95 %"}, "press.toml: drives[0]")
    assert isinstance(d, Drive) and d.coordinate == "phi" and d.name == "motor"
    assert isinstance(d.torque, GearStage)
    assert d.torque.efficiency == pytest.approx(0.95)
    assert d.torque.motor.characteristic == "extended"
    assert d.torque.extra_inertia() == pytest.approx(0.0033 * 3.4**2)


def test_drive_table_with_explicit_data_and_units():
    d = drive_from_table({"type": "induction_motor", "coordinate": "phi",
                          "rated_power": "1.5 kW", "synchronous_speed": "1500 rpm",
                          "rated_speed": "1415 rpm", "breakdown_ratio": 2.2,
                          "rotor_inertia": "0.0033 kg*m^2"}, "t")
    m = d.torque
    assert m.rated_speed == pytest.approx(1415 * math.pi / 30)
    assert m.rated_power == 1500.0


def test_drive_table_catalogue_with_override():
    d = drive_from_table({"type": "induction_motor", "coordinate": "phi",
                          "catalogue": "4A80B4U3", "rated_speed": "1415 rpm"}, "t")
    assert d.torque.rated_slip == pytest.approx(85 / 1500)


@pytest.mark.parametrize("table, msg", [
    ({"type": "diesel", "coordinate": "phi"}, "unknown drive type 'diesel'.*induction_motor"),
    ({"type": "induction_motor", "catalogue": "4A80B4U3"}, "coordinate: missing"),
    ({"type": "induction_motor", "coordinate": "phi", "catalogue": "4A80B4U3", "gear": 3},
     "unknown key of a 'induction_motor' drive 'gear'.*gear_ratio"),
    ({"type": "induction_motor", "coordinate": "phi", "rated_power": "1.5 kW"},
     "missing synchronous_speed, breakdown_ratio, rated_speed"),
    ({"type": "induction_motor", "coordinate": "phi", "catalogue": "4A80B4U3",
      "efficiency": 0.9}, "gear_ratio: missing"),
    ({"type": "induction_motor", "coordinate": "phi", "catalogue": "4A80B4U3",
      "breakdown_ratio": 0.8}, "t: induction motor '4A80B4U3': breakdown_ratio"),
    ({"type": "dc_motor", "coordinate": "phi", "stall_torque": "5 N*m"}, "no_load_speed"),
    ({"type": "constant_speed", "coordinate": "phi"}, "speed: missing"),
])
def test_bad_drive_tables_name_the_key(table, msg):
    with pytest.raises(ModelError, match=msg):
        drive_from_table(table, "t")


def test_drive_table_unit_errors_name_the_key():
    with pytest.raises(UnitError, match="t: synchronous_speed"):
        drive_from_table({"type": "induction_motor", "coordinate": "phi",
                          "rated_power": "1.5 kW", "synchronous_speed": "1500 mm",
                          "rated_slip": 0.05, "breakdown_ratio": 2.2}, "t")


def test_other_drive_types_from_tables():
    dc = drive_from_table({"type": "dc_motor", "coordinate": "phi", "no_load_speed": "3000 rpm",
                           "rated_power": "500 W", "rated_speed": "2500 rpm"}, "t").torque
    assert dc.torque_at(2500 * math.pi / 30) == pytest.approx(500 / (2500 * math.pi / 30))
    cs = drive_from_table({"type": "constant_speed", "coordinate": "phi",
                           "speed": "43.5 rad/s"}, "t").torque
    assert cs.speed == 43.5
    tab = drive_from_table({"type": "torque_speed", "coordinate": "phi",
                            "omega": ["0 rpm", "1500 rpm"], "torque": ["20 N*m", "0 N*m"],
                            "gear_ratio": 2}, "t").torque
    assert tab.torque_at(1500 * math.pi / 30 / 4) == pytest.approx(2 * 10.0)


def test_extra_inertia_by_coordinate():
    mech = Mechanism("m")
    mech.add(drive_from_table({"type": "induction_motor", "coordinate": "phi",
                               "catalogue": "4A80B4U3", "gear_ratio": 2.0}, "t"))
    mech.add(Drive("constant", "phi", 5.0))
    assert extra_inertia_by_coordinate(mech) == {"phi": pytest.approx(0.0033 * 4)}
