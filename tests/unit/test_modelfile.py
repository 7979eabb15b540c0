"""TOML model files: good files load into SI elements; each bad input gets one clear error."""

import math

import pytest

from mechdyn.errors import ModelError, UnitError
from mechdyn.mechanism import (
    Bushing,
    Drive,
    Force,
    Prismatic,
    RotarySpring,
    Spring,
    Table,
    Torque,
    TorqueSpeedCurve,
)
from mechdyn.modelfile import load, loads, schema

SLIDER_CRANK = """
[model]
name = "test slider-crank"
description = "for the tests"
gravity = ["0 m/s^2", "-9.81 m/s^2"]

[ground.points]
O = ["0 mm", "0 mm"]

[bodies.crank]
mass = "2 kg"
inertia = "0.01 kg*m^2"
pose = ["0 mm", "0 mm", "30 deg"]
[bodies.crank.points]
A = ["50 mm", "0 mm"]

[bodies.rod]
mass = "1.2 kg"
inertia = "0.004 kg*m^2"
com = ["48 mm", "0 mm"]
pose = ["43.3 mm", "25 mm", "-9 deg"]
[bodies.rod.points]
B = ["160 mm", "0 mm"]

[bodies.piston]
mass = "0.8 kg"
inertia = "0 kg*m^2"
pose = ["201 mm", "0 mm", "0 deg"]

[joints.O]
type = "revolute"
parent = "ground"
child = "crank"
parent_point = "O"

[joints.A]
type = "revolute"
parent = "crank"
child = "rod"
parent_point = "A"

[joints.B]
type = "revolute"
parent = "rod"
child = "piston"
parent_point = "B"

[joints.slide]
type = "prismatic"
parent = "ground"
child = "piston"
axis = [1, 0]

[coordinates.phi]
kind = "angle"
body = "crank"

[initial]
phi = "30 deg"

[initial_speed]
phi = "3000 rpm"

[[loads]]
type = "force"
name = "gas"
body = "piston"
magnitude = { x = ["0 deg", "180 deg", "360 deg"], y = ["0 N", "-1 kN", "0 N"], variable = "phi" }
direction = "0 deg"

[[loads]]
type = "spring"
name = "return_spring"
body1 = "piston"
point1 = [0, 0]
body2 = "ground"
point2 = "O"
stiffness = "2 N/mm"
free_length = "150 mm"
damping = "5 N*s/m"

[[loads]]
type = "rotary_damper"
name = "bearing"
joint = "O"
damping = "0.01 N*m*s/rad"

[[loads]]
type = "torque"
name = "brake"
body = "crank"
magnitude = { pulse = "-2 N*m", start = "0.1 s", duration = "20 ms" }
reaction_body = "ground"

[[drives]]
name = "motor"
coordinate = "phi"
torque = { omega = ["0 rpm", "3000 rpm"], torque = ["20 N*m", "0 N*m"] }
"""


def bad(old: str, new: str, text: str = SLIDER_CRANK):
    """Load the slider-crank with one edit; the edit must apply."""
    assert old in text, old
    return loads(text.replace(old, new, 1), name="slider_crank.toml")


# ---------------------------------------------------------------- good files
def test_good_file_loads_in_si_units():
    m = loads(SLIDER_CRANK, name="slider_crank.toml")
    assert m.name == "test slider-crank"
    assert m.gravity == pytest.approx((0.0, -9.81))
    assert list(m.bodies) == ["crank", "rod", "piston"]
    assert m.bodies["crank"].points["A"] == pytest.approx((0.05, 0.0))
    assert m.bodies["crank"].pose[2] == pytest.approx(math.radians(30))
    assert m.bodies["rod"].com == pytest.approx((0.048, 0.0))
    assert m.bodies["rod"].mass == 1.2
    assert isinstance(m.joints["slide"], Prismatic)
    assert m.dof == 1
    assert m.extras["initial"]["q"]["phi"] == pytest.approx(math.radians(30))
    assert m.extras["initial"]["qdot"]["phi"] == pytest.approx(100 * math.pi)


