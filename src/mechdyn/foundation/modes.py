"""Natural frequencies and mode shapes of the base on elastic supports, and the
excitation orders of the running speed that come near them.

The base (mass m, moment of inertia J about its centre of mass) on its supports, small
motions u = (x, y, theta) of the centre of mass: K phi = w^2 M phi, M = diag(m, m, J),
K the supports' stiffness about the centre of mass (see
:mod:`mechdyn.foundation.isolation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..brief import brief, number
from ..errors import ModelError
from .supports import Foundation

__all__ = ["Modes", "natural_frequencies", "ExcitationWarning", "excitation_warnings"]

_DOF = ("x", "y", "theta")


@dataclass(frozen=True, repr=False)
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

    def __repr__(self) -> str:
        return brief(self, "frequencies " + ", ".join(number(f) for f in self.frequencies)
                     + " Hz", f"labels={list(self.labels)}")


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
    from scipy.linalg import eigh
    w2, shapes = eigh(foundation.stiffness_matrix(foundation.com), Mm)
    omega = np.sqrt(np.clip(w2, 0.0, None))
    share = np.diag(Mm)[:, None] * shapes**2
    share = share / share.sum(axis=0)
    labels = tuple(f"{_DOF[k]} ({100 * share[k, j]:.0f} %)"
                   for j, k in enumerate(np.argmax(share, axis=0)))
    return Modes(frequencies=omega / (2 * np.pi), omega=omega, shapes=shapes, labels=labels)


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
