"""The frame-load history of a run or a record, as (t, Fx, Fy, M, point).

mechdyn reports, for every ``simulate`` run and every kinetostatics record, the load
the machine exerts ON its frame: ``Fx_frame_N``, ``Fy_frame_N`` and ``M_frame_Nm``
(moment about the ground origin, or about the ``point`` given to ``simulate`` /
``kinetostatics``; a kinetostatics record keeps it as ``frame_point``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import ModelError

__all__ = ["FrameLoads", "frame_loads"]

_COLUMNS = ("Fx_frame_N", "Fy_frame_N", "M_frame_Nm")


class FrameLoads(NamedTuple):
    """A frame-load history: times (n,) s, force (n,) N, moment (n,) N m about ``point``."""

    t: np.ndarray
    Fx: np.ndarray
    Fy: np.ndarray
    M: np.ndarray
    point: np.ndarray


def frame_loads(source, point=None) -> FrameLoads:
    """The load on the frame of a Trajectory, a Kinetostatics record or a table.

    Parameters
    ----------
    source : Trajectory, Kinetostatics, or pandas.DataFrame
        A run of :func:`mechdyn.simulate`, a record of :func:`mechdyn.kinetostatics`, or a
        table with the columns ``t_s``, ``Fx_frame_N``, ``Fy_frame_N``, ``M_frame_Nm``.
    point : (float, float), optional
        The point ``M_frame_Nm`` is about, m.  Default: the record's ``frame_point``, else
        the ground origin (a Trajectory does not keep the ``point`` of its run: pass the
        same one here).

    Returns
    -------
    FrameLoads
        Rows with a non-finite load (samples of a run that stopped early) are dropped.

    Raises
    ------
    ModelError
        A source without frame loads (a run without moment column ...).

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"t_s": [0.0, 0.1], "Fx_frame_N": [1.0, 2.0],
    ...                    "Fy_frame_N": [-5.0, -4.0], "M_frame_Nm": [0.5, 0.0]})
    >>> frame_loads(df).Fy.tolist()
    [-5.0, -4.0]
    """
    if hasattr(source, "frame_force") and hasattr(source, "frame_moment"):  # kinetostatics
        t = np.asarray(source.t, float)
        F = np.asarray(source.frame_force, float)
        cols = [F[:, 0], F[:, 1], np.asarray(source.frame_moment, float)]
        if point is None:
            point = getattr(source, "frame_point", None)
    else:
        df = source.to_dataframe(energy=False, bodies=False, degrees=False) \
            if hasattr(source, "switching") else source
        missing = [c for c in ("t_s",) + _COLUMNS if c not in df]
        if missing:
            raise ModelError(f"no frame loads in {type(source).__name__}: missing column(s) "
                             f"{', '.join(missing)} (a run with frame loads from "
                             f"mechdyn.simulate, or a kinetostatics record, is needed)")
        t = df["t_s"].to_numpy(dtype=float)
        cols = [df[c].to_numpy(dtype=float) for c in _COLUMNS]
    point = np.zeros(2) if point is None else np.asarray(point, float)
    if point.shape != (2,) or not np.all(np.isfinite(point)):
        raise ModelError(f"point must be a finite (x, y) in m, got {point!r}")
    good = np.isfinite(t) & np.all(np.isfinite(cols), axis=0)
    if not np.any(good):
        raise ModelError("the frame-load history has no finite sample")
    return FrameLoads(t[good], *(c[good] for c in cols), point)
