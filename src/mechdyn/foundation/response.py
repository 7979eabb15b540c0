"""The mounted base's response to a frame-load history: its motion and the force it
passes to the floor (linear, one way; see :mod:`mechdyn.foundation.isolation`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..brief import brief, number
from ..errors import ModelError
from .supports import Foundation, shift_moment, support_matrix

__all__ = ["MountedResponse", "mounted_response"]


@dataclass(frozen=True, repr=False)
class MountedResponse:
    """The base's motion and the load it passes to the floor over a load history.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s.
    u, v : ndarray, shape (n, 3)
        Displacement and velocity of the centre of mass from its static position at
        zero load: x, y (m, m/s), theta (rad, rad/s).
    floor : ndarray, shape (n, 3)
        Load passed to the floor by all supports: Fx, Fy (N), moment about ``point``
        (N m).
    supports : dict str -> ndarray, shape (n, 2)
        Force each support passes to the floor, x and y, N.
    point : ndarray, shape (2,)
        The point of the moments, m.
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    floor: np.ndarray
    supports: dict
    point: np.ndarray

    def __repr__(self) -> str:
        ok = self.floor[np.all(np.isfinite(self.floor), axis=1)]
        peak = float(np.max(np.hypot(ok[:, 0], ok[:, 1]))) if len(ok) else None
        return brief(self, f"{self.t.size} samples", f"supports={list(self.supports)[:6]}",
                     f"peak |F| to the floor {number(peak, 'N')}")

    def to_dataframe(self):
        """A pandas DataFrame: ``t_s``, ``x_base_m``, ``y_base_m``, ``theta_base_rad``,
        ``Fx_floor_N``, ``Fy_floor_N``, ``M_floor_Nm`` and ``Fx_<support>_N``,
        ``Fy_<support>_N``."""
        import pandas as pd

        cols = {"t_s": self.t, "x_base_m": self.u[:, 0], "y_base_m": self.u[:, 1],
                "theta_base_rad": self.u[:, 2], "Fx_floor_N": self.floor[:, 0],
                "Fy_floor_N": self.floor[:, 1], "M_floor_Nm": self.floor[:, 2]}
        for name, f in self.supports.items():
            cols[f"Fx_{name}_N"], cols[f"Fy_{name}_N"] = f[:, 0], f[:, 1]
        return pd.DataFrame(cols)


def mounted_response(foundation: Foundation, t, Fx, Fy, M, point=(0.0, 0.0),
                     start: str = "static") -> MountedResponse:
    """Time response of the mounted base to a frame-load history (one-way coupling).

    The load (taken linear between the samples) drives M u'' + C u' + K u = f; the
    state is advanced exactly over each step (matrix exponential with a first-order
    hold), so unequal steps are fine.  One way: the base's motion does not feed back into
    the mechanism (the machine runs as on a rigid frame); the two-way coupled simulation
    is not part of this function.

    Parameters
    ----------
    foundation : Foundation
        With ``mass`` and ``inertia``.
    t : array_like, shape (n,)
        Times, s, not decreasing (a repeated time, as at a switching instant, is a jump
        of the load).
    Fx, Fy, M : array_like, shape (n,)
        The load the machine exerts on its frame: N, N, N m about ``point``.
    point : (float, float)
        The point of ``M``, m.
    start : {"static", "rest"}
        Initial state: the static deflection under the first load (default), or zero.

    Returns
    -------
    MountedResponse

    Raises
    ------
    ModelError
        ``mass`` or ``inertia`` missing, arrays of different lengths, times that
        decrease, an unknown ``start``.

    Examples
    --------
    A constant load gives the static deflection:

    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5, cy=400.0),
    ...                 Isolator("R", 0.5, 0.0, 1e5, 1e5, cy=400.0)], mass=200.0, inertia=25.0)
    >>> t = np.linspace(0.0, 0.1, 11)
    >>> r = mounted_response(f, t, 0 * t, -2000.0 + 0 * t, 0 * t)
    >>> round(float(r.u[-1, 1]), 9), round(float(r.floor[-1, 1]), 6)
    (-0.01, -2000.0)
    """
    if start not in ("static", "rest"):
        raise ModelError(f"mounted_response: start must be 'static' or 'rest', got {start!r}")
    t = np.atleast_1d(np.asarray(t, float))
    loads = [np.atleast_1d(np.asarray(v, float)) for v in (Fx, Fy, M)]
    if any(a.shape != t.shape for a in loads) or t.ndim != 1:
        raise ModelError("mounted_response: t, Fx, Fy and M must be 1-D of the same length")
    if t.size > 1 and not np.all(np.diff(t) >= 0):
        raise ModelError("mounted_response: the times must not decrease")
    com = foundation.com
    f = shift_moment(np.column_stack(loads), point, com)
    Mm = foundation.mass_matrix()
    K, C = foundation.stiffness_matrix(com), foundation.damping_matrix(com)
    Minv = np.linalg.inv(Mm)
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((3, 3)), Minv])
    z = np.zeros((t.size, 6))
    if start == "static":
        z[0, :3] = np.linalg.solve(K, f[0])
    steps = np.diff(t)
    cache: dict = {}
    for k, h in enumerate(steps):
        key = round(float(h), 15)
        if key not in cache:
            cache[key] = _hold(A, B, float(h))
        Phi, G0, G1 = cache[key]
        z[k + 1] = Phi @ z[k] + G0 @ f[k] + G1 @ (f[k + 1] - f[k])
    u, v = z[:, :3], z[:, 3:]
    T = support_matrix(foundation.supports, com)
    per = (np.einsum("sk,ski,ni->nsk", foundation.stiffnesses(), T, u)
           + np.einsum("sk,ski,ni->nsk", foundation.dampings(), T, v))
    floor = shift_moment(u @ K.T + v @ C.T, com, point)
    return MountedResponse(t=t, u=u, v=v, floor=floor, point=np.asarray(point, float),
                           supports={n: per[:, i] for i, n in enumerate(foundation.names)})


def _hold(A, B, h):
    """Exact step of z' = A z + B f over h with f linear: (Phi, Gamma0, Gamma1) so that
    z1 = Phi z0 + Gamma0 f0 + Gamma1 (f1 - f0)."""
    n, m = A.shape[0], B.shape[1]
    big = np.zeros((n + 2 * m, n + 2 * m))
    big[:n, :n] = A * h
    big[:n, n:n + m] = B * h
    big[n:n + m, n + m:] = np.eye(m)
    from scipy.linalg import expm
    E = expm(big)
    return E[:n, :n], E[:n, n:n + m], E[:n, n + m:]
