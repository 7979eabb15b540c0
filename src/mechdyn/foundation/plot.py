"""Plot of the loads on the supports: the load on the base, the vertical and horizontal
force of every support (bolts: tension and clamp force), the opening of a joint, and
with an elastic mounting the force passed to the floor beside the rigid case."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..results.figure import figure, save
from .response import MountedResponse
from .rigid import SupportLoads

__all__ = ["plot_support_loads"]

_KN = 1e-3


def plot_support_loads(loads: SupportLoads, path, mounted: MountedResponse | None = None,
                       dpi: int = 120) -> Path:
    """Plot a :class:`~mechdyn.foundation.rigid.SupportLoads` (forces in kN).

    Parameters
    ----------
    loads : SupportLoads
    path : str or Path
        Image file (format from the suffix).
    mounted : MountedResponse, optional
        The elastic mounting's response: its floor force is drawn beside the rigid one.
    dpi : int

    Returns
    -------
    Path
    """
    bolts = bool(loads.tension)
    fig, ax = figure(3 + bolts + (mounted is not None), height=2.2)
    t = loads.t
    a = loads.applied
    ax[0].plot(t, a[:, 0] * _KN, label="Fx")
    ax[0].plot(t, a[:, 1] * _KN, label="Fy")
    ax[0].set_ylabel("load on base (kN)")
    twin = ax[0].twinx()
    twin.plot(t, a[:, 2] * _KN, "k:", lw=1.0, label="M")
    twin.set_ylabel(f"M about ({loads.point[0]:.3g}, {loads.point[1]:.3g}) m (kN m)")
    ax[0].legend(loc="upper left", fontsize="small")
    for name in loads.names:
        bolt = name in loads.tension
        ax[1].plot(t, (loads.tension[name] if bolt else loads.fy[name]) * _KN, label=name)
        ax[2].plot(t, loads.fx[name] * _KN, label=name)
        if bolt:
            ax[3].plot(t, loads.clamp[name] * _KN, label=name)
    ax[1].set_ylabel("bolt tension /\nvertical force (kN)" if bolts else "vertical force (kN)")
    ax[2].set_ylabel("shear / horizontal\nforce (kN)" if bolts else "horizontal force (kN)")
    if bolts:
        ax[3].set_ylabel("clamp force (kN)")
        ax[3].axhline(0.0, color="k", lw=0.8)
        opening = loads.first_opening
        if opening is not None:
            ax[3].axvline(opening[1], color="r", ls="--", lw=1.0,
                          label=f"{opening[0]} opens, {opening[1]:.4g} s")
    if mounted is not None:
        ax[-1].plot(t, np.hypot(a[:, 0], a[:, 1]) * _KN, label="rigid frame")
        ax[-1].plot(mounted.t, np.hypot(mounted.floor[:, 0], mounted.floor[:, 1]) * _KN,
                    label="on the mounts")
        ax[-1].set_ylabel("|force to floor| (kN)")
    for panel in ax[1:]:
        panel.legend(loc="upper right", fontsize="small")
    ax[-1].set_xlabel("t (s)")
    fig.suptitle("loads on the supports")
    return save(fig, Path(path), dpi)
