"""Plot of a kinematic sweep: the guided points' travel, velocity and acceleration, the links'
angles, angular velocities and accelerations, the coupler curve of a point, the dead centres."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..kinematics.records import four_bar_loops
from .figure import mosaic as _mosaic
from .figure import save as _save
from .frame_geometry import trace_spec
from .plot_axes import model_name, speed_text, x_axis
from .table import deg_or_mm

__all__ = ["plot_kinematic_sweep"]


# ---------------------------------------------------------------- kinematic sweep
def _label(body, name) -> str:
    return f"{body}.{name}" if isinstance(name, str) else f"{body}({name[0]:.4g}, {name[1]:.4g})"


def _default_trace(model):
    """A coupler point of the first four-bar loop that is no joint point, else None."""
    mech = model.mechanism
    for loop in four_bar_loops(model):
        joined = {j.child_point if j.child == loop.coupler else j.parent_point
                  for j in mech.joints.values() if loop.coupler in (j.parent, j.child)}
        for p in mech.bodies[loop.coupler].points:
            if p not in joined:
                return loop.coupler, p
    return None


def plot_kinematic_sweep(sweep, path=None, points: Iterable | None = None, *,
                         trace=None, title: str | None = None, dpi: int = 120):
    """Kinematics against the swept coordinate, and the coupler curve of a point.

    Left: position (mm), velocity (m/s) and acceleration (m/s^2) of points; right: angle
    (deg), angular velocity (rad/s) and angular acceleration (rad/s^2) of every link that
    turns; below: the path of ``trace`` in the plane (mm).  The sliders' dead centres (TDC,
    BDC) are marked; a full turn of an angle runs 0..360 deg.  The title names the model
    and the speed.

    Parameters
    ----------
    sweep : KinematicSweep
    path : str or Path, optional
        Image file to write; None returns the figure.
    points : iterable of "BODY.POINT" or (body, point), optional
        Default: the guided point of every slider, else the named points of the
        last body.  Components that stay constant over the sweep are left out.
    trace : "BODY.POINT" or (body, point), optional
        The point whose coupler curve is drawn (default: a coupler point of a four-bar
        loop, if there is one; ``False`` for none).
    title : str, optional
    dpi : int

    Returns
    -------
    Path, or Figure when ``path`` is None
    """
    model = sweep.model
    mech = model.mechanism
    if points is None:  # the sliders' guided points, else the named points of the last body
        body = model.body_names[-1]
        sliders = [(jn, mech.joints[jn]) for jn in model.pri.names]
        pts = [(j.child, j.child_point, f"{j.child} on {jn!r}") for jn, j in sliders
               if j.child != "ground"] or [
            (body, p, _label(body, p)) for p in list(mech.bodies[body].points) or ["com"]]
    else:
        pts = [(b, n, _label(b, n)) for b, n in (trace_spec(model, p, "point") for p in points)]
    spec = (_default_trace(model) if trace is None else
            None if trace is False else trace_spec(model, trace, "trace"))
    turning = [b for b in model.body_names
               if len(sweep) and np.ptp(sweep.angular(b)[0]) > 1e-9]
    layout = [["position", "angle"], ["velocity", "omega"], ["acceleration", "alpha"]]
    if not turning:
        layout = [row[:1] for row in layout]
    if spec is not None:
        layout.append(["curve"] * len(layout[0]))
    width = 12.0 if turning else 8.0
    fig, axd = _mosaic(layout, width, 2.6 * 3 + (4.0 if spec is not None else 0.0),
                       height_ratios=[1, 1, 1] + ([1.6] if spec is not None else []))
    series = [axd[r[0]] for r in layout[:3]] + ([axd[r[1]] for r in layout[:3]]
                                                 if turning else [])
    for ax in series[1:]:
        ax.sharex(series[0])
    xa = x_axis(sweep)
    scale = model.length_scale
    for body, name, label in pts:
        data = sweep.point(body, name)
        for c, comp in enumerate("xy"):
            if len(sweep) == 0 or np.ptp(data[0][:, c]) <= 1e-12 * scale:
                continue  # a constant component (e.g. y of a horizontal slider)
            for key, values, f in zip(("position", "velocity", "acceleration"), data,
                                      (1e3, 1.0, 1.0), strict=True):
                axd[key].plot(xa.x, xa.y(values[:, c]) * f, label=f"{comp} of {label}")
    for b in turning:
        theta, omega, alpha = sweep.angular(b)
        theta, omega, alpha = xa.angle(theta), xa.y(omega), xa.y(alpha)
        for key, values in zip(("angle", "omega", "alpha"), (np.rad2deg(theta), omega, alpha),
                               strict=True):
            axd[key].plot(xa.x, values, label=b)
    for key, what in (("position", "position (mm)"), ("velocity", "velocity (m/s)"),
                      ("acceleration", "acceleration (m/s²)"), ("angle", "link angle (deg)"),
                      ("omega", "angular velocity ω (rad/s)"),
                      ("alpha", "angular acceleration α (rad/s²)")):
        if key in axd:
            ax = axd[key]
            ax.set_ylabel(what)
            if key != "position" and key != "angle":
                ax.axhline(0.0, color="0.6", lw=0.6)
            if ax.lines:
                ax.legend(fontsize="small", loc="best")
    for row in layout[:3]:
        for key in row:
            axd[key].tick_params(labelbottom=False)
    for key in layout[2]:
        axd[key].tick_params(labelbottom=True)
        xa.setup(axd[key])
    _dead_centres(sweep, xa, series)
    if spec is not None:
        _coupler_curve(axd["curve"], sweep, spec)
    head = title or " ".join(filter(None, (f"{model_name(sweep)}: kinematics",
                                           speed_text(sweep))))
    fig.suptitle(head)
    if sweep.status != "success" and len(sweep):
        end = xa.at(float(deg_or_mm(sweep.values[-1], sweep.over_is_angle)[0]))
        for ax in series:
            ax.axvline(end, color="tab:red", ls="--", lw=1.0)
        series[0].annotate("dead position", (end, 0.98), xycoords=("data", "axes fraction"),
                           color="tab:red", ha="right", va="top", fontsize="small")
    return _save(fig, path, dpi)


def _dead_centres(sweep, xa, axes) -> None:
    """Vertical lines at the sliders' dead centres, labelled TDC / BDC on the top panels."""
    if not len(sweep):
        return
    for d in sweep.summary().dead_centres:
        at = xa.at(float(deg_or_mm(d.at, sweep.over_is_angle)[0]))
        for ax in axes:
            ax.axvline(at, color="0.35", ls=":", lw=1.0)
        for ax in axes[::3]:  # the top panel of each column
            ax.annotate(d.label, (at, 1.0), xycoords=("data", "axes fraction"), ha="center",
                        va="bottom", fontsize="small", color="0.25")


def _coupler_curve(ax, sweep, spec) -> None:
    """The path of a point in the plane (mm), its first position marked."""
    body, point = spec
    r = sweep.point(body, point)[0] * 1e3
    ax.plot(r[:, 0], r[:, 1], color="tab:purple", label=f"coupler curve of {_label(body, point)}")
    ax.plot(r[:1, 0], r[:1, 1], "o", color="tab:purple", label="first position")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.legend(fontsize="small", loc="best")
