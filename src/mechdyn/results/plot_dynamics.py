"""Plots of a simulated motion: q, q' and q'' against time, with units."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figure import figure as _figure
from .figure import save as _save
from .plot_axes import XAxis, model_name, shade_modes, speed_text

__all__ = ["plot_trajectory"]


def plot_trajectory(traj, path=None, *, coordinates=None, degrees: bool = True,
                    energy: bool = True, dpi: int = 120, title: str | None = None) -> Path:
    """Plot q, q' and q'' of a :class:`~mechdyn.results.trajectory.Trajectory` against time.

    Parameters
    ----------
    traj : Trajectory
    path : str or Path, optional
        Image file to write (format from the suffix, e.g. ``.png``, ``.svg``); None
        returns the figure.
    coordinates : sequence of str, optional
        Coordinates to plot (default: all).
    degrees : bool
        Angles in deg, deg/s, deg/s^2 (else rad, rad/s, rad/s^2).
    energy : bool
        Add a panel with T, U, W_nc and the balance T + U - W_nc (J).
    dpi : int
    title : str, optional

    Returns
    -------
    Path, or Figure when ``path`` is None

    Notes
    -----
    Every axis names its unit; angles are in deg, travels in mm (on a right-hand axis when
    they share a panel with angles), the frame force of a variable-structure run in kN.
    The title names the model, the mean speed of the first coordinate and the integrator;
    the modes of a variable-structure run are shaded and named in the legend of the last
    panel.  Draw a run sampled from the dense output (``t_eval``; the command line's default
    ``--samples 1001``): one sample per integrator step can be too coarse for a smooth curve.
    """
    names = list(coordinates) if coordinates is not None else list(traj.coordinate_names)
    idx = [traj.coordinate_names.index(n) for n in names]
    show_energy = bool(energy and traj.energy and traj.t.size)
    vs = traj.switching if traj.t.size else None
    rows = 3 + (1 if show_energy else 0) + (1 if vs else 0)
    fig, axes = _figure(rows, height=2.4)
    t = traj.t
    is_angle = [traj.coordinate_is_angle[k] if traj.coordinate_is_angle else True for k in idx]
    au = "deg" if degrees else "rad"
    fa = np.rad2deg(1.0) if degrees else 1.0
    # lengths (travels) in mm on a right-hand axis when angles share the panel
    twins = [ax.twinx() if (any(is_angle) and not all(is_angle)) else ax for ax in axes[:3]]
    panels = (("coordinate", "", "", traj.q), ("rate", "'", "/s", traj.qdot),
              ("acceleration", "''", "/s^2", traj.qddot))
    for n, (k, name, ang) in enumerate(zip(idx, names, is_angle, strict=True)):
        f, u = (fa, au) if ang else (1e3, "mm")
        for ax, (_, tick, per, data) in zip(axes[:3] if ang else twins, panels, strict=True):
            ax.plot(t, data[:, k] * f, color=f"C{n}", label=f"{name}{tick} [{u}{per}]")
    for ax, twin, (what, _, per, _) in zip(axes[:3], twins, panels, strict=True):
        if twin is ax:
            ax.set_ylabel(f"{what} [{au if any(is_angle) else 'mm'}{per}]")
        else:
            ax.set_ylabel(f"{what}: angles [{au}{per}]")
            twin.set_ylabel(f"{what}: travels [mm{per}]")
            ax.legend(handles=ax.lines + twin.lines, loc="best", fontsize="small")
    if show_energy:
        for key, style, label in (("kinetic", "-", "T"), ("potential", "-", "U"),
                                  ("work_nc", "-", "W_nc"), ("balance", "k--", "T + U - W_nc")):
            axes[3].plot(t, traj.energy[key], style, label=f"{label} [J]")
        axes[3].set_ylabel("energy [J]")
    if vs:
        ax = axes[-1]
        frame = np.asarray(vs["frame_force"], float)
        ax.plot(t, frame[:, 0] * 1e-3, label="Fx frame [kN]")
        ax.plot(t, frame[:, 1] * 1e-3, label="Fy frame [kN]")
        ax.set_ylabel("force on the frame [kN]")
        shade_modes(axes, XAxis(t, "t [s]"), vs["mode_index"], vs["modes"], legend_ax=ax)
    for ax in axes:
        if ax.get_legend() is None:
            ax.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("t [s]")
    head = title or " ".join(filter(None, (
        f"{model_name(traj)}: simulation", speed_text(traj),
        f"- {traj.stats.integrator} ({traj.stats.formulation})")))
    if not traj.success:
        head += f" - stopped: {traj.status}"
    fig.suptitle(head)
    return _save(fig, path, dpi)