def test_loads_and_drives_are_parsed_into_elements():
    m = loads(SLIDER_CRANK, name="slider_crank.toml")
    gas, spring, bearing, brake = m.loads
    assert isinstance(gas, Force) and isinstance(gas.magnitude, Table)
    assert gas.magnitude.variable == "phi"
    assert gas.magnitude.x == pytest.approx((0.0, math.pi, 2 * math.pi))
    assert gas.magnitude(math.pi / 2) == pytest.approx(-500.0)
    assert gas.direction == pytest.approx((1.0, 0.0))
    assert isinstance(spring, Spring)
    assert (spring.stiffness, spring.free_length, spring.damping) == pytest.approx(
        (2000.0, 0.15, 5.0))
    assert spring.point1 == (0.0, 0.0) and spring.point2 == "O"
    assert isinstance(bearing, RotarySpring) and bearing.stiffness == 0.0
    assert bearing.damping == pytest.approx(0.01)
    assert isinstance(brake, Torque) and brake.reaction_body == "ground"
    assert brake.magnitude(0.11) == pytest.approx(-2.0)
    assert brake.magnitude(0.05) == 0.0
    (motor,) = m.drives
    assert isinstance(motor, Drive) and isinstance(motor.torque, TorqueSpeedCurve)
    assert motor.torque(50 * math.pi) == pytest.approx(10.0)


def test_load_reads_a_file_and_uses_its_name(tmp_path):
    f = tmp_path / "crank.toml"
    f.write_text(SLIDER_CRANK.replace('mass = "2 kg"', 'mass = "-2 kg"'), encoding="utf-8")
    with pytest.raises(ModelError, match=r"^crank\.toml: \[bodies\.crank\] mass"):
        load(f)
    f.write_text(SLIDER_CRANK.replace('name = "test slider-crank"\n', ""), encoding="utf-8")
    assert load(f).name == "crank"


def test_missing_file_is_a_model_error(tmp_path):
    with pytest.raises(ModelError, match="cannot read the model file"):
        load(tmp_path / "nope.toml")


def test_inertia_about_a_point_is_converted_to_the_centre_of_mass():
    m = bad('inertia = "0.01 kg*m^2"\npose',
            'inertia = "0.01 kg*m^2"\ninertia_about = "A"\ncom = ["10 mm", "0 mm"]\npose')
    assert m.bodies["crank"].inertia == pytest.approx(0.01 - 2 * 0.04**2)


def test_sketch_frame_gives_the_same_body_as_the_body_frame():
    # the rod given by its points in the sketch (ground frame, pose of the sketch),
    # with its frame on A and its x axis towards B, equals the canonical rod
    c, s = math.cos(math.radians(-9)), math.sin(math.radians(-9))
    sketch_rod = f"""[bodies.rod]
mass = "1.2 kg"
inertia = "0.004 kg*m^2"
frame = "sketch"
frame_points = ["A", "B"]
com = ["{43.3 + 48 * c!r} mm", "{25 + 48 * s!r} mm"]
[bodies.rod.points]
A = ["43.3 mm", "25 mm"]
B = ["{43.3 + 160 * c!r} mm", "{25 + 160 * s!r} mm"]"""
    canonical_rod = """[bodies.rod]
mass = "1.2 kg"
inertia = "0.004 kg*m^2"
com = ["48 mm", "0 mm"]
pose = ["43.3 mm", "25 mm", "-9 deg"]
[bodies.rod.points]
B = ["160 mm", "0 mm"]"""
    text = SLIDER_CRANK.replace(canonical_rod, sketch_rod)
    text = text.replace('child = "rod"\nparent_point = "A"',
                        'child = "rod"\nparent_point = "A"\nchild_point = "A"')
    sketch = loads(text, name="s.toml").bodies["rod"]
    canon = loads(SLIDER_CRANK, name="c.toml").bodies["rod"]
    assert sketch.pose == pytest.approx(canon.pose, abs=1e-15)
    assert sketch.points["B"] == pytest.approx(canon.points["B"], abs=1e-15)
    assert sketch.points["A"] == pytest.approx((0.0, 0.0), abs=1e-15)
    assert sketch.com == pytest.approx(canon.com, abs=1e-15)


def test_schema_is_packaged():
    assert schema()["title"] == "mechdyn model file"


# ---------------------------------------------------------------- one clear error each
def test_unknown_body_name_lists_the_valid_names():
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: \[joints\.A\] child: unknown "
                                         r"body 'rdo'; valid body names: 'crank', 'ground', "
                                         r"'piston', 'rod'$"):
        bad('child = "rod"', 'child = "rdo"')


def test_negative_mass():
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: \[bodies\.rod\] mass: '-2 kg': "
                                         r"mass must be >= 0 kg$"):
        bad('mass = "1.2 kg"', 'mass = "-2 kg"')


