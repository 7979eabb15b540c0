"""What the plots show (issue 14, item 13): units on every axis, the model and its speed in
the title, a full turn on 0..360 deg, dead centres, one force unit per axis, shaded modes
with a legend, chosen columns, the polar diagram of a joint force."""

import re

import numpy as np
import pytest

import mechdyn
from mechdyn.errors import ModelError
from mechdyn.results.plot import (
    plot_columns,
    plot_joint_force_polar,
    plot_kinematic_sweep,
    plot_kinetostatics,
    plot_trajectory,
)

UNIT = re.compile(r"[(\[]([^()\[\]]+)[)\]]\s*$")


@pytest.fixture(scope="module")
def crank_sweep():
    model = mechdyn.examples.load("slider_crank").compile()
    return mechdyn.sweep(model, "phi", np.deg2rad(np.linspace(-64.1, 295.9, 181)), speed=10.0)


@pytest.fixture(scope="module")
def press_forces():
    model = mechdyn.examples.load("toggle_press").compile()
    return mechdyn.kinetostatics(model, speed=4.0, values=np.linspace(0, 2 * np.pi, 121))


def _units_of(ax):
    """The units named in the labels of an axis's lines."""
    return {m.group(1) for ln in ax.lines if (m := UNIT.search(ln.get_label()))}


def test_kinematics_plot_has_units_title_full_turn_and_dead_centres(crank_sweep):
    fig = plot_kinematic_sweep(crank_sweep, None)
    title = fig.get_suptitle()
    assert "slider-crank" in title and "rpm" in title
    labels = {ax.get_ylabel() for ax in fig.axes}
    assert {"position (mm)", "link angle (deg)", "angular velocity ω (rad/s)",
            "angular acceleration α (rad/s²)"} <= labels
    for ax in fig.axes:
        assert UNIT.search(ax.get_ylabel()), ax.get_ylabel()
        assert ax.get_xlim() == pytest.approx((0.0, 360.0))
    assert [ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()] == ["phi (deg)"] * 2
    marks = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert "TDC" in marks and "BDC" in marks
    pos = next(ax for ax in fig.axes if ax.get_ylabel() == "position (mm)")
    y = pos.lines[0].get_ydata()
    assert y.max() == pytest.approx(210.0, rel=1e-6)  # lengths in mm
    angle = next(ax for ax in fig.axes if ax.get_ylabel() == "link angle (deg)")
    crank = next(ln for ln in angle.lines if ln.get_label() == "crank")
    assert np.all(np.diff(crank.get_ydata()) >= 0)  # continuous over the turn, in deg
    assert np.allclose(crank.get_ydata(), crank.get_xdata(), atol=1e-6)


def test_kinematics_plot_draws_the_coupler_curve_of_the_chosen_point():
    model = mechdyn.examples.load("four_bar").compile()
    sw = mechdyn.sweep(model, "phi", np.linspace(0, 2 * np.pi, 91))
    fig = plot_kinematic_sweep(sw, None, trace="coupler.P")
    curve = next(ax for ax in fig.axes if ax.get_xlabel() == "x (mm)")
    assert curve.get_ylabel() == "y (mm)"
    ln = next(ln for ln in curve.lines if "coupler curve of coupler.P" in ln.get_label())
    r = sw.point("coupler", "P")[0] * 1e3
    assert np.allclose(ln.get_xdata(), r[:, 0]) and np.allclose(ln.get_ydata(), r[:, 1])


def test_kinetostatics_plot_keeps_one_unit_per_axis(press_forces):
    fig = plot_kinetostatics(press_forces, None)
    assert "triangular toggle press" in fig.axes[0].get_title()
    assert "rpm" in fig.axes[0].get_title()
    for ax in fig.axes:
        unit = UNIT.search(ax.get_ylabel()).group(1)
        assert not ("N m" in ax.get_ylabel() and "kN" in ax.get_ylabel())
        assert _units_of(ax) <= {unit}, (ax.get_ylabel(), _units_of(ax))
    assert fig.axes[1].get_ylabel() == "joint force (kN)"  # 10 kN peaks
    assert fig.axes[2].get_xlim() == pytest.approx((0.0, 360.0))


def test_trajectory_plot_shades_the_modes_with_a_legend():
    model = mechdyn.examples.load("bolt_buffer").compile()
    tr = mechdyn.simulate(model, 0.5, t_eval=np.linspace(0, 0.5, 201), progress=False)
    fig = plot_trajectory(tr, None)
    assert fig.get_suptitle().startswith("bolt and buffer: simulation")
    for ax in fig.axes:
        assert UNIT.search(ax.get_ylabel()), ax.get_ylabel()
        assert len(ax.patches) >= 2  # the modes' spans
    legend = [t.get_text() for t in fig.axes[-1].get_legend().get_texts()]
    modes = [m for m in legend if m.startswith("mode: ")]
    assert len(modes) == len(tr.switching["modes"]) >= 2


def test_chosen_columns_are_plotted_in_engineering_units(crank_sweep):
    fig = plot_columns(crank_sweep, "phi_deg,omega_rod_rad_s,x_piston_com_m", None)
    df = crank_sweep.to_dataframe()
    got = {ln.get_label(): ln for ax in fig.axes for ln in ax.lines}
    assert set(got) == {"phi_deg", "omega_rod_rad_s", "x_piston_com_m"}
    assert [ax.get_ylabel() for ax in fig.axes] == ["phi (deg)", "omega_rod (rad/s)",
                                                   "x_piston_com (mm)"]
    x = got["x_piston_com_m"]
    xs = np.mod(np.rad2deg(crank_sweep.values), 360.0)
    k = np.argsort(xs, kind="stable")
    assert np.allclose(x.get_ydata()[1:-1], df["x_piston_com_m"].to_numpy()[k] * 1e3)
    assert fig.axes[-1].get_xlim() == pytest.approx((0.0, 360.0))
    with pytest.raises(ModelError, match="unknown column 'nope_m'; valid column names: .*'phi"):
        plot_columns(crank_sweep, ["phi_deg", "nope_m"], None)
    with pytest.raises(ModelError, match=r"column 'a_m'; .*'phi_deg'.*\(also unknown: 'b_N'\)"):
        plot_columns(crank_sweep, ["a_m", "phi_deg", "b_N"], None)
    with pytest.raises(ModelError, match="no columns given; valid column names: .*'phi_deg'"):
        plot_columns(crank_sweep, " , ", None)


def test_polar_plot_draws_the_joint_force_of_the_record(press_forces):
    fig = plot_joint_force_polar(press_forces, "C")
    ax = fig.axes[0]
    assert ax.name == "polar"
    line = ax.lines[0]
    assert "kN" in line.get_label()
    theta, r = line.get_xdata(), line.get_ydata() * 1e3
    F = press_forces.reactions["C"]
    assert np.allclose(r * np.cos(theta), F[:, 0], atol=1e-6 * np.abs(F).max())
    assert np.allclose(r * np.sin(theta), F[:, 1], atol=1e-6 * np.abs(F).max())
    assert "triangular toggle press" in ax.get_title() and "'C'" in ax.get_title()
    with pytest.raises(ModelError, match="unknown joint"):
        plot_joint_force_polar(press_forces, "nowhere")
