"""Bodies without a pose: placed by the assembly from their joints, the initial
coordinates and the declared assembly mode (issue 14, item 16).

The poses found are checked against closed forms (circle intersections of the
four-bar, the slider-crank's piston position) and against the bundled examples,
whose sketch poses were computed by hand.
"""

import json
import math
import re

import numpy as np
import pytest

import mechdyn
from mechdyn import Mechanism, examples
from mechdyn.cli import main
from mechdyn.errors import ModelError

O, C = np.array([0.0, 0.0]), np.array([0.1, 0.0])  # four_bar.toml: frame 100 mm
CRANK, COUPLER, ROCKER = 0.04, 0.12, 0.08
SC_MODE = ('\n[[assembly]]\nname = "piston"\npoints = ["ground.O", "crank.A", "rod.B"]\n'
           'turn = "{}"\n')


def without_poses(name: str) -> str:
    """A bundled example with every ``pose = ...`` line deleted."""
    text = examples.path(name).read_text(encoding="utf-8")
    out = re.sub(r"(?m)^pose = .*\n", "", text)
    assert out.count("pose =") == 0 and text.count("pose =") >= 3
    return out


def circle_intersections(a, ra, b, rb):
    """The two points at distance ra from a and rb from b (closed form)."""
    d = np.linalg.norm(b - a)
    x = (d**2 + ra**2 - rb**2) / (2 * d)
    h = math.sqrt(ra**2 - x**2)
    u = (b - a) / d
    n = np.array([-u[1], u[0]])
    return a + x * u + h * n, a + x * u - h * n


def world(model, x, body, point):
    k = model.body_index(body)
    th = x[3 * k + 2]
    p = model.point_local(body, point)
    return x[3 * k:3 * k + 2] + [math.cos(th) * p[0] - math.sin(th) * p[1],
                                 math.sin(th) * p[0] + math.cos(th) * p[1]]


def four_bar_B(turn: str, phi: float):
    """Point B of the four-bar by circle intersection: left of A -> C for "right"."""
    A = O + CRANK * np.array([math.cos(phi), math.sin(phi)])
    b1, b2 = circle_intersections(A, COUPLER, C, ROCKER)
    cross = lambda B: (B - A)[0] * (C - B)[1] - (B - A)[1] * (C - B)[0]  # noqa: E731
    return b1 if (cross(b1) < 0) == (turn == "right") else b2


def test_four_bar_without_poses_assembles_as_the_sketch():
    posed = mechdyn.loads(examples.path("four_bar").read_text(), "four_bar.toml").compile()
    found = mechdyn.loads(without_poses("four_bar"), "four_bar.toml").compile()
    np.testing.assert_allclose(found.x0, posed.x0, rtol=0, atol=1e-9)
    assert set(found.found_poses) == {"crank", "coupler", "rocker"}
    assert posed.found_poses == {}
    B = four_bar_B("right", math.radians(60))
    np.testing.assert_allclose(world(found, found.x0, "coupler", "B"), B, atol=1e-12)
    np.testing.assert_allclose(world(found, found.x0, "rocker", "B"), B, atol=1e-12)
    assert found.found_poses["crank"][2] == pytest.approx(math.radians(60), abs=1e-12)


@pytest.mark.parametrize("phi_deg", [60.0, 200.0])
def test_the_other_assembly_mode_gives_the_mirrored_branch(phi_deg):
    text = without_poses("four_bar").replace('phi = "60 deg"', f'phi = "{phi_deg} deg"')
    right = mechdyn.loads(text).compile()
    left = mechdyn.loads(text.replace('turn = "right"', 'turn = "left"')).compile()
    phi = math.radians(phi_deg)
    A = O + CRANK * np.array([math.cos(phi), math.sin(phi)])
    Br, Bl = (world(m, m.x0, "coupler", "B") for m in (right, left))
    np.testing.assert_allclose(Br, four_bar_B("right", phi), atol=1e-12)
    np.testing.assert_allclose(Bl, four_bar_B("left", phi), atol=1e-12)
    u = (C - A) / np.linalg.norm(C - A)  # the mirror of B across the line A-C
    mirrored = A + 2 * np.dot(Br - A, u) * u - (Br - A)
    np.testing.assert_allclose(Bl, mirrored, atol=1e-12)