def test_bad_unit_for_a_length():
    with pytest.raises(UnitError, match=r"^slider_crank\.toml: \[bodies\.rod\.points\] B\[0\]: "
                                        r"'15 kg': the unit kg is a mass unit; expected a length "
                                        r"\(m\), e\.g\. \"15 mm\"$"):
        bad('B = ["160 mm", "0 mm"]', 'B = ["15 kg", "0 mm"]')


def test_missing_key():
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: \[bodies\.rod\]: missing key "
                                         r"'mass' \(mass, e\.g\. \"4\.6 kg\"\)$"):
        bad('mass = "1.2 kg"\n', "")


def test_wrong_type():
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: \[bodies\.piston\] mass: true: "
                                         r"wrong type: expected a string or a number, got a "
                                         r"boolean$"):
        bad('mass = "0.8 kg"', "mass = true")


def test_loop_that_cannot_close_names_the_open_joints_and_the_gap():
    # a four-bar whose coupler is 3.2 mm too short to reach the rocker at phi = 0:
    # |A C| = 200 - 40 = 160 mm, coupler + rocker = 76.8 + 80 = 156.8 mm
    four_bar = """
[ground.points]
O = ["0 mm", "0 mm"]
C = ["200 mm", "0 mm"]
[bodies.crank]
mass = "0.2 kg"
inertia = "2.7e-5 kg*m^2"
points = { A = ["40 mm", "0 mm"] }
[bodies.coupler]
mass = "0.5 kg"
inertia = "6e-4 kg*m^2"
pose = ["40 mm", "0 mm", "0 deg"]
points = { B = ["76.8 mm", "0 mm"] }
[bodies.rocker]
mass = "0.35 kg"
inertia = "1.9e-4 kg*m^2"
pose = ["200 mm", "0 mm", "180 deg"]
points = { B = ["80 mm", "0 mm"] }
[joints.O]
type = "revolute"
parent = "ground"
child = "crank"
parent_point = "O"
[joints.A]
type = "revolute"
parent = "crank"
child = "coupler"
parent_point = "A"
[joints.B]
type = "revolute"
parent = "coupler"
child = "rocker"
point = "B"
[joints.C]
type = "revolute"
parent = "ground"
child = "rocker"
parent_point = "C"
[coordinates.phi]
kind = "angle"
body = "crank"
"""
    with pytest.raises(ModelError) as info:
        loads(four_bar, name="four_bar.toml")
    msg = str(info.value)
    assert msg.startswith("four_bar.toml: the initial sketch cannot be assembled")
    assert "does not close by about 3.2 mm" in msg
    for joint in ("'O'", "'A'", "'B'", "'C'"):
        assert joint in msg


def test_all_problems_are_reported_at_once():
    text = SLIDER_CRANK.replace('mass = "1.2 kg"', 'mass = "-2 kg"\ncolour = "red"')
    text = text.replace('B = ["160 mm", "0 mm"]', 'B = ["160 kg", "0 mm"]')
    text = text.replace('body = "crank"\n', 'body = "crnk"\n', 1)
    with pytest.raises(ModelError) as info:
        loads(text, name="x.toml")
    probs = info.value.problems
    assert len(probs) == 4, probs
    assert str(info.value).startswith("4 problems in the model:")
    assert any("unknown key 'colour'" in p for p in probs)
    assert any("mass must be >= 0" in p for p in probs)
    assert any("'160 kg'" in p for p in probs)
    assert any("unknown body 'crnk'" in p for p in probs)


def test_unknown_key_lists_valid_keys():
    with pytest.raises(ModelError, match=r"\[bodies\.rod\]: unknown key 'con' \(did you mean "
                                         r"'com'\?\); valid keys: 'description', 'mass'"):
        bad('com = ["48 mm", "0 mm"]', 'con = ["48 mm", "0 mm"]')


def test_unknown_table_lists_valid_tables():
    with pytest.raises(ModelError, match=r"unknown table 'intial' \(did you mean 'initial'\?\); "
                                         r"valid tables: 'model', 'ground'"):
        bad("[initial]", "[intial]")


def test_toml_syntax_error():
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: not valid TOML: .*line \d+"):
        bad("[initial]", "[initial")


def test_unknown_joint_type():
    with pytest.raises(ModelError, match=r"\[joints\.slide\] type: 'slider': must be one of "
                                         r"'revolute', 'prismatic', 'lock'"):
        bad('type = "prismatic"', 'type = "slider"')


def test_unknown_point_lists_the_points_of_the_body():
    with pytest.raises(ModelError, match=r"\[joints\.B\] parent_point: unknown point 'C' of body "
                                         r"'rod'; valid point names: 'com', 'B'"):
        bad('parent_point = "B"', 'parent_point = "C"')


