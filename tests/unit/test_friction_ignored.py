"""Analyses that do not model the friction of the pairs say so (issue 12): the reduction
method warns once, naming every joint with friction and what it leaves out."""

import warnings

import numpy as np
import pytest

import mechdyn
from mechdyn.cli import main
from mechdyn.friction.ignored import FrictionIgnoredWarning
from mechdyn.reduction.reduce import ReducedMachine, reduce_model

JOINTS = ("A", "B", "C", "D", "E", "F", "slide")


@pytest.fixture(scope="module")
def press():
    return mechdyn.examples.load("toggle_press_friction").compile()


def _ignored(record) -> list[str]:
    return [str(w.message) for w in record if issubclass(w.category, FrictionIgnoredWarning)]


def test_reduction_warns_once_naming_the_joints(press):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        red = reduce_model(press, steps=37)
    msgs = _ignored(rec)
    assert len(msgs) == 1
    msg = msgs[0]
    for j in JOINTS:
        assert f"joint {j!r} has friction" in msg
    assert "friction = 0.08 (pin_radius 40 mm)" in msg
    assert "friction = 0.1 (guide_length 120 mm)" in msg
    assert "reduction method" in msg and "does not model friction" in msg
    assert "reduced torque leaves out" in msg
    assert red.stats["friction_ignored"] == JOINTS
    assert rec[0].filename == __file__  # points at the caller
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        ReducedMachine.from_model(press)
    assert len(_ignored(rec)) == 1


def test_frictionless_model_reduces_silently():
    model = mechdyn.examples.load("toggle_press").compile()
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionIgnoredWarning)
        red = reduce_model(model, steps=13)
    assert red.stats["friction_ignored"] == () and np.all(np.isfinite(red.J_red))


def test_reduce_command_shows_the_warning(tmp_path, capsys):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        rc = main(["reduce", "toggle_press_friction", "--steps", "37",
                   "-o", str(tmp_path / "red.csv")])
    assert rc == 0, capsys.readouterr().err
    assert len(_ignored(rec)) == 1


def test_flywheel_command_warns_once_though_it_reduces_twice(capsys):
    # no --speed: a first reduction finds the torque speed-independent, a second one at
    # the model's speed makes the table; the user is told once
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        rc = main(["flywheel", "toggle_press_friction", "--delta", "0.05", "--steps", "37"])
    assert rc == 0, capsys.readouterr().err
    assert len(_ignored(rec)) == 1