@pytest.mark.parametrize("turn, sign", [("right", 1.0), ("left", -1.0)])
def test_slider_crank_without_poses(turn, sign):
    text = without_poses("slider_crank") + SC_MODE.format(turn)
    model = mechdyn.loads(text).compile()
    r, ell, phi = 0.05, 0.16, math.radians(30)
    piston = r * math.cos(phi) + sign * math.sqrt(ell**2 - (r * math.sin(phi))**2)
    x = model.found_poses["piston"]
    assert x == pytest.approx((piston, 0.0, 0.0), abs=1e-12)
    if turn == "right":  # the bundled sketch is this branch
        posed = mechdyn.loads(examples.path("slider_crank").read_text()).compile()
        np.testing.assert_allclose(model.x0, posed.x0, rtol=0, atol=1e-9)


def test_two_branches_and_no_assembly_mode_is_a_named_error():
    with pytest.raises(ModelError) as err:
        mechdyn.loads(without_poses("slider_crank"), "sc.toml")
    msg = str(err.value)
    assert "2 assembly branches fit the joints at phi = 30 deg" in msg
    assert "no assembly mode is declared" in msg
    assert "branch 1: rod at" in msg and "branch 2: rod at" in msg
    assert "piston at (201.336 mm, 0 mm, 0 deg)" in msg  # r cos + sqrt(l^2 - r^2 sin^2)
    assert "piston at (-114.734 mm, 0 mm, 0 deg)" in msg
    hint = re.search(r'\[\[assembly\]\] points = (\[.*?\]) with turn = "(\w+)" \(branch 1\) '
                     r'or "(\w+)" \(branch 2\)', msg)
    assert hint, msg
    # the suggested mode, with either turn, loads the branch it names
    pistons = {}
    for turn, k in ((hint[2], 1), (hint[3], 2)):
        text = (without_poses("slider_crank")
                + f'\n[[assembly]]\nname = "m"\npoints = {hint[1]}\nturn = "{turn}"\n')
        x = mechdyn.loads(text).compile().found_poses["piston"][0]
        assert f"piston at ({1e3 * x:.6g} mm" in msg.split(f"branch {k}: ")[1].split(";")[0]
        pistons[k] = x
    assert pistons[1] != pytest.approx(pistons[2])


def python_four_bar(rocker_pose=None, turn=None):
    m = Mechanism("four-bar")
    m.add_ground({"O": (0.0, 0.0), "C": (0.1, 0.0)})
    m.add_body("crank", mass=0.2, points={"A": (CRANK, 0.0)})
    m.add_body("coupler", mass=0.5, points={"B": (COUPLER, 0.0)})
    m.add_body("rocker", mass=0.35, points={"B": (ROCKER, 0.0)}, pose=rocker_pose)
    m.add_revolute("O", "ground", "crank", "O")
    m.add_revolute("A", "crank", "coupler", "A")
    m.add_revolute("B", "coupler", "rocker", "B", "B")
    m.add_revolute("C", "ground", "rocker", "C")
    m.add_coordinate("phi", kind="angle", body="crank")
    m.set_initial(q={"phi": 1.0})
    if turn:
        m.add_assembly_mode("open", ("crank", "A"), ("coupler", "B"), ("ground", "C"), turn)
    return m


def test_python_api_and_a_rough_sketch_only_picks_the_branch():
    model = python_four_bar(turn="left").compile()
    assert list(model.found_poses) == ["crank", "coupler", "rocker"]
    np.testing.assert_allclose(world(model, model.x0, "coupler", "B"),
                               four_bar_B("left", 1.0), atol=1e-12)
    # no mode, a rough rocker pose (about 20 deg off) below the frame: the lower branch
    rough = python_four_bar(rocker_pose=(0.1, 0.0, math.radians(-90))).compile()
    B = world(rough, rough.x0, "rocker", "B")
    np.testing.assert_allclose(B, four_bar_B("left", 1.0), atol=1e-12)
    assert "rocker" not in rough.found_poses
    with pytest.raises(ModelError, match="no assembly mode is declared"):
        python_four_bar().compile()


