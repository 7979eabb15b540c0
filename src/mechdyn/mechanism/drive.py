"""Drives: torques or forces acting directly on a generalized coordinate.

A drive on coordinate ``q_k`` adds its torque (N m; N for a travel) to the
generalized force Q_k: for an absolute-angle coordinate it acts on the body
against the ground, for a relative angle on the child against the parent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Drive", "TorqueSpeedCurve"]


@dataclass(frozen=True)
class TorqueSpeedCurve:
    """A mechanical characteristic M(omega) from a table, linearly interpolated.

    Parameters
    ----------
    omega : sequence of float
        Speeds of the driven coordinate, rad/s (increasing).
    torque : sequence of float
        Torque at those speeds, N m.
    """

    omega: tuple
    torque: tuple

    def __post_init__(self):
        w = np.asarray(self.omega, dtype=float).reshape(-1)
        m = np.asarray(self.torque, dtype=float).reshape(-1)
        if w.size < 2 or w.size != m.size or not np.all(np.diff(w) > 0):
            raise ValueError("torque-speed curve: omega must increase strictly and have the "
                             "same length (>= 2) as torque")
        object.__setattr__(self, "omega", tuple(w))
        object.__setattr__(self, "torque", tuple(m))

    def __call__(self, omega):
        """Torque (N m) at ``omega`` (a float, or an array of the shape of an array ``omega``)."""
        y = np.interp(omega, self.omega, self.torque)
        return float(y) if np.ndim(y) == 0 else y


@dataclass(frozen=True)
class Drive:
    """A drive torque (or force) on a generalized coordinate.

    Parameters
    ----------
    name : str
    coordinate : str
        The driven generalized coordinate.
    torque : float, TorqueSpeedCurve, Table or callable
        Constant (N m); a characteristic M(omega) of the coordinate's rate; a
        :class:`~mechdyn.mechanism.load.Table`; or a callable of a LoadContext.
    """

    name: str
    coordinate: str
    torque: object = 0.0
    is_drive = True