def test_unknown_coordinate_in_initial():
    with pytest.raises(ModelError, match=r"\[initial\] ph: unknown coordinate 'ph'; valid "
                                         r"coordinate names: 'phi'"):
        bad('phi = "30 deg"', 'ph = "30 deg"')


def test_initial_speed_needs_an_angular_unit():
    with pytest.raises(UnitError, match=r"\[initial_speed\] phi: '50 Hz': .*no angle unit"):
        bad('phi = "3000 rpm"', 'phi = "50 Hz"')


def test_pose_with_two_components():
    with pytest.raises(ModelError, match=r"\[bodies\.crank\] pose: .*expected exactly 3 "
                                         r"components, got 2"):
        bad('pose = ["0 mm", "0 mm", "30 deg"]', 'pose = ["0 mm", "0 mm"]')


def test_coordinate_on_the_wrong_kind_of_joint():
    with pytest.raises(ModelError, match=r"\[coordinates\.phi\] joint: 'slide' is a prismatic "
                                         r"joint, but kind 'relative_angle' needs a revolute "
                                         r"joint; revolute joints: 'O', 'A', 'B'"):
        bad('kind = "angle"\nbody = "crank"', 'kind = "relative_angle"\njoint = "slide"')


def test_problems_of_the_mechanism_are_prefixed_with_the_file():
    # two coordinates for a 1-DOF mechanism: Mechanism.validate reports the DOF count
    # (and that the sketch cannot be assembled); the loader prefixes the file name
    with pytest.raises(ModelError, match=r"slider_crank\.toml: degrees of freedom by "
                                         r"Gruebler's count: .* = 1, but 2 coordinate"):
        bad("[initial]", '[coordinates.psi]\nkind = "angle"\nbody = "rod"\n\n[initial]')


def test_load_errors_name_the_load():
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #3 'bearing' joint: unknown revolute "
                                         r"joint 'P'; valid revolute joint names: 'A', 'B', 'O'"):
        bad('joint = "O"\ndamping', 'joint = "P"\ndamping')
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #1 'gas' magnitude\.variable: 'phj': "
                                         r"unknown variable; valid variables: 't', 'phi'"):
        bad('variable = "phi"', 'variable = "phj"')
    with pytest.raises(UnitError, match=r"\[\[loads\]\] #1 'gas' magnitude\.y\[1\]: '-1 kN\*m': "
                                        r"the unit kN \* m is a torque unit; expected a force"):
        bad('"-1 kN"', '"-1 kN*m"')
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #1 'gas' magnitude\.x: the values must "
                                         r"increase strictly"):
        bad('"180 deg", "360 deg"', '"360 deg", "180 deg"')
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #2 'return_spring': missing key "
                                         r"'point2'"):
        bad('point2 = "O"\n', "")


def test_drive_errors():
    with pytest.raises(ModelError, match=r"\[\[drives\]\] #1 'motor' coordinate: unknown "
                                         r"coordinate 'ph'"):
        bad('coordinate = "phi"', 'coordinate = "ph"')
    with pytest.raises(UnitError, match=r"\[\[drives\]\] #1 'motor' torque\.omega\[1\]: "
                                        r"'3000 m/s'"):
        bad('"3000 rpm"]', '"3000 m/s"]')


def test_errors_come_without_a_chained_traceback():
    with pytest.raises(ModelError) as info:
        bad('B = ["160 mm", "0 mm"]', 'B = "16O mm"')
    assert info.value.__cause__ is None
    assert info.value.__suppress_context__ or info.value.__context__ is None


def test_examples_in_the_documentation_are_valid():
    import re
    import tomllib
    from pathlib import Path

    from mechdyn.modelfile.schema import schema_problems

    doc = Path(__file__).resolve().parents[2] / "docs" / "model-file.md"
    blocks = re.findall(r"```toml\n(.*?)```", doc.read_text(encoding="utf-8"), re.S)
    assert len(blocks) >= 8
    for block in blocks:
        msgs, _ = schema_problems(tomllib.loads(block), "doc")
        assert all("missing table" in m for m in msgs), msgs
    assert loads(blocks[-1], name="pendulum.toml").dof == 1