def test_lock_without_offset_takes_it_at_the_initial_coordinates():
    m = Mechanism("two coaxial discs", gravity=(0.0, 0.0))
    m.add_body("d1", mass=3.0, inertia=0.2)
    m.add_body("d2", mass=1.0, inertia=0.05)
    m.add_revolute("O1", "ground", "d1")
    m.add_revolute("O2", "ground", "d2")
    m.add_coordinate("th1", kind="angle", body="d1")
    m.add_coordinate("th2", kind="angle", body="d2")
    m.add_lock("clutch", "d1", "d2", engaged=False)
    m.set_initial(q={"th1": 0.3, "th2": 0.5})
    model = m.compile()
    assert model.lock.angle[0] == pytest.approx(0.2, abs=1e-15)
    assert model.found_poses["d2"] == pytest.approx((0.0, 0.0, 0.5), abs=1e-15)


def test_check_prints_the_poses_found(tmp_path, capsys):
    path = tmp_path / "four_bar.toml"
    path.write_text(without_poses("four_bar"), encoding="utf-8")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "poses found" in out and "x [mm]" in out and "angle [deg]" in out
    row = next(line.split() for line in out.splitlines() if line.strip().startswith("rocker"))
    B = four_bar_B("right", math.radians(60))
    assert float(row[1]) == pytest.approx(100.0) and float(row[2]) == pytest.approx(0.0)
    assert float(row[3]) == pytest.approx(math.degrees(math.atan2(*(B - C)[::-1])), abs=1e-3)
    assert main(["check", str(path), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)["summary"]["poses_found"]
    assert found["coupler"]["x_mm"] == pytest.approx(20.0)
    assert main(["check", "four_bar"]) == 0
    assert "poses found" not in capsys.readouterr().out


@pytest.mark.parametrize("turn, sign", [("right", 1.0), ("left", -1.0)])
def test_a_travel_coordinate_places_the_piston_and_the_mode_the_crank(turn, sign):
    r, ell, s = 0.05, 0.16, 0.19
    m = Mechanism("slider-crank driven by its piston")
    m.add_ground({"O": (0.0, 0.0)})
    m.add_body("crank", mass=1.0, points={"A": (r, 0.0)})
    m.add_body("rod", mass=1.0, points={"B": (ell, 0.0)})
    m.add_body("piston", mass=1.0)
    m.add_revolute("O", "ground", "crank", "O")
    m.add_revolute("A", "crank", "rod", "A")
    m.add_revolute("B", "rod", "piston", "B")
    m.add_prismatic("cylinder", "ground", "piston", "O")
    m.add_coordinate("s", kind="travel", joint="cylinder")
    m.add_assembly_mode("crank", ("ground", "O"), ("crank", "A"), ("rod", "B"), turn)
    m.set_initial(q={"s": s})
    found = m.compile().found_poses
    assert found["piston"] == pytest.approx((s, 0.0, 0.0), abs=1e-12)
    phi = math.acos((r**2 + s**2 - ell**2) / (2 * r * s))  # law of cosines
    # O -> A -> B turns right with the crank above the axis (B ahead on the axis)
    assert found["crank"][2] == pytest.approx(sign * phi, abs=1e-12)


def test_a_rough_pose_of_one_body_picks_the_branch_of_a_six_bar():
    text = examples.path("toggle_press").read_text(encoding="utf-8")
    posed = mechdyn.loads(text).compile()
    rough = re.sub(r'(?m)^pose = \["185 mm", "-206.828 mm", "0 deg"\]',
                   'ROUGH = ["190 mm", "-150 mm", "0 deg"]', text)
    rough = re.sub(r"(?m)^pose = .*\n", "", rough).replace("ROUGH =", "pose =")
    assert rough.count("pose =") == 1
    model = mechdyn.loads(rough).compile()
    assert "slider" not in model.found_poses and len(model.found_poses) == 4
    d = model.x0 - posed.x0
    d[2::3] = np.angle(np.exp(1j * d[2::3]))
    assert np.max(np.abs(d)) < 1e-9
    with pytest.raises(ModelError, match="4 assembly branches fit"):
        mechdyn.loads(re.sub(r"(?m)^pose = .*\n", "", text))
