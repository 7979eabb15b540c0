"""A stop with friction on a variable that is not a point coordinate: a ModelError."""

import pytest

from mechdyn.errors import ModelError
from mechdyn.mechanism.contact import Stop


@pytest.mark.parametrize("variable", ["joint:px", "angle:rod", "phi", "rod.A"])
def test_stop_friction_on_a_non_point_variable_is_a_model_error(variable):
    with pytest.raises(ModelError) as info:
        Stop("end", variable, lower=0.0, friction=0.2)
    msg = str(info.value)
    assert "stop 'end'" in msg and repr(variable) in msg
    assert "'body.point.x' or 'body.point.y'" in msg


def test_a_frictionless_stop_on_a_joint_is_fine():
    assert Stop("end", "joint:px", lower=0.0).friction == 0.0
