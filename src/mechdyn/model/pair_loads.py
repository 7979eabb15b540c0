"""Loads between two body points, evaluated together as arrays: linear springs and
dampers (:class:`~mechdyn.mechanism.load.Spring`) and bushings
(:class:`~mechdyn.mechanism.load.Bushing`), for :class:`mechdyn.model.forces.ForceModel`
(one pose or a batch), with the planar rotation and cross product they use.

A row of either set is ``(name, i, si, j, sj, ...)``: end 1 at ``si`` (body frame, m) on
body slot ``i``, end 2 at ``sj`` on slot ``j``, the ground the last slot, nb.  Their
forces are scattered onto the slots (force and moment about each body-frame origin) by
incidence matrices, one matrix product for all elements.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..kernels.planar import cross, perp, rotate

__all__ = ["SpringSet", "BushingSet"]


class _Pairs:
    """Load elements between two body points, as arrays: rows ``(name, i, si, j, sj, ...)``
    with end 1 at ``si`` on body slot ``i``, end 2 at ``sj`` on slot ``j`` (the ground the
    last slot, nb), and the incidence matrices that scatter their forces onto the slots."""

    def __init__(self, rows, nb: int):
        self.names = [r[0] for r in rows]
        self.i = np.array([r[1] for r in rows], dtype=int)
        self.j = np.array([r[3] for r in rows], dtype=int)
        self.si = np.array([r[2] for r in rows], dtype=float).reshape(-1, 2)
        self.sj = np.array([r[4] for r in rows], dtype=float).reshape(-1, 2)
        n = len(rows)
        #: slot incidence of end 1 and of end 2
        self.p1, self.p2 = np.zeros((n, nb + 1)), np.zeros((n, nb + 1))
        self.p1[np.arange(n), self.i] = 1.0
        self.p2[np.arange(n), self.j] = 1.0

    def geometry(self, X):
        """Arms of both ends (..., n, 2) and the vectors P1 -> P2 (..., n, 2) for the slot
        poses X (..., nb + 1, 3)."""
        ai, aj = rotate(X[..., self.i, 2], self.si), rotate(X[..., self.j, 2], self.sj)
        return ai, aj, X[..., self.j, :2] + aj - X[..., self.i, :2] - ai

    def scatter(self, F, f, a1, a2):
        """Add force f (..., n, 2) on end 1 at arm a1 from its slot's origin, and -f on end 2
        at arm a2, to F (..., nb + 1, 3)."""
        F[..., :2] += np.swapaxes(np.swapaxes(f, -1, -2) @ (self.p1 - self.p2), -1, -2)
        F[..., 2] += cross(a1, f) @ self.p1 - cross(a2, f) @ self.p2


class SpringSet(_Pairs):
    """The springs of a force model, evaluated together (one NumPy operation for all of
    them, not one per spring): rows ``(name, i, si, j, sj, k, L0, c, pre)``."""

    def __init__(self, springs, nb: int):
        super().__init__(springs, nb)
        self.k, self.L0, self.c, self.pre = (np.array([sp[n] for sp in springs], dtype=float)
                                             for n in (5, 6, 7, 8))
        self.damped = bool(np.any(self.c != 0.0))

    def apply(self, F, X, V):
        """Add the spring forces (stiffness, preload, and damping unless V is None) at
        the slot poses X and rates V to F (..., nb + 1, 3)."""
        ai, aj, d = self.geometry(X)
        L = np.hypot(d[..., 0], d[..., 1])
        short = L < 1e-300
        if short.any():
            name = self.names[int(np.argmax(short.reshape(-1, len(self.names)).any(axis=0)))]
            raise ModelError(f"spring {name!r}: its two points coincide; direction undefined")
        e = d / L[..., None]
        f = self.k * (L - self.L0)
        if V is not None and self.damped:
            vd = (V[..., self.j, :2] + V[..., self.j, 2, None] * perp(aj)
                  - V[..., self.i, :2] - V[..., self.i, 2, None] * perp(ai))
            f = f + self.c * np.sum(e * vd, axis=-1)
        self.scatter(F, (f + self.pre)[..., None] * e, ai, aj)  # on end 1, towards end 2

    def energy(self, X):
        """Stored energy of stiffness and preload (...), J."""
        d = self.geometry(X)[2]
        L = np.hypot(d[..., 0], d[..., 1])
        return np.sum(0.5 * self.k * (L - self.L0) ** 2 + self.pre * L, axis=-1)


class BushingSet(_Pairs):
    """The bushings of a force model (:class:`~mechdyn.mechanism.load.Bushing`), evaluated
    together: rows ``(name, i, si, j, sj, kx, ky, cx, cy)``.

    The offset of end 2 from end 1 in the axes of body i, d = A_i^T (r_j - r_i), loads
    end 2 with -A_i (K d + C d') and body i with the opposite at the same place, so the
    pair has no moment and does the work -(K d + C d) . d' (d' the rate of d: end 2's
    velocity less that of the point of body i under it)."""

    def __init__(self, rows, nb: int):
        super().__init__(rows, nb)
        self.k = np.array([r[5:7] for r in rows], dtype=float).reshape(-1, 2)
        self.c = np.array([r[7:9] for r in rows], dtype=float).reshape(-1, 2)
        self.damped = bool(np.any(self.c != 0.0))

    def offsets(self, X):
        """Arms of both ends, d in body i's axes (..., n, 2) and body i's angle (..., n)."""
        ai, aj, delta = self.geometry(X)
        th = X[..., self.i, 2]
        return ai, aj, delta, rotate(-th, delta), th

    def apply(self, F, X, V):
        """Add the bushing forces (stiffness, and damping unless V is None) at the slot
        poses X and rates V to F (..., nb + 1, 3)."""
        ai, aj, delta, d, th = self.offsets(X)
        f = self.k * d
        a1 = ai + delta  # body i takes its force where end 2 is
        if V is not None and self.damped:
            vd = (V[..., self.j, :2] + V[..., self.j, 2, None] * perp(aj)
                  - V[..., self.i, :2] - V[..., self.i, 2, None] * perp(a1))
            f = f + self.c * rotate(-th, vd)
        self.scatter(F, rotate(th, f), a1, aj)

    def energy(self, X):
        """Stored energy (...), J."""
        d = self.offsets(X)[3]
        return np.sum(0.5 * np.sum(self.k * d * d, axis=-1), axis=-1)
