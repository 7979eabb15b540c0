"""mechdyn.foundation.mounted: what moves onto the base, and the named errors."""

import argparse
import dataclasses
import warnings

import numpy as np
import pytest

import mechdyn
from mechdyn import Mechanism
from mechdyn.cli import foundation as cli
from mechdyn.errors import ModelError
from mechdyn.foundation import (
    AnchorBolt,
    FloorFrameWarning,
    Foundation,
    Isolator,
    base_coordinates,
    mounted,
)
from mechdyn.mechanism import Bushing, Coordinate, Drive, RotarySpring, Spring, Torque
from mechdyn.results.table import read_csv

MOUNTS = Foundation([Isolator("L", -0.5, -0.2, 1e6, 1e6, 1e3, 1e3),
                     Isolator("R", 0.5, -0.2, 1e6, 1e6, 1e3, 1e3)], mass=200.0, inertia=20.0,
                    com=(0.0, -0.1))


def crank_and_bar() -> Mechanism:
    """A crank pinned to the ground, a free bar pinned to it; a spring and a torque
    reacting on the ground."""
    m = Mechanism("crank and bar")
    m.add_ground({"P": (0.2, 0.1)})
    m.add_body("crank", mass=1.0, inertia=0.01, com=(0.05, 0.0), points={"A": (0.1, 0.0)})
    m.add_body("bar", mass=1.0, inertia=0.02, com=(0.1, 0.0), pose=(0.1, 0.0, 0.0))
    m.add_revolute("O", "ground", "crank")
    m.add_revolute("A", "crank", "bar", "A", (0.0, 0.0))
    m.add_coordinate("phi", kind="angle", body="crank")
    m.add_coordinate("psi", kind="angle", body="bar")
    m.add(Spring("s", "ground", "P", "bar", (0.2, 0.0), stiffness=100.0, free_length=0.1))
    m.add(Torque("t", "crank", 1.0, reaction_body="ground"))
    m.add(Drive("motor", "phi", 2.0))
    return m


def test_everything_on_the_ground_moves_onto_the_base():
    with pytest.warns(FloorFrameWarning, match="coordinate 'psi' \\(absolute angle of 'bar'\\)"):
        mm = mounted(crank_and_bar(), MOUNTS)
    assert mm.joints["O"].parent == "base" and mm.bodies["base"].points["P"] == (0.2, 0.1)
    spring = next(ld for ld in mm.loads if ld.name == "s")
    torque = next(ld for ld in mm.loads if ld.name == "t")
    assert spring.body1 == "base" and torque.reaction_body == "base"
    # the driven crank angle is now measured against the base, its stator on it
    assert (mm.coordinates["phi"].kind, mm.coordinates["phi"].joint) == ("relative_angle", "O")
    assert mm.coordinates["psi"].kind == "angle"  # a free bar keeps its absolute angle
    assert list(mm.coordinates)[-3:] == list(base_coordinates())
    mounts = {ld.name: ld for ld in mm.loads if isinstance(ld, Bushing)}
    assert list(mounts) == ["base_L", "base_R"]
    assert (mounts["base_L"].body1, mounts["base_L"].body2) == ("ground", "base")
    assert mm.dof == 5 and not crank_and_bar().bodies.get("base")
    mm.validate()


def test_the_mounted_machine_starts_at_rest_on_its_isolators():
    m = crank_and_bar()
    m.drives.clear()
    with pytest.warns(FloorFrameWarning):
        mm = mounted(m, MOUNTS)
    tr = mechdyn.simulate(mm, 1e-3, progress=False, q0={"phi": 0.0, "psi": 0.0})
    assert tr.success
    # no drive: the base starts in equilibrium, up to the machine's falling links
    assert np.max(np.abs(tr.coordinate("base_theta"))) < 1e-3


