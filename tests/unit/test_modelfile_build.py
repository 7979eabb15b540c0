"""loader.build_model: the Model that validation compiled, handed back; and build without
the JSON-schema pass (schema=False) for documents whose structure is known good: the
value checks still run and say the same."""

import pytest
from test_modelfile import SLIDER_CRANK

import mechdyn.compiler
from mechdyn.errors import ModelError
from mechdyn.model import Model
from mechdyn.modelfile import loader
from mechdyn.modelfile.loader import build, build_model, read_document


def doc_with(old: str = "", new: str = "") -> dict:
    assert old in SLIDER_CRANK, old
    return read_document(SLIDER_CRANK.replace(old, new, 1), "slider_crank.toml")


def test_the_model_validation_compiled_is_handed_back_and_compiled_once(monkeypatch):
    calls = []
    real = mechdyn.compiler.compile_mechanism
    monkeypatch.setattr(mechdyn.compiler, "compile_mechanism",
                        lambda m: calls.append(m) or real(m))
    model = build_model(doc_with(), "slider_crank.toml")
    assert isinstance(model, Model) and len(calls) == 1
    assert model.mechanism is calls[0]
    assert model.coordinate_names == ("phi",)
    assert model.mechanism.bodies["rod"].mass == pytest.approx(1.2)
    with pytest.raises(AttributeError, match="frozen"):
        model.x0 = None


def test_without_the_schema_pass_the_structure_is_not_checked(monkeypatch):
    def refuse(*args):
        raise AssertionError("the schema pass ran")

    monkeypatch.setattr(loader, "schema_problems", refuse)
    mech = build(doc_with(), "slider_crank.toml", schema=False)
    assert mech.bodies["rod"].mass == pytest.approx(1.2)
    with pytest.raises(AssertionError, match="schema pass"):
        build(doc_with(), "slider_crank.toml")  # the default checks the structure


@pytest.mark.parametrize("old, new, named", [
    ('mass = "1.2 kg"', 'mass = "-2 kg"', r"\[bodies\.rod\] mass: '-2 kg': mass must be >= 0"),
    ('B = ["160 mm", "0 mm"]', 'B = ["15 kg", "0 mm"]',
     r"\[bodies\.rod\.points\] B\[0\]: '15 kg': the unit kg is a mass unit"),
    ('child = "rod"', 'child = "rdo"', r"\[joints\.A\] child: unknown body 'rdo'"),
    ('stiffness = "2 N/mm"', 'stiffness = "2 N"', r"\[\[loads\]\] #2 'return_spring'"),
    ('phi = "30 deg"', 'phi = "30 mm"', r"\[initial\] phi"),
])
def test_the_value_checks_run_without_the_schema_pass_and_say_the_same(old, new, named):
    messages = []
    for schema in (True, False):
        with pytest.raises(ModelError, match=named) as err:
            build(doc_with(old, new), "slider_crank.toml", schema=schema)
        messages.append((type(err.value), str(err.value)))
    assert messages[0] == messages[1]


def test_a_sketch_that_cannot_be_assembled_is_named_without_the_schema_pass():
    doc = doc_with('B = ["160 mm", "0 mm"]', 'B = ["10 mm", "0 mm"]')
    with pytest.raises(ModelError, match=r"^slider_crank\.toml: the initial sketch cannot be "
                                         r"assembled: .*does not close"):
        build_model(doc, "slider_crank.toml", schema=False)
