"""Animations and snapshots: the drawn coordinates are the record's point positions."""

import numpy as np
import pytest
from PIL import Image

import mechdyn
from mechdyn.errors import MechdynError, ModelError
from mechdyn.model.constraints import point_position
from mechdyn.results.animate import (
    _Scene,
    animate,
    frame_geometry,
    frame_indices,
    snapshot,
)


@pytest.fixture(scope="module")
def crank_sweep():
    mech = mechdyn.examples.load("slider_crank")
    return mechdyn.sweep(mech, "phi", np.linspace(0.0, 2 * np.pi, 37))


@pytest.fixture(scope="module")
def four_bar_sweep():
    return mechdyn.sweep(mechdyn.examples.load("four_bar"), "phi",
                         np.linspace(0.0, 2 * np.pi, 25))


def _joint_point(model, name):
    j = model.mechanism.joints[name]
    if j.child != "ground":
        return j.child, j.child_point
    return j.parent, j.parent_point


def test_drawn_joint_points_are_the_point_positions_of_the_record(four_bar_sweep):
    sw = four_bar_sweep
    m = sw.model
    g = frame_geometry(sw, trace="coupler.P")
    assert set(g["revolutes"]) == set(m.rev.names)
    for name, drawn in g["revolutes"].items():
        body, pt = _joint_point(m, name)
        assert np.allclose(drawn, point_position(m, sw.x, body, pt), atol=1e-14)
    assert np.allclose(g["trace"], point_position(m, sw.x, "coupler", "P"), atol=1e-14)
    (x0, x1), (y0, y1) = g["limits"]  # the whole motion fits inside the axis limits
    drawn = np.concatenate([a.reshape(-1, 2) for a in g["bodies"].values()] + [g["trace"]])
    assert x0 < drawn[:, 0].min() and drawn[:, 0].max() < x1
    assert y0 < drawn[:, 1].min() and drawn[:, 1].max() < y1
    # each body outline passes through every named point of the body
    for b in m.body_names:
        for p in m.mechanism.bodies[b].points:
            r = point_position(m, sw.x, b, p)
            d = np.min(np.linalg.norm(g["bodies"][b] - r[:, None, :], axis=-1), axis=1)
            assert np.max(d) < 1e-14
    # ground anchors sit at the ground pivots
    assert set(g["anchors"]) == {"O", "C"}
    for name, p in g["anchors"].items():
        j = m.mechanism.joints[name]
        ref = j.parent_point if j.parent == "ground" else j.child_point
        assert np.allclose(p, point_position(m, sw.x[0], "ground", ref))


def test_artists_of_the_first_frame_show_the_joint_positions(crank_sweep):
    sw = crank_sweep
    m = sw.model
    scene = _Scene(sw)
    scene.update(0, "first")
    xs, ys = scene.revolutes.get_data()
    drawn = np.column_stack([xs, ys])
    want = np.array([point_position(m, sw.x[0], *_joint_point(m, j)) for j in m.rev.names])
    assert np.allclose(drawn, want, atol=1e-14)
    # the piston block is centred on the guided point, the guide line on the x axis
    block = scene.bodies["piston"][0].get_xy()[:4]
    assert np.allclose(block.mean(axis=0), point_position(m, sw.x[0], "piston", "com"))
    gx, gy = scene.guides["cylinder"].get_data()
    assert np.allclose(gy, 0.0) and min(gx) < 0.11 and max(gx) > 0.21  # the whole stroke


def test_gif_has_the_requested_number_of_frames(crank_sweep, tmp_path):
    path = animate(crank_sweep, tmp_path / "crank.gif", frames=12, fps=10, trace="rod.com")
    with Image.open(path) as im:
        assert im.format == "GIF"
        assert im.n_frames == 12
        assert im.info["duration"] == 100


def test_frames_of_a_trajectory_are_equally_spaced_in_time():
    t = np.array([0.0, 0.001, 0.002, 0.01, 0.011, 0.02, 0.05, 0.1])
    traj = mechdyn.Trajectory(t=t, q=np.zeros((8, 1)), qdot=np.zeros((8, 1)),
                              qddot=np.zeros((8, 1)), x=np.zeros((8, 3)), xdot=np.zeros((8, 3)),
                              model=object())
    idx = frame_indices(traj, 3)
    assert list(idx) == [0, 6, 7]  # nearest samples to t = 0, 0.05, 0.1 s


def test_snapshot_writes_a_png_and_bad_outputs_are_clear_errors(crank_sweep, tmp_path):
    p = snapshot(crank_sweep, tmp_path / "s.png", -1)
    assert p.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(MechdynError, match=r"\.gif"):
        animate(crank_sweep, tmp_path / "motion.avi")
    with pytest.raises(ModelError, match="valid point names"):
        animate(crank_sweep, tmp_path / "m.gif", trace="rod.Q")
    with pytest.raises(ModelError, match="outside"):
        snapshot(crank_sweep, tmp_path / "t.png", 37)