@pytest.mark.filterwarnings("ignore::mechdyn.foundation.FloorFrameWarning")
def test_named_errors():
    with pytest.raises(ModelError, match="no foundation"):
        mounted(crank_and_bar())
    bolts = Foundation([AnchorBolt("b1", -0.4, 0.0, 2e8, 1e8), AnchorBolt("b2", 0.4, 0.0, 2e8,
                                                                           1e8)],
                       mass=10.0, inertia=1.0)
    with pytest.raises(ModelError, match="'b1', 'b2' are anchor bolts"):
        mounted(crank_and_bar(), bolts)
    with pytest.raises(ModelError, match="needs the mass and inertia"):
        mounted(crank_and_bar(), Foundation(MOUNTS.supports))
    with pytest.raises(ModelError, match="name\\(s\\) 'crank' are taken"):
        mounted(crank_and_bar(), MOUNTS, base="crank")
    m = crank_and_bar()
    m.add(Drive("bar_motor", "psi", 1.0))
    with pytest.raises(ModelError, match="drive 'bar_motor'.*'psi' of body 'bar'"):
        mounted(m, MOUNTS)
    m = crank_and_bar()
    m.extras["gadgets"] = [object()]
    with pytest.raises(ModelError, match="'gadgets' cannot be carried.*known kinds"):
        mounted(m, MOUNTS)


def test_floor_frame_variables_are_named():
    m = mechdyn.examples.load("press_cycle")
    # the bundled springs over the ram's own travel ("joint:guide"); over its position in
    # the ground frame they would keep measuring against the floor
    m.loads = [dataclasses.replace(ld, magnitude=dataclasses.replace(
        ld.magnitude, variable="slider.com.x")) if ld.name == "ram_springs" else ld
        for ld in m.loads]
    with pytest.warns(FloorFrameWarning, match="force 'ram_springs' \\('slider.com.x'\\)"):
        mm = mounted(m)
    # the rocker, pinned to the ram that slides on the frame: measured against the base
    assert (mm.coordinates["psi"].kind, mm.coordinates["psi"].joint) == ("relative_angle", "C")
    m = crank_and_bar()
    m.coordinates["psi"] = Coordinate("psi", "relative_angle", joint="A")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mounted(m, MOUNTS)


def test_cli_coupled(tmp_path, capsys):
    parser = argparse.ArgumentParser(prog="mechdyn")
    cli.register(parser.add_subparsers(dest="command"))
    out = tmp_path / "loads.csv"
    args = parser.parse_args(
        ["foundation", "slider_crank", "--t-end", "0.05s", "--samples", "51", "--coupled",
         "--mass", "50kg", "--inertia", "2kg*m^2", "-o", str(out),
         "--isolator", "m1: x=-0.2m, y=-0.1m, kx=1e6N/m, ky=2e6N/m, cx=500N*s/m, cy=800N*s/m",
         "--isolator", "m2: x=0.3m, y=-0.1m, kx=1e6N/m, ky=2e6N/m, cx=500N*s/m, cy=800N*s/m"])
    assert cli.run(args) == 0
    text = capsys.readouterr().out
    assert "coupled: the frame as a body on its isolators" in text
    assert "peak |F| to floor, kN" in text
    df = read_csv(tmp_path / "loads_coupled.csv")
    assert {"Fy_floor_N_rigid", "Fy_floor_N_oneway", "Fy_floor_N_coupled",
            "Fy_m1_N_coupled", "y_base_m_coupled"} <= set(df.columns)
    bolt = ["--support", "b1: x=-0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m",
            "--support", "b2: x=0.4m, y=0m, k_axial=2e8N/m, k_shear=1e8N/m"]
    args = parser.parse_args(["foundation", "slider_crank", "--t-end", "0.05s", "--coupled",
                              "--mass", "50kg", "--inertia", "2kg*m^2", *bolt])
    with pytest.raises(ModelError, match="--coupled needs isolators"):
        cli.run(args)
    args = parser.parse_args(["foundation", "slider_crank", "--t-end", "0.05s", "--bed", "x",
                              "--mass", "50kg", "--inertia", "2kg*m^2", *bolt])
    with pytest.raises(ModelError, match="--bed goes with --coupled"):
        cli.run(args)


def test_a_pin_whose_angle_is_used_is_not_turned_round():
    """The crank as the parent of its pin: turning the pin round would flip the sign of
    the angle its rotary spring reads; then the driven angle cannot move onto the base."""
    m = crank_and_bar()
    m.joints["O"] = type(m.joints["O"])("O", "crank", "ground")
    with pytest.warns(FloorFrameWarning):
        mm = mounted(m, MOUNTS)
    assert (mm.joints["O"].parent, mm.joints["O"].child) == ("base", "crank")
    m.add(RotarySpring("k", "O", stiffness=10.0))
    with pytest.raises(ModelError, match="drive 'motor'"):
        mounted(m, MOUNTS)
