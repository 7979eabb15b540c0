"""Plot of a kinetostatic analysis: driving torque, pin forces, shaking force and moment."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .figure import figure as _figure
from .figure import save as _save
from .table import deg_or_mm

__all__ = ["plot_kinetostatics"]


def plot_kinetostatics(record, path, *, joints: Sequence[str] | None = None,
                       dpi: int = 120) -> Path:
    """Write a three-panel figure of a :class:`~mechdyn.dynamics.kinetostatics.Kinetostatics`.

    Panels: (1) driving torque/force of every driven coordinate; (2) resultant
    reaction |R| of the chosen joints; (3) shaking force components and
    magnitude, with the shaking moment on a second axis.

    Parameters
    ----------
    record : Kinetostatics
    path : str or Path
        Image file (format from the suffix, e.g. ``.png``).
    joints : sequence of str, optional
        Joints whose forces are drawn (default: all joints).
    dpi : int

    Returns
    -------
    Path
        The file written.
    """
    names = list(record.reactions) if joints is None else list(joints)
    xv, xunit = deg_or_mm(record.values, record.over_is_angle)
    fig, axes = _figure(3, height=3.0)
    ax = axes[0]
    for c in record.driven:
        sym, unit = record._drive_unit(c)
        ax.plot(xv, record.driving[c], label=f"{sym} drive {c} ({'N m' if unit == 'Nm' else unit})")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_ylabel("driving torque / force")
    ax.legend(loc="best", fontsize="small")
    title = getattr(getattr(record.model, "mechanism", None), "name", "mechanism")
    ax.set_title(f"{title}: kinetostatics ({record.status})")
    ax = axes[1]
    for j in names:
        ax.plot(xv, record.force_magnitude(j), label=f"|F {j}|")
    ax.set_ylabel("joint force (N)")
    ax.legend(loc="best", fontsize="small", ncol=2)
    ax = axes[2]
    ff = record.frame_force
    ax.plot(xv, ff[:, 0], label="Fx frame")
    ax.plot(xv, ff[:, 1], label="Fy frame")
    ax.plot(xv, np.hypot(ff[:, 0], ff[:, 1]), "k", lw=1.0, label="|F| frame")
    ax.set_ylabel("shaking force (N)")
    ax.set_xlabel(f"{record.over} ({xunit})")
    ax2 = ax.twinx()
    ax2.plot(xv, record.frame_moment, "--", color="tab:red", lw=1.0, label="M frame")
    ax2.set_ylabel("shaking moment (N m)", color="tab:red")
    ax.legend(handles=ax.lines + ax2.lines, loc="best", fontsize="small")
    return _save(fig, path, dpi)