def test_motor_drives_are_built_by_the_motors_module():
    from mechdyn.mechanism.motors import ConstantSpeedDrive, GearStage
    from mechdyn.modelfile.drives import DRIVE_TYPES

    curve = 'torque = { omega = ["0 rpm", "3000 rpm"], torque = ["20 N*m", "0 N*m"] }'
    m = bad(curve, 'type = "constant_speed"\nspeed = "100 rpm"')
    assert isinstance(m.drives[0].torque, ConstantSpeedDrive)
    assert m.drives[0].torque.speed == pytest.approx(100 * math.pi / 30)
    m = bad(curve, 'type = "induction_motor"\ncatalogue = "4A80B4U3"\ngear_ratio = 3.4')
    assert isinstance(m.drives[0].torque, GearStage)
    with pytest.raises(UnitError, match=r"\[\[drives\]\] #1 'motor': no_load_speed: '3000 kg'"):
        bad(curve, 'type = "dc_motor"\nno_load_speed = "3000 kg"\nstall_torque = "1 N*m"')
    with pytest.raises(ModelError, match=r"\[\[drives\]\] #1 'motor' type: 'electric': must be "
                                         r"one of 'induction_motor'"):
        bad(curve, 'type = "electric"')
    # the schema knows the same motor types as the motors module
    enum = schema()["$defs"]["drive"]["then"]["properties"]["type"]["enum"]
    assert sorted(enum) == sorted(DRIVE_TYPES)


def test_periodic_tables_and_pulses():
    m = bad('variable = "phi" }', 'variable = "phi", period = "360 deg" }')
    gas = m.loads[0].magnitude
    assert gas.period == pytest.approx(2 * math.pi)
    for k in (-2, 0, 3):  # -1 kN * |sin|-like hat over every revolution
        assert gas(math.pi / 2 + 2 * math.pi * k) == pytest.approx(-500.0)
        assert gas(1.5 * math.pi + 2 * math.pi * k) == pytest.approx(-500.0)
    m = bad('duration = "20 ms" }', 'duration = "20 ms", period = "0.1 s" }')
    brake = m.loads[3].magnitude
    assert brake.period == pytest.approx(0.1)
    assert brake(0.11) == pytest.approx(-2.0) and brake(0.61) == pytest.approx(-2.0)
    assert brake(0.05) == 0.0 and brake(-0.39) == pytest.approx(-2.0)
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #1 'gas' magnitude\.period: the "
                                         r"period of the table over 'phi' \('180 deg' = "
                                         r"3\.14159 SI\) is shorter than the table's span"):
        bad('variable = "phi" }', 'variable = "phi", period = "180 deg" }')
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #1 'gas' magnitude\.period: the "
                                         r"period of the table over 'phi' must be > 0, got "
                                         r"'-1 deg'"):
        bad('variable = "phi" }', 'variable = "phi", period = "-1 deg" }')
    with pytest.raises(UnitError, match=r"\[\[loads\]\] #1 'gas' magnitude\.period: '1 s': "
                                        r"the unit s is a time unit; expected an angle"):
        bad('variable = "phi" }', 'variable = "phi", period = "1 s" }')
    with pytest.raises(ModelError, match=r"\[\[loads\]\] #4 'brake' magnitude\.period: the "
                                         r"period of the pulse over 't' \('10 ms'\) must be "
                                         r"longer than its duration"):
        bad('duration = "20 ms" }', 'duration = "20 ms", period = "10 ms" }')


def test_bushing_is_read_in_si_units_and_checked():
    text = SLIDER_CRANK.replace('''[[loads]]
type = "rotary_damper"''', '''[[loads]]
type = "bushing"
name = "mount"
body1 = "ground"
point1 = "O"
body2 = "crank"
point2 = [0, 0]
kx = "2 N/mm"
ky = "3 kN/m"
cy = "5 N*s/mm"

[[loads]]
type = "rotary_damper"''', 1)
    m = loads(text, name="slider_crank.toml")
    mount = next(ld for ld in m.loads if ld.name == "mount")
    assert isinstance(mount, Bushing)
    assert (mount.body1, mount.point1, mount.body2) == ("ground", "O", "crank")
    assert (mount.kx, mount.ky, mount.cx, mount.cy) == pytest.approx((2e3, 3e3, 0.0, 5e3))
    with pytest.raises(ModelError) as err:
        loads(text.replace('kx = "2 N/mm"', 'kx = "-2 N/mm"').replace('body1 = "ground"\n'
              'point1 = "O"\nbody2 = "crank"', 'body1 = "crank"\npoint1 = [0, 0]\n'
              'body2 = "crank"'), name="slider_crank.toml")
    msg = str(err.value)
    assert "'mount' kx: '-2 N/mm': kx must be >= 0 N/m" in msg
    assert "body1 and body2 are the same body 'crank'" in msg
