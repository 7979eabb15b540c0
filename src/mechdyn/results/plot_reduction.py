"""Plots of the reduction method's records: reduced quantities, steady cycle, start-up.

Drawn on matplotlib's Agg canvas (no screen needed, pyplot untouched); each
function takes a record and a PNG path and returns the path written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figure import figure as _figure
from .figure import save as _save
from .table import deg_or_mm

__all__ = ["plot_reduction", "plot_steady_cycle", "plot_startup", "plot_motor"]


def plot_reduction(red, path, *, title: str | None = None, dpi: int = 120) -> Path:
    """J_red, dJ_red/dphi and M_red (drive and forces) over the positions of a
    :class:`~mechdyn.reduction.reduce.Reduction`.

    Parameters
    ----------
    red : Reduction
    path : str or Path
        PNG file to write.
    title : str, optional
    dpi : int

    Returns
    -------
    Path
    """
    x, unit = deg_or_mm(red.position, red.is_angle or red.link is not None)
    xlabel = f"angle of {red.link} ({unit})" if red.link else f"{red.coordinate} ({unit})"
    iu, tu = ("kg m$^2$", "N m") if unit == "deg" else ("kg", "N")
    fig, ax = _figure(3, height=2.4)
    ax[0].plot(x, red.J_red, label="$J_{red}$ (mechanism)")
    if np.any(red.J_extra):
        ax[0].plot(x, red.J_total, "--", label="$J_{red} + J_{extra}$")
    ax[0].set_ylabel(f"reduced inertia ({iu})")
    ax[0].legend(loc="best", fontsize="small")
    ax[1].plot(x, red.dJ_red_dphi, color="C1")
    ax[1].set_ylabel(f"$dJ_{{red}}/d\\varphi$ ({iu})")
    ax[2].plot(x, red.M_red, label="$M_{red}$ (all)")
    ax[2].plot(x, red.M_forces, ":", label="forces")
    if np.any(red.M_drive):
        ax[2].plot(x, red.M_drive, "--", label="drive")
    ax[2].set_ylabel(f"reduced torque ({tu})")
    ax[2].legend(loc="best", fontsize="small")
    ax[2].set_xlabel(xlabel)
    ax[0].set_title(title or f"reduction to {red.link or red.coordinate}")
    return _save(fig, path, dpi)


def plot_steady_cycle(cycle, path, *, title: str | None = None, dpi: int = 120) -> Path:
    """Speed and reduced torque over one steady cycle (a
    :class:`~mechdyn.reduction.flywheel.SteadyCycle`)."""
    x = np.degrees(cycle.phi)
    fig, ax = _figure(2, height=2.4)
    ax[0].plot(x, cycle.omega)
    for v, ls in ((cycle.omega_max, ":"), (cycle.omega_min, ":"), (cycle.omega_mean, "--")):
        ax[0].axhline(v, color="gray", ls=ls, lw=0.8)
    ax[0].set_ylabel("speed (rad/s)")
    ax[0].set_title(title or f"steady cycle: delta = {cycle.delta:.4g}, "
                             f"omega_mean = {cycle.omega_mean:.4g} rad/s")
    ax[1].plot(x, cycle.M)
    ax[1].set_ylabel("reduced torque (N m)")
    ax[1].set_xlabel("position (deg)")
    return _save(fig, path, dpi)


def plot_startup(res, path, *, title: str | None = None, dpi: int = 120) -> Path:
    """Speed and torques of a start-up (a :class:`~mechdyn.reduction.run.StartupResult`)."""
    run = res.run
    fig, ax = _figure(2, height=2.4)
    ax[0].plot(run.t, run.omega)
    ax[0].axhline(res.omega_mean, color="gray", ls="--", lw=0.8)
    if res.t_steady is not None:
        ax[0].axvline(res.t_steady, color="C3", ls=":", lw=0.8)
    ax[0].set_ylabel("speed (rad/s)")
    ax[0].set_title(title or "start-up")
    ax[1].plot(run.t, run.M_drive, label="drive (link side)")
    if run.M_motor is not None:
        ax[1].plot(run.t, run.M_motor, "--", label="motor shaft")
    ax[1].set_ylabel("torque (N m)")
    ax[1].set_xlabel("time (s)")
    ax[1].legend(loc="best", fontsize="small")
    return _save(fig, path, dpi)


def plot_motor(motor, path, *, points: int = 401, title: str | None = None,
               dpi: int = 120) -> Path:
    """Mechanical characteristic M(omega) of a motor from standstill to synchronous speed."""
    w_top = getattr(motor, "synchronous_speed", None) or getattr(motor, "no_load_speed", None)
    if w_top is None:
        w_top = float(np.max(getattr(motor, "omega", (1.0,))))
    w = np.linspace(0.0, float(w_top), points)
    m = np.asarray(motor.torque_at(w), dtype=float)
    fig, ax = _figure(1, height=3.2)
    ax[0].plot(m, w)
    ax[0].set_xlabel("torque (N m)")
    ax[0].set_ylabel("speed (rad/s)")
    ax[0].set_title(title or f"characteristic of {getattr(motor, 'name', 'motor')}")
    return _save(fig, path, dpi)
