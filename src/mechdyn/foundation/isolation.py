"""Elastic mounting: the frame and base as one rigid body on its supports, linear.

Coordinates u = (x, y, theta) of the base's centre of mass (small displacements from
the static position), with M = diag(m, m, J) and the stiffness K and damping C of the
supports about the centre of mass (:class:`~mechdyn.foundation.supports.Foundation`):

    M u'' + C u' + K u = f(t),

f = (Fx, Fy, M about the centre of mass) of the load on the base.  The force passed to
the floor is the supports' K u + C u' (the floor pushes back with the opposite).  For a
harmonic load f e^{i w t} the transmitted load is (K + i w C)(K - w^2 M + i w C)^-1 f:
its ratio to the load is the transmissibility (Den Hartog, *Mechanical Vibrations*,
ch. 3, for one degree of freedom).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh, expm

from ..errors import ModelError
from .supports import Foundation, support_matrix

__all__ = ["Modes", "natural_frequencies", "transmissibility", "MountedResponse",
           "mounted_response", "ExcitationWarning", "excitation_warnings"]

_DOF = ("x", "y", "theta")
_DIRECTIONS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "theta": (0.0, 0.0, 1.0)}


def _shift(F, point, com) -> np.ndarray:
    """Loads (..., 3) with the moment about ``point`` moved to be about ``com``."""
    F = np.asarray(F, float)
    d = np.asarray(point, float) - np.asarray(com, float)
    out = F.copy()
    out[..., 2] = F[..., 2] + d[0] * F[..., 1] - d[1] * F[..., 0]
    return out


@dataclass(frozen=True)
class Modes:
    """The natural frequencies and mode shapes of the mounted base (undamped).

    Attributes
    ----------
    frequencies : ndarray, shape (3,)
        Natural frequencies, Hz, ascending.
    omega : ndarray, shape (3,)
        The same, rad/s.
    shapes : ndarray, shape (3, 3)
        Column j: mode j as (x m, y m, theta rad) of the centre of mass, mass-normalised.
    labels : tuple of str
        The coordinate that carries most of each mode's kinetic energy, with its share.
    """

    frequencies: np.ndarray
    omega: np.ndarray
    shapes: np.ndarray
    labels: tuple


def natural_frequencies(foundation: Foundation) -> Modes:
    """Natural frequencies and mode shapes of the base on its supports.

    Solves K phi = w^2 M phi (``scipy.linalg.eigh``) about the centre of mass.

    Parameters
    ----------
    foundation : Foundation
        With ``mass`` and ``inertia``.

    Returns
    -------
    Modes

    Raises
    ------
    ModelError
        ``mass`` or ``inertia`` missing.

    Examples
    --------
    Two isolators at the height of the centre of mass, 0.5 m either side:

    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 4e5), Isolator("R", 0.5, 0.0, 1e5, 4e5)],
    ...                mass=200.0, inertia=25.0)
    >>> modes = natural_frequencies(f)
    >>> np.round(modes.omega, 6).tolist()  # sqrt(2 kx/m), sqrt(2 ky/m), sqrt(2 ky a^2/J)
    [31.622777, 63.245553, 89.442719]
    >>> modes.labels
    ('x (100 %)', 'y (100 %)', 'theta (100 %)')
    """
    Mm = foundation.mass_matrix()
    w2, shapes = eigh(foundation.stiffness_matrix(foundation.com), Mm)
    omega = np.sqrt(np.clip(w2, 0.0, None))
    share = np.diag(Mm)[:, None] * shapes**2
    share = share / share.sum(axis=0)
    labels = tuple(f"{_DOF[k]} ({100 * share[k, j]:.0f} %)"
                   for j, k in enumerate(np.argmax(share, axis=0)))
    return Modes(frequencies=omega / (2 * np.pi), omega=omega, shapes=shapes, labels=labels)


def _load_vector(direction) -> np.ndarray:
    if isinstance(direction, str):
        if direction not in _DIRECTIONS:
            raise ModelError(f"transmissibility: unknown direction {direction!r}; use 'x', "
                             f"'y', 'theta' or a load vector (Fx, Fy, M)")
        return np.array(_DIRECTIONS[direction])
    e = np.asarray(direction, float)
    if e.shape != (3,) or not np.all(np.isfinite(e)) or not np.any(e):
        raise ModelError(f"transmissibility: a load vector is (Fx, Fy, M), finite and not "
                         f"zero, got {direction!r}")
    return e / np.linalg.norm(e)


def transmissibility(foundation: Foundation, omega, direction="y", point=None,
                     resultant: bool = False) -> np.ndarray:
    """Force transmitted to the floor per unit harmonic load on the base.

    Parameters
    ----------
    foundation : Foundation
        With ``mass`` and ``inertia``.
    omega : float or array_like, shape (n,)
        Angular frequencies of the load, rad/s.
    direction : {"x", "y", "theta"} or array_like, shape (3,)
        The load: a force along x or y at ``point``, a moment, or a load vector
        (Fx, Fy, M about ``point``), normalised to unit length.
    point : (float, float), optional
        Where the load acts (and the point of the moments), m; default the centre of mass.
    resultant : bool
        Return the whole transmitted load (Fx, Fy, M about ``point``) per unit load,
        shape (n, 3), instead of its component along ``direction``.

    Returns
    -------
    ndarray of complex, shape (n,) (or (n, 3), or scalar for a scalar ``omega``)
        The complex frequency response; ``abs`` of it is the transmissibility.

    Raises
    ------
    ModelError
        ``mass`` or ``inertia`` missing, a bad direction, a negative frequency.

    Examples
    --------
    Symmetric isolators, vertical load at the centre of mass: 1-DOF transmissibility
    sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2):

    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5, cy=400.0),
    ...                 Isolator("R", 0.5, 0.0, 1e5, 1e5, cy=400.0)], mass=200.0, inertia=25.0)
    >>> wn = np.sqrt(2e5 / 200.0); zeta = 800.0 / (2 * np.sqrt(2e5 * 200.0))
    >>> r = 2.0
    >>> closed = np.sqrt(1 + (2 * zeta * r)**2) / np.sqrt((1 - r**2)**2 + (2 * zeta * r)**2)
    >>> bool(abs(abs(transmissibility(f, r * wn, "y")) - closed) < 1e-12)
    True
    """
    w = np.asarray(omega, float)
    if np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ModelError("transmissibility: omega must be finite and >= 0 rad/s")
    e = _load_vector(direction)
    com = foundation.com
    point = com if point is None else point
    Mm = foundation.mass_matrix()
    K, C = foundation.stiffness_matrix(com), foundation.damping_matrix(com)
    ww = np.atleast_1d(w)[:, None, None]
    support = K + 1j * ww * C  # (n, 3, 3)
    u = np.linalg.solve(support - ww**2 * Mm, np.broadcast_to(_shift(e, point, com),
                                                              (ww.shape[0], 3))[..., None])
    R = (support @ u)[..., 0]  # about the centre of mass
    d = np.asarray(point, float) - np.asarray(com, float)
    R[:, 2] -= d[0] * R[:, 1] - d[1] * R[:, 0]  # about the point again
    out = R if resultant else R @ e
    return out[0] if w.ndim == 0 else out


@dataclass(frozen=True)
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
    f = _shift(np.column_stack(loads), point, com)
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
    floor = (u @ K.T + v @ C.T)  # about the centre of mass
    d = np.asarray(point, float) - np.asarray(com, float)
    floor[:, 2] -= d[0] * floor[:, 1] - d[1] * floor[:, 0]
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
    E = expm(big)
    return E[:n, :n], E[:n, n:n + m], E[:n, n + m:]


@dataclass(frozen=True)
class ExcitationWarning:
    """A natural frequency near an excitation order of the running speed."""

    mode: int
    label: str
    f_mode: float
    order: int
    f_order: float

    def __str__(self) -> str:
        return (f"mode {self.mode + 1} ({self.label}) at {self.f_mode:.4g} Hz is within "
                f"{100 * abs(self.f_mode / self.f_order - 1):.0f} % of order {self.order} "
                f"({self.f_order:.4g} Hz)")


def excitation_warnings(foundation: Foundation, rpm: float, orders=(1, 2, 3, 4),
                        band: float = 0.2) -> list[ExcitationWarning]:
    """The natural frequencies within +-``band`` of an excitation order.

    Parameters
    ----------
    foundation : Foundation
        With ``mass`` and ``inertia``.
    rpm : float
        Running speed of the crank, rev/min (order k excites k rpm / 60 Hz).
    orders : sequence of int
        The orders to check.
    band : float
        Relative distance counted as "near" (default 0.2: +-20 %).

    Returns
    -------
    list of ExcitationWarning
        Empty when no mode is near an order.

    Raises
    ------
    ModelError
        A negative or non-finite speed, ``mass`` or ``inertia`` missing.

    Examples
    --------
    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 4e5), Isolator("R", 0.5, 0.0, 1e5, 4e5)],
    ...                mass=200.0, inertia=25.0)
    >>> [str(w) for w in excitation_warnings(f, 300.0)]  # 5, 10, 15, 20 Hz
    ['mode 1 (x (100 %)) at 5.033 Hz is within 1 % of order 1 (5 Hz)', \
'mode 2 (y (100 %)) at 10.07 Hz is within 1 % of order 2 (10 Hz)', \
'mode 3 (theta (100 %)) at 14.24 Hz is within 5 % of order 3 (15 Hz)']
    """
    if not (math.isfinite(rpm) and rpm >= 0):
        raise ModelError(f"excitation_warnings: rpm must be finite and >= 0, got {rpm!r}")
    modes = natural_frequencies(foundation)
    out = []
    for j, fn in enumerate(modes.frequencies):
        for k in orders:
            fk = k * rpm / 60.0
            if fk > 0 and abs(fn - fk) <= band * fk:
                out.append(ExcitationWarning(j, modes.labels[j], float(fn), int(k), fk))
    return out
