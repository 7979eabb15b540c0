"""compile() validates the whole model: a bad switch is found before any analysis runs."""

import pytest

from mechdyn.errors import ModelError
from mechdyn.mechanism import Mechanism, Spring
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import CoordinateLock, Switch, add_element


def _slider():
    m = Mechanism("mass on a spring", gravity=(0.0, 0.0))
    m.add_ground(points={"A": (-1.0, 0.0)})
    m.add_body("mass", mass=1.0, inertia=0.1)
    m.add_prismatic("slide", "ground", "mass", axis=(1.0, 0.0))
    m.add_coordinate("s", kind="travel", joint="slide")
    m.add(Spring("k", "ground", "A", "mass", (0.0, 0.0), stiffness=100.0, free_length=1.0))
    return m


def test_switch_with_unknown_target_and_variable_fails_at_compile_listing_both():
    m = _slider()
    add_element(m, CoordinateLock("hold", "s"))
    add_element(m, Switch("go", "engage", "hodl", variable="ss", value=0.0))
    with pytest.raises(ModelError) as info:
        m.compile()
    problems = info.value.problems
    assert any("target" in p and "'hodl'" in p and "hold" in p for p in problems), problems
    assert any("variable" in p and "'ss'" in p for p in problems), problems


def test_stop_on_an_unknown_variable_and_a_bad_drive_are_reported_together():
    from mechdyn.mechanism.drive import Drive

    m = _slider()
    add_element(m, Stop("end", "s_typo", lower=-0.1))
    m.add(Drive("push", "q_typo", 1.0))
    with pytest.raises(ModelError) as info:
        m.compile()
    text = str(info.value)
    assert "stop 'end'" in text and "s_typo" in text
    assert "drive 'push'" in text and "q_typo" in text


def test_a_compiled_model_is_frozen_and_keeps_its_structure():
    m = _slider()
    add_element(m, Stop("end", "s", lower=-0.1))
    model = m.compile()
    with pytest.raises(AttributeError, match="frozen"):
        model.n_q = 3
    m.extras.pop("stops")  # changing the mechanism afterwards does not change the model
    assert model.has_switching
