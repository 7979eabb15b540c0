"""The model file's ``[foundation]`` table: read into ``Mechanism.foundation``, every
problem named, and ``mechdyn foundation`` using it."""

import argparse
import dataclasses

import pytest

from mechdyn import examples
from mechdyn.cli import foundation as cli
from mechdyn.cli import main
from mechdyn.errors import ModelError, UnitError
from mechdyn.foundation import AnchorBolt, Foundation, Isolator
from mechdyn.mechanism import Mechanism
from mechdyn.modelfile import load, loads

TABLE = """
[foundation]
mass = "800 kg"
inertia = "120 kg*m^2"
com = ["0 mm", "-300 mm"]

[[foundation.bolts]]
name = "b1"
x = "-400 mm"
y = "-600 mm"
k_axial = "2e8 N/m"
k_shear = "1e8 N/m"
preload = "20 kN"

[[foundation.bolts]]
name = "b2"
x = "400 mm"
y = "-600 mm"
k_axial = "2e8 N/m"
k_shear = "100 N/um"
preload = "20 kN"
load_factor = "20 %"

[[foundation.isolators]]
name = "m1"
x = "0 mm"
y = "-600 mm"
kx = "2e5 N/m"
ky = "5e5 N/m"
cy = "2000 N*s/m"
"""

EXPECTED = Foundation([AnchorBolt("b1", -0.4, -0.6, 2e8, 1e8, preload=2e4),
                       AnchorBolt("b2", 0.4, -0.6, 2e8, 1e8, preload=2e4, load_factor=0.2),
                       Isolator("m1", 0.0, -0.6, 2e5, 5e5, cy=2000.0)],
                      mass=800.0, inertia=120.0, com=(0.0, -0.3))


def _text(old="", new=""):
    text = examples.path("slider_crank").read_text(encoding="utf-8") + TABLE
    assert old in text
    return text.replace(old, new, 1)


def test_the_table_reads_into_the_mechanism_as_the_python_api_builds_it():
    mech = loads(_text(), name="sc.toml")
    assert mech.foundation == EXPECTED
    assert load(examples.path("slider_crank")).foundation is None
    by_hand = Mechanism("m")
    assert by_hand.add_foundation(EXPECTED.supports, mass=800.0, inertia=120.0,
                                  com=(0.0, -0.3)) == EXPECTED
    assert by_hand.foundation == EXPECTED and by_hand.add(EXPECTED) is EXPECTED


def test_a_foundation_table_does_not_change_the_mechanism():
    mech = load(examples.path("press_cycle"))
    assert mech.foundation.names == ("left", "right") and mech.foundation.mass == 3000.0
    text = examples.path("press_cycle").read_text(encoding="utf-8")
    bare = loads(text[:text.index("\n[foundation]\n")], name="press_cycle.toml")
    assert bare.foundation is None
    assert repr(dataclasses.replace(mech, foundation=None)) == repr(bare)
    assert mech.compile().n_q == bare.compile().n_q


@pytest.mark.parametrize("old, new, match", [
    ('k_axial = "2e8 N/m"', 'k_axial = "-2e8 N/m"',
     r"\[\[foundation.bolts\]\] #1 'b1' k_axial: '-2e8 N/m': k_axial must be a finite "
     r"positive number"),
    ('cy = "2000 N*s/m"', 'cy = "-2 N*s/m"',
     r"\[\[foundation.isolators\]\] #1 'm1' cy: '-2 N\*s/m': cy must be a finite damping"),
    ('load_factor = "20 %"', "load_factor = 2",
     r"\[\[foundation.bolts\]\] #2 'b2' load_factor: 2: load_factor must be in \[0, 1\]"),
    ('mass = "800 kg"', 'mass = "0 kg"', r"\[foundation\] mass: '0 kg': mass must be a finite "
                                         r"positive number"),
    ('preload = "20 kN"\n', 'preload = "20 kN"\nk_axail = "1 N/m"\n',
     r"\[\[foundation.bolts\]\] #1 'b1': unknown key 'k_axail' \(did you mean 'k_axial'\?\); "
     r"valid keys: 'name', 'x', 'y', 'k_axial', 'k_shear', 'preload', 'load_factor'"),
    ('[[foundation.isolators]]', '[[foundation.mounts]]',
     r"\[foundation\]: unknown key 'mounts'; valid keys: 'mass', 'inertia', 'com', 'bolts', "
     r"'isolators'"),
    ('x = "0 mm"\n', "", r"\[\[foundation.isolators\]\] #1 'm1': missing key 'x'"),
    ('x = "0 mm"', "x = true", r"\[\[foundation.isolators\]\] #1 'm1' x: true: wrong type: "
                               r"expected a string or a number, got a boolean"),
    ('com = ["0 mm", "-300 mm"]', 'com = ["0 mm"]', r"\[foundation\] com: \['0 mm'\]: expected "
                                                    r"exactly 2 components"),
    ('mass = "800 kg"', "mass = [1]", r"\[foundation\] mass: \[1\]: wrong type"),
    ('name = "b2"', 'name = "b1"', r"\[\[foundation.bolts\]\] #2 'b1' name: 'b1' is already the "
                                   r"name of \[\[foundation.bolts\]\] #1 'b1'; support names must "
                                   r"be unique"),
    ('name = "m1"', 'name = "b2"', r"\[\[foundation.isolators\]\] #1 'b2' name: 'b2' is already "
                                   r"the name of \[\[foundation.bolts\]\] #2 'b2'"),
    ('name = "m1"', 'name = "1m"', r"\[\[foundation.isolators\]\] #1 '1m' name: name '1m' is not "
                                   r"allowed"),
    ('mass = "800 kg"\n', "", r"\[foundation\]: mass and inertia go together \(the elastic "
                              r"analysis needs both\); missing 'mass'"),
])
def test_each_problem_names_the_table_the_entry_and_the_key(old, new, match):
    with pytest.raises(ModelError, match=match) as err:
        loads(_text(old, new), name="sc.toml")
    assert all(p.startswith("sc.toml: [") for p in err.value.problems), err.value.problems


