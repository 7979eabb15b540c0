"""What the animation draws beyond the links (issue 14, item 15): larger frames, the names
of bodies and joints, springs, stops, loads and joint forces."""

import numpy as np
import pytest
from matplotlib.patches import FancyArrowPatch
from matplotlib.text import Text
from PIL import Image

import mechdyn
from mechdyn.model.constraints import point_position
from mechdyn.results.animate import _zigzag, animate, frame_geometry, snapshot


@pytest.fixture(scope="module")
def bolt_run():
    model = mechdyn.examples.load("bolt_buffer").compile()
    return mechdyn.simulate(model, 0.3, t_eval=np.linspace(0.0, 0.3, 31), progress=False)


@pytest.fixture(scope="module")
def press_forces():
    model = mechdyn.examples.load("toggle_press").compile()
    return mechdyn.kinetostatics(model, speed=4.0, values=np.linspace(0, 2 * np.pi, 25))


def _texts(fig):
    return {t.get_text() for t in fig.findobj(Text)}


def test_frames_are_large_and_name_the_bodies_and_joints(press_forces, tmp_path):
    out = animate(press_forces, tmp_path / "press.gif", frames=3)
    with Image.open(out) as im:
        assert im.size[0] == 900 and im.size[1] >= 450
    fig = snapshot(press_forces, None, 5)
    names = _texts(fig)
    model = press_forces.model
    assert set(model.body_names) <= names
    assert {"A", "B", "C", "D", "E", "F"} <= names  # the revolutes
    assert "working_load" in names  # the load
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x (mm)" and ax.get_ylabel() == "y (mm)"


def test_label_of_a_body_sits_on_the_body(press_forces):
    fig = snapshot(press_forces, None, 7)
    label = next(t for t in fig.axes[0].texts if t.get_text() == "crank")
    g = frame_geometry(press_forces, 7)
    assert np.allclose(label.get_position(), g["bodies"]["crank"][0].mean(axis=0))
    assert "crank" not in _texts(snapshot(press_forces, None, 7, labels=False))


def test_springs_and_stops_are_drawn_where_they_are(bolt_run):
    model = bolt_run.model
    i = 20
    g = frame_geometry(bolt_run, i)
    assert set(g["springs"]) == {"drive", "buffer_spring"}
    ends = g["springs"]["buffer_spring"][0]
    x = bolt_run.x[i:i + 1]
    assert np.allclose(ends[0], point_position(model, x, "ground", "buffer_seat")[0])
    assert np.allclose(ends[1], point_position(model, x, "buffer", (0.0, 0.02))[0])
    assert set(g["stops"]) == {"buffer_stops@lower", "buffer_stops@upper", "bolt_rear@lower"}
    bar = g["stops"]["bolt_rear@lower"][0]
    j = model.mechanism.joints["bolt_guide"]
    guide0 = point_position(model, x, j.parent, j.parent_point)[0]
    # the bar crosses the guide at travel -20 mm
    assert np.allclose(bar.mean(axis=0), guide0 + [-0.02, 0.0], atol=1e-12)
    fig = snapshot(bolt_run, None, i)
    lines = {tuple(np.round(np.column_stack(ln.get_data()).ravel(), 12)) for ln in
             fig.axes[0].lines}
    assert tuple(np.round(_zigzag(*ends, g["size"]).ravel(), 12)) in lines
    assert tuple(np.round(bar.ravel(), 12)) in lines
    legend = {t.get_text() for t in fig.axes[0].get_legend().get_texts()}
    assert {"spring", "stop"} <= legend


def test_loads_and_joint_forces_are_arrows(press_forces):
    i = 10
    g = frame_geometry(press_forces, i)
    arrow = g["reactions"]["C"][0]
    F = press_forces.reactions["C"][i]
    assert np.allclose(arrow[0], press_forces.joint_points["C"][i])
    assert np.allclose(arrow[1] - arrow[0], g["force_scale"] * F)
    load = g["loads"]["working_load"][0]
    assert np.hypot(*(load[1] - load[0])) == pytest.approx(4 * g["size"])
    fig = snapshot(press_forces, None, i)
    arrows = [p for p in fig.axes[0].patches if isinstance(p, FancyArrowPatch)]
    assert len(arrows) == len(g["reactions"]) + len(g["loads"])
    legend = {t.get_text() for t in fig.axes[0].get_legend().get_texts()}
    assert {"load", "joint force"} <= legend
