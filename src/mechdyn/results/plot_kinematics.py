"""Plot of a kinematic sweep: the guided points' travel, velocity and acceleration."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from .animate import _trace_spec
from .figure import figure as _figure
from .figure import save as _save
from .table import deg_or_mm, rate_text

__all__ = ["plot_kinematic_sweep"]


# ---------------------------------------------------------------- kinematic sweep
def _label(body, name) -> str:
    return f"{body}.{name}" if isinstance(name, str) else f"{body}({name[0]:.4g}, {name[1]:.4g})"


def plot_kinematic_sweep(sweep, path, points: Iterable | None = None, *,
                         title: str | None = None, dpi: int = 120) -> Path:
    """Position, velocity and acceleration of points against the swept coordinate.

    Parameters
    ----------
    sweep : KinematicSweep
    path : str or Path
        PNG file to write.
    points : iterable of "BODY.POINT" or (body, point), optional
        Default: the guided point of every slider, else the named points of the
        last body.  Components that stay constant over the sweep are left out.
    title : str, optional
    dpi : int

    Returns
    -------
    Path
    """
    model = sweep.model
    if points is None:  # the sliders' guided points, else the named points of the last body
        mech, body = model.mechanism, model.body_names[-1]
        sliders = [(jn, mech.joints[jn]) for jn in model.pri.names]
        pts = [(j.child, j.child_point, f"{j.child} on {jn!r}") for jn, j in sliders
               if j.child != "ground"] or [
            (body, p, _label(body, p)) for p in list(mech.bodies[body].points) or ["com"]]
    else:
        pts = [(b, n, _label(b, n)) for b, n in (_trace_spec(model, p, "point") for p in points)]
    angle = sweep.over_is_angle
    xs, xunit = deg_or_mm(sweep.values, angle)
    fig, axes = _figure(3)
    scale = model.length_scale
    rows = [("position", "m"), ("velocity", "m/s"), ("acceleration", "m/s²")]
    for body, name, label in pts:
        data = sweep.point(body, name)
        for c, comp in enumerate("xy"):
            if len(sweep) == 0 or np.ptp(data[0][:, c]) <= 1e-12 * scale:
                continue  # a constant component (e.g. y of a horizontal slider)
            for ax, values in zip(axes, data, strict=True):  # position, velocity, acceleration
                ax.plot(xs, values[:, c], label=f"{comp} of {label}")
    for ax, (what, unit) in zip(axes, rows, strict=True):
        ax.set_ylabel(f"{what} ({unit})")
        ax.axhline(0.0, color="0.6", lw=0.6)
        if ax.lines[1:]:
            ax.legend(fontsize="small", loc="best")
    axes[-1].set_xlabel(f"{sweep.over} ({xunit})")
    rate = float(sweep.qdot[0, sweep.over_index]) if len(sweep) else 1.0
    fig.suptitle(title or f"{model.mechanism.name}: kinematics at constant {sweep.over}-rate "
                 f"{rate_text(rate, angle)}")
    if sweep.status != "success" and len(sweep):
        for ax in axes:
            ax.axvline(xs[-1], color="tab:red", ls="--", lw=1.0)
        axes[0].annotate("dead position", (xs[-1], 0.98), xycoords=("data", "axes fraction"),
                         color="tab:red", ha="right", va="top", fontsize="small")
    return _save(fig, path, dpi)
