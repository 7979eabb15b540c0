"""Plots of a simulated motion: q, q' and q'' against time, with units."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["plot_trajectory"]


def plot_trajectory(traj, path, *, coordinates=None, degrees: bool = True,
                    energy: bool = True, dpi: int = 120, title: str | None = None) -> Path:
    """Plot q, q' and q'' of a :class:`~mechdyn.results.trajectory.Trajectory` against time.

    Parameters
    ----------
    traj : Trajectory
    path : str or Path
        Image file to write (format from the suffix, e.g. ``.png``, ``.svg``).
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
    Path
        The file written.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    names = list(coordinates) if coordinates is not None else list(traj.coordinate_names)
    idx = [traj.coordinate_names.index(n) for n in names]
    show_energy = bool(energy and traj.energy and traj.t.size)
    rows = 3 + (1 if show_energy else 0)
    fig, axes = plt.subplots(rows, 1, figsize=(8.0, 2.4 * rows), sharex=True,
                             constrained_layout=True)
    t = traj.t
    for k, name in zip(idx, names, strict=True):
        ang = traj.coordinate_is_angle[k] if traj.coordinate_is_angle else True
        f = np.rad2deg(1.0) if (ang and degrees) else 1.0
        u = ("deg" if degrees else "rad") if ang else "m"
        axes[0].plot(t, traj.q[:, k] * f, label=f"{name} [{u}]")
        axes[1].plot(t, traj.qdot[:, k] * f, label=f"{name}' [{u}/s]")
        axes[2].plot(t, traj.qddot[:, k] * f, label=f"{name}'' [{u}/s^2]")
    axes[0].set_ylabel("coordinate")
    axes[1].set_ylabel("rate")
    axes[2].set_ylabel("acceleration")
    if show_energy:
        e = traj.energy
        ax = axes[3]
        ax.plot(t, e["kinetic"], label="T [J]")
        ax.plot(t, e["potential"], label="U [J]")
        ax.plot(t, e["work_nc"], label="W_nc [J]")
        ax.plot(t, e["balance"], "k--", label="T + U - W_nc [J]")
        ax.set_ylabel("energy [J]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("t [s]")
    head = title or f"simulation: {traj.stats.get('integrator', '')} " \
                    f"({traj.stats.get('formulation', '')})"
    if not traj.success:
        head += f" - stopped: {traj.status}"
    fig.suptitle(head)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