def test_a_wrong_unit_is_a_unit_error_naming_the_key():
    with pytest.raises(UnitError, match=r"\[\[foundation.bolts\]\] #1 'b1' k_axial: '2e8 kg': "
                                        r"the unit kg is a mass unit; expected a stiffness"):
        loads(_text('k_axial = "2e8 N/m"', 'k_axial = "2e8 kg"'), name="sc.toml")


def test_every_problem_at_once_with_those_of_the_rest_of_the_file():
    text = _text('k_axial = "2e8 N/m"', 'k_axial = "-2e8 N/m"').replace('ky = "5e5 N/m"',
                                                                        'ky = "5e5 kg"')
    with pytest.raises(ModelError) as err:
        loads(text.replace('mass = "', 'mass = "-', 1), name="sc.toml")
    text = "\n".join(err.value.problems)
    assert "'b1' k_axial" in text and "'m1' ky" in text and "[bodies." in text


def test_supports_that_cannot_hold_the_base_are_a_problem_of_the_foundation():
    text = _text('x = "400 mm"', 'x = "-400 mm"').replace('x = "0 mm"', 'x = "-400 mm"')
    with pytest.raises(ModelError, match=r"sc.toml: \[foundation\]: the supports b1, b2, m1 "
                                         r"cannot hold the base: nothing resists a rotation "
                                         r"about \(-0.4, -0.6\) m"):
        loads(text, name="sc.toml")
    bare = examples.path("slider_crank").read_text(encoding="utf-8")
    with pytest.raises(ModelError, match=r"\[foundation\]: no supports: add "
                                         r"\[\[foundation.bolts\]\] or "):
        loads(bare + '\n[foundation]\nmass = "1 kg"\ninertia = "1 kg*m^2"\n', name="sc.toml")
    with pytest.raises(ModelError, match=r"sc.toml: \[foundation\]: 3: wrong type: expected a "
                                         r"table"):
        loads("foundation = 3\n" + bare, name="sc.toml")


def test_a_foundation_that_is_not_one_is_a_problem_of_the_mechanism():
    mech = load(examples.path("slider_crank"))
    mech.foundation = [AnchorBolt("b1", 0.0, 0.0, 1.0, 1.0)]
    assert any(p.startswith("foundation: expected a Foundation") for p in mech.problems())


def test_check_reports_a_bad_foundation(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(_text('k_shear = "1e8 N/m"', 'k_shear = "1e8 N"'), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    assert "[[foundation.bolts]] #1 'b1' k_shear: '1e8 N'" in capsys.readouterr().out


def _args(*argv):
    parser = argparse.ArgumentParser(prog="mechdyn")
    sub = parser.add_subparsers(dest="command")
    cli.register(sub)
    return parser.parse_args(["foundation", *argv])


RUN = ("--t-end", "0.02s", "--samples", "21", "--rpm", "400rpm")


def test_the_command_uses_the_model_files_foundation(tmp_path, capsys):
    path = tmp_path / "sc.toml"
    path.write_text(_text(), encoding="utf-8")
    assert cli.run(_args(str(path), *RUN)) == 0
    out = capsys.readouterr().out
    assert "loads on 3 supports (the model's [foundation])" in out
    assert "b1: |F| max" in out and "m1: |F| max" in out
    assert "natural frequencies of the mounted base" in out
    # supports on the command line replace the file's; --mass and --inertia override it
    iso = "q1: x=-0.5m, y=-0.6m, kx=2e5N/m, ky=5e5N/m"
    argv = [str(path), *RUN, "--isolator", iso, "--isolator", iso.replace("q1", "q2")
            .replace("-0.5m", "0.5m"), "--mass", "2000kg"]
    args = _args(*argv)
    f = cli.build_foundation(args, loads(_text(), name="sc.toml").foundation)
    assert f.names == ("q1", "q2") and (f.mass, f.inertia, f.com) == (2000.0, 120.0, (0.0, -0.3))
    assert cli.run(args) == 0
    out = capsys.readouterr().out
    assert "loads on 2 supports (the command line)" in out and "b1:" not in out


def test_without_supports_anywhere_the_error_says_how_to_give_them(tmp_path):
    with pytest.raises(ModelError, match=r"no supports: the model has no \[foundation\] table; "
                                         r"give the supports with --support \(anchor bolts\) "
                                         r"or --isolator.*\[\[foundation.bolts\]\]"):
        cli.run(_args("slider_crank", *RUN))
    path = tmp_path / "sc.toml"
    path.write_text(_text('mass = "800 kg"\ninertia = "120 kg*m^2"\n', ""), encoding="utf-8")
    with pytest.raises(ModelError, match=r"--mass: the model's \[foundation\] has no inertia"):
        cli.run(_args(str(path), *RUN, "--mass", "500kg"))
    with pytest.raises(ModelError, match="--mass and --inertia go together"):
        cli.run(_args("slider_crank", *RUN, "--mass", "500kg", "--support",
                      "b1: x=0m, y=0m, k_axial=1e8N/m, k_shear=1e8N/m"))
