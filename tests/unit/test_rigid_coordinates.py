"""The coordinates that cannot carry a dead position (dead_position.rigid_coordinates):
the pose of a free body and of a mounted base, not a crank pinned to the ground."""

import warnings

import numpy as np

import mechdyn
from mechdyn import Mechanism
from mechdyn.dynamics.dead_position import rigid_coordinates
from mechdyn.foundation import Foundation, Isolator, mounted


def _system(mech):
    """The mode system and pose of the first segment of a short run."""
    from mechdyn.dynamics.mode_system import ModeSystem
    from mechdyn.model.switchable import SwitchedModel

    model = mech.compile()
    sm = SwitchedModel(model)
    return ModeSystem(sm, model.initial_mode, {}, model.x0), model.x0


def pendulum():
    m = Mechanism("pendulum")
    m.add_body("bar", mass=2.0, inertia=0.05, com=(0.5, 0.0), points={"P": (1.0, 0.0)})
    m.add_revolute("O", "ground", "bar")
    m.add_coordinate("theta", kind="angle", body="bar")
    return m


def test_a_free_body_is_rigid_a_pinned_one_is_not():
    m = Mechanism("block")
    m.add_body("block", mass=1.0, inertia=0.1)
    for name, kind in (("X", "x"), ("Y", "y"), ("th", "angle")):
        m.add_coordinate(name, kind=kind, body="block")
    ms, x = _system(m)
    assert rigid_coordinates(ms, x) == {0, 1, 2}
    ms, x = _system(pendulum())
    assert rigid_coordinates(ms, x) == frozenset()


def test_the_mounted_base_is_rigid_with_the_machine_on_it():
    f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5), Isolator("R", 0.5, 0.0, 1e5, 1e5)],
                   mass=100.0, inertia=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mm = mounted(pendulum(), f)
    ms, x = _system(mm)
    names = [ms.coord_names[k] for k in sorted(rigid_coordinates(ms, x))]
    assert names == ["base_x", "base_y", "base_theta"]  # theta: the pin's relative angle
    tr = mechdyn.simulate(mm, 0.2, q0={"theta": -0.3}, progress=False)
    assert tr.status == "success" and np.all(np.isfinite(tr.q))
