"""The NumPy evaluator of constraint rows, batched over poses.

For rows m(x) = w . (p1 - p2) + ka theta_a + kb theta_b + c (see
:mod:`mechdyn.model.rows`) it returns the value, the Jacobian m_x and the
velocity-quadratic part of the second derivative,

    d2m/dt2 = m_x xddot + quad(x, xdot),
    quad = -w_d^2 w.(p1 - p2) + 2 w_d perp(w).(v_p1 - v_p2) + w.(w_2^2 rho_2 - w_1^2 rho_1),

(rho_k = A(theta_k) s_k, perp = rotation by +90 deg, w_k the angular rates), so
that the acceleration right-hand side of Phi_x xddot = gamma is gamma = -quad.
Poses ``x`` have shape (..., n_x); every result carries the same leading
dimensions.  :mod:`mechdyn.kernels.rows_numba` is the compiled twin over the
same arrays.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

__all__ = ["Parts", "parts", "values", "jacobian", "quad", "evaluate", "VariantRows",
           "variant_rows"]


class Rows(Protocol):
    """What the evaluator reads of a set of rows (:class:`mechdyn.model.rows.Rows`, which
    the model lowers and which imports these kernels): the body indices and arrays of
    every row, ``nb`` bodies, ``n_x`` = 3 nb, the contiguous columns and the Jacobian's
    scatter indices."""

    nb: int
    b1: np.ndarray
    b2: np.ndarray
    d: np.ndarray
    a: np.ndarray
    bb: np.ndarray
    ka: np.ndarray
    kb: np.ndarray
    c: np.ndarray

    @property
    def n_x(self) -> int: ...

    @property
    def columns(self) -> tuple: ...

    @property
    def scatter(self) -> np.ndarray: ...


class Parts:
    """Geometric parts of the rows at a pose (rotated points, direction, separation)."""

    __slots__ = ("th", "r1x", "r1y", "r2x", "r2y", "wx", "wy", "dx", "dy")

    def __init__(self, rows: Rows, x):
        x = np.asarray(x, dtype=float)
        nb = rows.nb
        X = np.zeros(x.shape[:-1] + (nb + 1, 3))
        X[..., :nb, :] = x.reshape(x.shape[:-1] + (nb, 3))
        th = X[..., 2]
        c, s = np.cos(th), np.sin(th)
        b1, b2, d = rows.b1, rows.b2, rows.d
        # gathers along the last axis (take: the same for one pose and for a batch)
        c1, s1, c2, s2 = c.take(b1, -1), s.take(b1, -1), c.take(b2, -1), s.take(b2, -1)
        cd, sd = c.take(d, -1), s.take(d, -1)
        s1x, s1y, s2x, s2y, ux, uy = rows.columns
        self.th = th
        self.r1x = c1 * s1x - s1 * s1y
        self.r1y = s1 * s1x + c1 * s1y
        self.r2x = c2 * s2x - s2 * s2y
        self.r2y = s2 * s2x + c2 * s2y
        self.wx = cd * ux - sd * uy
        self.wy = sd * ux + cd * uy
        px, py = X[..., 0], X[..., 1]
        self.dx = px.take(b1, -1) + self.r1x - px.take(b2, -1) - self.r2x
        self.dy = py.take(b1, -1) + self.r1y - py.take(b2, -1) - self.r2y


def parts(rows: Rows, x) -> Parts:
    """The :class:`Parts` of ``rows`` at poses ``x`` (..., n_x)."""
    return Parts(rows, x)


def values(rows: Rows, x, p: Parts | None = None) -> np.ndarray:
    """m(x), shape (..., n) (m or rad).

    Examples
    --------
    >>> from mechdyn.model import rows as R
    >>> r = R.revolute("A", 0, (0.1, 0.0), 1, (0.0, 0.0), nb=2)
    >>> values(r, [0.0, 0.0, 0.0, 0.1, 0.0, 1.0]).round(12).tolist()
    [0.0, 0.0]
    """
    p = p or Parts(rows, x)
    return (p.wx * p.dx + p.wy * p.dy + rows.ka * p.th.take(rows.a, -1)
            + rows.kb * p.th.take(rows.bb, -1) + rows.c)


def jacobian(rows: Rows, x, p: Parts | None = None) -> np.ndarray:
    """m_x, shape (..., n, n_x)."""
    p = p or Parts(rows, x)
    n, n_x = len(rows), rows.n_x
    batch = p.dx.shape[:-1]
    terms = (p.wx, p.wy, p.wy * p.r1x - p.wx * p.r1y, -p.wx, -p.wy,
             p.wx * p.r2y - p.wy * p.r2x, p.wx * p.dy - p.wy * p.dx, rows.ka, rows.kb)
    if not batch:
        out = np.bincount(rows.scatter, np.concatenate(terms), n * (n_x + 1))
        return out.reshape(n, n_x + 1)[:, :n_x]
    flat = rows.scatter.reshape(9, n)
    out = np.zeros(batch + (n * (n_x + 1),))
    for k in range(9):  # within one term every (row, column) pair is distinct
        out[..., flat[k]] += terms[k]  # (ka, kb broadcast over the batch)
    return out.reshape(batch + (n, n_x + 1))[..., :n_x]


def quad(rows: Rows, x, xdot, p: Parts | None = None) -> np.ndarray:
    """Velocity-quadratic part of d2m/dt2, shape (..., n); gamma = -quad."""
    p = p or Parts(rows, x)
    xdot = np.asarray(xdot, dtype=float)
    nb = rows.nb
    V = np.zeros(xdot.shape[:-1] + (nb + 1, 3))
    V[..., :nb, :] = xdot.reshape(xdot.shape[:-1] + (nb, 3))
    vx, vy, om = V[..., 0], V[..., 1], V[..., 2]
    b1, b2 = rows.b1, rows.b2
    w1, w2, wd = om.take(b1, -1), om.take(b2, -1), om.take(rows.d, -1)
    ddx = vx.take(b1, -1) - w1 * p.r1y - vx.take(b2, -1) + w2 * p.r2y
    ddy = vy.take(b1, -1) + w1 * p.r1x - vy.take(b2, -1) - w2 * p.r2x
    w1s, w2s = w1 * w1, w2 * w2
    return (-wd * wd * (p.wx * p.dx + p.wy * p.dy) + 2.0 * wd * (p.wx * ddy - p.wy * ddx)
            + p.wx * (w2s * p.r2x - w1s * p.r1x) + p.wy * (w2s * p.r2y - w1s * p.r1y))


def evaluate(rows: Rows, x, xdot=None):
    """(value (..., n), Jacobian (..., n, n_x), quad (..., n) or None) in one pass.

    Examples
    --------
    >>> from mechdyn.model import rows as R
    >>> r = R.angle("phi", 0, nb=1)
    >>> v, J, q = evaluate(r, [0.0, 0.0, 0.5], [0.0, 0.0, 2.0])
    >>> float(v[0]), J.tolist(), float(q[0])
    (0.5, [[0.0, 0.0, 1.0]], 0.0)
    """
    p = Parts(rows, x)
    return values(rows, x, p), jacobian(rows, x, p), (
        None if xdot is None else quad(rows, x, xdot, p))


class VariantRows:
    """Rows of V variants of one topology: the integers (bodies) of one
    :class:`~mechdyn.model.rows.Rows`, the numbers (points, directions, angle factors and
    offsets) of each variant, shaped (V, 1, n) so that every evaluator of this module
    takes poses ``x`` (V, N, n_x) (N poses of each variant) and gives results (V, N, ...).

    Build with :func:`variant_rows`.
    """

    __slots__ = ("nb", "b1", "b2", "d", "a", "bb", "scatter", "columns", "ka", "kb", "c")

    def __init__(self, rows: Rows, flts):
        f = np.asarray(flts, dtype=float)
        self.nb, self.b1, self.b2, self.d = rows.nb, rows.b1, rows.b2, rows.d
        self.a, self.bb, self.scatter = rows.a, rows.bb, rows.scatter
        self.columns = tuple(np.ascontiguousarray(f[:, None, :, k]) for k in range(6))
        self.ka, self.kb, self.c = (np.ascontiguousarray(f[:, None, :, k]) for k in (6, 7, 8))

    def __len__(self) -> int:
        return self.c.shape[-1]

    @property
    def n_x(self) -> int:
        """Length of the pose vector, 3 nb."""
        return 3 * self.nb


def variant_rows(rows: Rows, flts) -> VariantRows:
    """The rows of V variants: the structure of ``rows``, the numbers ``flts`` (V, n, 9)
    of each variant (in the layout of :meth:`~mechdyn.model.rows.Rows.packed`: s1, s2,
    u, ka, kb, c).

    Examples
    --------
    >>> from mechdyn.model import rows as R
    >>> r = R.revolute("A", 0, (0.1, 0.0), 1, (0.0, 0.0), nb=2)
    >>> f = np.stack([r.packed()[1], r.packed()[1] * [2, 1, 1, 1, 1, 1, 1, 1, 1]])
    >>> x = np.zeros((2, 1, 6))
    >>> values(variant_rows(r, f), x).round(12).tolist()
    [[[0.1, 0.0]], [[0.2, 0.0]]]
    """
    return VariantRows(rows, flts)
