"""The model-file schema's validator tests the points of a table by their type, once per
item, instead of resolving the item's ``$ref`` each time: the same errors and messages as
the plain jsonschema validator, in a fraction of its time."""

import importlib
import time
import tomllib

import pytest
from jsonschema import Draft202012Validator

from mechdyn import examples
from mechdyn.errors import ModelError
from mechdyn.modelfile import loads

sch = importlib.import_module("mechdyn.modelfile.schema")  # the module, not its function

BAD_LOADS = """
[[loads]]
type = "force"
name = "tab"
body = "crank"
point = "com"
magnitude = { x = ["0 s", true, "2 s", [1, 2]], y = [1, { a = 1 }, "3 N", "4 N"], variable = "t" }

[[loads]]
type = "torque"
name = "tq"
body = "crank"
magnitude = { x = "0 s", y = ["1 N*m", "2 N*m"], variable = "t" }

[[drives]]
name = "motor"
coordinate = "phi"
torque = { omega = ["0 rad/s", false], torque = ["1 N*m", "0 N*m"] }
"""


def _doc(extra: str = "") -> dict:
    return tomllib.loads(examples.path("four_bar").read_text(encoding="utf-8") + extra)


def _plain_problems(doc, monkeypatch):
    with monkeypatch.context() as m:
        m.setattr(sch, "_validator", lambda: Draft202012Validator(sch.schema()))
        return sch.schema_problems(doc, "bad.toml")


def test_bad_table_points_give_the_plain_validators_messages(monkeypatch):
    doc = _doc(BAD_LOADS)
    doc["bodies"]["crank"]["pose"] = ["0 mm", True, "0 deg"]  # a vector of quantities
    fast = sch.schema_problems(doc, "bad.toml")
    assert fast == _plain_problems(doc, monkeypatch)
    messages = fast[0]
    assert len(messages) == 6
    assert any("[[loads]] #1 'tab' magnitude.x[1]: true: wrong type: expected a string or a "
               "number, got a boolean" in m for m in messages)
    assert any("magnitude.y[1]" in m and "got a table" in m for m in messages)
    assert any("magnitude.x[3]" in m and "got an array" in m for m in messages)
    with pytest.raises(ModelError, match=r"magnitude.x\[1\]: true: wrong type"):
        loads(examples.path("four_bar").read_text(encoding="utf-8") + BAD_LOADS,
              name="bad.toml")


def test_a_long_table_is_checked_without_resolving_every_point(monkeypatch):
    n = 20_000
    xs = ", ".join(f'"{k * 1e-3:.3f} s"' for k in range(n))
    doc = _doc('\n[[loads]]\ntype = "force"\nname = "tab"\nbody = "crank"\npoint = "com"\n'
               f'magnitude = {{ x = [{xs}], y = [{xs.replace(" s", " N")}], variable = "t" }}\n')
    sch.schema_problems({}, "warm.toml")
    t0 = time.process_time()
    fast = sch.schema_problems(doc, "long.toml")
    t_fast = time.process_time() - t0
    t0 = time.process_time()
    plain = _plain_problems(doc, monkeypatch)
    t_plain = time.process_time() - t0
    assert fast == plain == ([], [])
    assert t_fast < t_plain / 3  # about 15 times faster on the machine it was written on


def test_a_bad_point_of_a_table_is_named_with_its_place():
    # the points are read without their place; one that fails is read again with it
    text = examples.path("four_bar").read_text(encoding="utf-8") + (
        '\n[[loads]]\ntype = "force"\nname = "tab"\nbody = "crank"\npoint = "com"\n'
        'magnitude = { x = ["0 s", "1 s", "2 s"], y = ["1 N", "2 kg", "3 N"], variable = "t" }\n')
    with pytest.raises(ModelError, match=r"bad.toml: \[\[loads\]\] #1 'tab' magnitude.y\[1\]: "
                                         r"'2 kg'"):
        loads(text, name="bad.toml")
