"""Plots of a kinetostatic analysis: driving torque, pin forces, shaking force and moment;
the polar diagram of a joint force."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .figure import figure as _figure
from .figure import save as _save
from .plot_axes import force_unit, model_name, shade_modes, speed_text, x_axis

__all__ = ["plot_kinetostatics", "plot_joint_force_polar"]


def _title(record, what: str, sep: str = " ") -> str:
    speed = speed_text(record)
    status = "" if record.status == "success" else f" ({record.status})"
    return f"{model_name(record)}: {what}" + (f"{sep}{speed}" if speed else "") + status


def plot_kinetostatics(record, path=None, *, joints: Sequence[str] | None = None,
                       dpi: int = 120):
    """Write a three-panel figure of a :class:`~mechdyn.kinetostatics.inverse.Kinetostatics`.

    Panels: (1) driving torque of every driven angle (N m; driving forces of travels in N on
    a right-hand axis); (2) resultant reaction |R| of the chosen joints (N, or kN when
    large); (3) shaking force components and magnitude (N or kN), with the shaking moment
    (N m) on a right-hand axis; with friction in the pairs (``record.power_out`` set) a
    fourth panel: (4) the power lost in each pair and in all (W), with the instantaneous
    efficiency (%) and the cycle efficiency (dashed) on a right-hand axis.  One unit per
    axis; a full turn runs 0..360 deg; the modes of a switched analysis are shaded and
    named in a legend.

    Parameters
    ----------
    record : Kinetostatics
    path : str or Path, optional
        Image file (format from the suffix, e.g. ``.png``); None returns the figure.
    joints : sequence of str, optional
        Joints whose forces are drawn (default: all joints).
    dpi : int

    Returns
    -------
    Path, or Figure when ``path`` is None
    """
    names = list(record.reactions) if joints is None else list(joints)
    for j in names:
        record.force_magnitude(j)  # a clear error for an unknown joint
    xa = x_axis(record)
    friction = record.power_out is not None
    fig, axes = _figure(3 + friction, height=3.0)
    ax = axes[0]
    torques = [c for c in record.driven if record._drive_unit(c)[1] == "Nm"]
    forces = [c for c in record.driven if c not in torques]
    tax = ax if torques or not forces else None
    fax = (ax.twinx() if tax is not None else ax) if forces else None
    for c in torques:
        ax.plot(xa.x, xa.y(record.driving[c]), label=f"M drive {c} (N m)")
    if fax is not None:
        f, unit = force_unit(*(record.driving[c] for c in forces))
        for k, c in enumerate(forces):
            fax.plot(xa.x, xa.y(record.driving[c]) * f, ls="--", color=f"C{len(torques) + k}",
                     label=f"F drive {c} ({unit})")
        fax.set_ylabel(f"driving force ({unit})")
    if tax is not None:
        ax.set_ylabel("driving torque (N m)")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.legend(handles=ax.lines[:len(torques)] + (fax.lines if fax is not None else []),
              loc="best", fontsize="small")
    ax.set_title(_title(record, "kinetostatics"))
    ax = axes[1]
    f, unit = force_unit(*(record.force_magnitude(j) for j in names))
    for j in names:
        ax.plot(xa.x, xa.y(record.force_magnitude(j)) * f, label=f"|F {j}|")
    ax.set_ylabel(f"joint force ({unit})")
    if names:
        ax.legend(loc="best", fontsize="small", ncol=2)
    ax = axes[2]
    ff = record.frame_force
    f, unit = force_unit(ff)
    ax.plot(xa.x, xa.y(ff[:, 0]) * f, label=f"Fx frame ({unit})")
    ax.plot(xa.x, xa.y(ff[:, 1]) * f, label=f"Fy frame ({unit})")
    ax.plot(xa.x, xa.y(np.hypot(ff[:, 0], ff[:, 1])) * f, "k", lw=1.0,
            label=f"|F| frame ({unit})")
    ax.set_ylabel(f"shaking force ({unit})")
    ax2 = ax.twinx()
    ax2.plot(xa.x, xa.y(record.frame_moment), "--", color="tab:red", lw=1.0,
             label="M frame (N m)")
    ax2.set_ylabel("shaking moment (N m)", color="tab:red")
    ax.legend(handles=ax.lines + ax2.lines, loc="best", fontsize="small")
    if friction:
        _friction_panel(axes[3], record, xa)
    xa.setup(axes[-1])
    if record.switched and record.mode_index is not None:
        shade_modes(axes, xa, record.mode_index, record.modes, legend_ax=axes[1])
    return _save(fig, path, dpi)


def _friction_panel(ax, record, xa) -> None:
    """Power lost per pair and in all (W); efficiency (%) on a right-hand axis, kept to
    -100..200 % where the ratio runs off (near zero input power)."""
    for j, p in record.losses.items():
        ax.plot(xa.x, xa.y(p), lw=1.0, label=f"P lost {j} (W)")
    ax.plot(xa.x, xa.y(record.power_loss), "k", lw=1.4, label="P lost, all pairs (W)")
    ax.set_ylabel("power lost by friction (W)")
    ax2 = ax.twinx()
    eta = 100.0 * np.asarray(record.efficiency, float)
    ax2.plot(xa.x, xa.y(eta), color="darkgreen", lw=1.8, label="efficiency (%)")
    cycle = 100.0 * record.cycle_efficiency
    if np.isfinite(cycle):
        ax2.axhline(cycle, color="darkgreen", ls="--", lw=1.0,
                    label=f"cycle efficiency {cycle:.3g} (%)")
    ok = eta[np.isfinite(eta)]
    if ok.size and (ok.min() < -100.0 or ok.max() > 200.0):
        lo, hi = max(float(ok.min()), -100.0), min(float(ok.max()), 200.0)
        ax2.set_ylim(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
    ax2.set_ylabel("efficiency (%)", color="darkgreen")
    ax.legend(handles=ax.lines + ax2.lines, loc="best", fontsize="x-small", ncol=3)


def plot_joint_force_polar(record, joint: str, path=None, *, frame: str = "ground",
                           dpi: int = 120):
    """Polar diagram of a joint force over the motion: the tip of the force vector on the
    child body (from the parent), magnitude as radius (N or kN), direction as angle.

    Parameters
    ----------
    record : Kinetostatics
    joint : str
        The joint (any key of ``record.reactions``).
    path : str or Path, optional
        Image file; None returns the figure.
    frame : {"ground", "joint"}
        Directions in the ground frame (``record.reactions``), or in the joint's frame
        (``record.joint_frame``: along the parent body's axes for a revolute, along and
        across the axis for a prismatic joint) -- the load as the bearing sees it.
    dpi : int

    Returns
    -------
    Path, or Figure when ``path`` is None

    Examples
    --------
    >>> import mechdyn
    >>> ks = mechdyn.kinetostatics(mechdyn.examples.load("slider_crank"), speed=10.0)
    >>> fig = plot_joint_force_polar(ks, "A")
    >>> fig.axes[0].name
    'polar'
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    record.force_magnitude(joint)  # a clear error for an unknown joint
    if frame not in ("ground", "joint"):
        raise ValueError(f"frame must be 'ground' or 'joint', got {frame!r}")
    F = np.asarray((record.reactions if frame == "ground" else record.joint_frame)[joint],
                   float)
    mag = np.hypot(F[:, 0], F[:, 1])
    f, unit = force_unit(mag)
    fig = Figure(figsize=(6.4, 6.4), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="polar")
    theta = np.arctan2(F[:, 1], F[:, 0])
    ax.plot(theta, mag * f, color="C0", lw=1.5, label=f"F {joint} ({unit})")
    k = int(np.nanargmax(mag)) if np.isfinite(mag).any() else 0
    ax.plot(theta[:1], mag[:1] * f, "o", color="tab:green", label="first position")
    ax.plot(theta[k:k + 1], mag[k:k + 1] * f, "^", color="tab:red",
            label=f"peak {mag[k] * f:.4g} {unit}")
    ax.set_rlabel_position(112.5)
    ax.text(np.deg2rad(112.5), ax.get_rmax() * 1.08, unit, ha="center")
    ax.legend(loc="lower left", bbox_to_anchor=(-0.1, -0.12), fontsize="small")
    where = "ground frame" if frame == "ground" else "joint frame"
    ax.set_title(_title(record, f"force on the child at {joint!r} ({where})", "\n"),
                 fontsize="medium")
    return _save(fig, path, dpi)
