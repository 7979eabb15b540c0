"""The compiled (Numba) twin of :mod:`mechdyn.kernels.rows_numpy`, over packed rows.

Rows are packed by :meth:`mechdyn.model.rows.Rows.packed` into ``ints`` (n, 5):
b1, b2, d, a, bb and ``flts`` (n, 9): s1x, s1y, s2x, s2y, ux, uy, ka, kb, c.
The functions are generic over these arrays, so they compile once for every
model (and are cached on disk).  Without numba installed they run as plain
Python (slow, but the same results).
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from . import cache_dir

__all__ = ["rows_values", "rows_jacobian", "rows_quad", "rows_values_cs",
           "rows_jacobian_cs", "rows_quad_cs", "body_rotations", "body_pose", "njit", "NUMBA",
           "compiling", "ANNOUNCE_AFTER", "copy_into", "copy_rows"]

#: seconds after which a compilation is announced on stderr
ANNOUNCE_AFTER = 2.0

try:  # pragma: no cover - depends on the environment
    import numba

    NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    NUMBA = False


@contextmanager
def compiling(what: str, after: float = ANNOUNCE_AFTER):
    """Announce on stderr a first compilation of ``what`` that takes longer than
    ``after`` seconds, where it is cached (:func:`mechdyn.kernels.cache_dir`) and how
    long it took (a later run, in any process, loads the cached code and says nothing).

    Examples
    --------
    >>> with compiling("nothing much"):
    ...     pass
    """
    from ..progress import stage

    with stage(f"mechdyn: compiling the {what} (first use on this machine, cached in "
               f"{cache_dir()})", None, after=after,
               done=f"mechdyn: {what} compiled in {{:.1f}} s"):
        yield


def njit(fn):
    """numba.njit with the project's settings (cached, no fastmath), or ``fn`` itself."""
    if NUMBA:
        return numba.njit(cache=True, fastmath=False, nogil=True)(fn)
    return fn


def njit_inline(fn):
    """:func:`njit`, and inlined into its callers by Numba (``inline="always"``): a step
    of a loop split into functions without the cost of a call per step; ``fn`` itself
    without Numba."""
    if NUMBA:
        return numba.njit(cache=True, fastmath=False, nogil=True, inline="always")(fn)
    return fn


@njit_inline
def copy_into(dst, src):
    """``dst[:] = src`` for 1-D arrays of one size, as a loop: Numba's slice assignment
    checks the shapes and builds its error message from them, and that string code
    costs seconds of every first compile of a function using it.

    Examples
    --------
    >>> a = np.zeros(3)
    >>> copy_into(a, np.array([1.0, 2.0, 3.0]))
    >>> a.tolist()
    [1.0, 2.0, 3.0]
    """
    for i in range(dst.size):
        dst[i] = src[i]


@njit_inline
def copy_rows(dst, src):
    """``dst[:, :] = src`` for 2-D arrays of one shape (see :func:`copy_into`).

    Examples
    --------
    >>> a = np.zeros((2, 2))
    >>> copy_rows(a, np.eye(2))
    >>> a.tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    for i in range(dst.shape[0]):
        for j in range(dst.shape[1]):
            dst[i, j] = src[i, j]


@njit
def body_pose(x, nb, b):
    """(x, y, theta) of body b in x (or its rates in xdot); the ground (b >= nb) is zero."""
    if b < nb:
        return x[3 * b], x[3 * b + 1], x[3 * b + 2]
    return 0.0, 0.0, 0.0


@njit
def body_rotations(x, nb, cs):
    """cos and sin of every body's angle in x into ``cs`` (nb + 1, 2), the ground's
    (row nb) (1, 0): computed once per pose, shared by every row's terms (the ``*_cs``
    evaluators)."""
    for b in range(nb):
        t = x[3 * b + 2]
        cs[b, 0] = np.cos(t)
        cs[b, 1] = np.sin(t)
    cs[nb, 0] = 1.0
    cs[nb, 1] = 0.0


@njit
def _rotations(x, nb):
    """:func:`body_rotations` into a new array."""
    cs = np.empty((nb + 1, 2))
    body_rotations(x, nb, cs)
    return cs


@njit
def _row_parts(x, nb, ints, flts, cs, k):
    """Rotated s1, rotated s2, w and the separation d of row k (``cs``:
    :func:`body_rotations` of x)."""
    b1, b2, bd = ints[k, 0], ints[k, 1], ints[k, 2]
    x1, y1, _ = body_pose(x, nb, b1)
    x2, y2, _ = body_pose(x, nb, b2)
    i1, i2, idd = min(b1, nb), min(b2, nb), min(bd, nb)
    c1, s1 = cs[i1, 0], cs[i1, 1]
    c2, s2 = cs[i2, 0], cs[i2, 1]
    cd, sd = cs[idd, 0], cs[idd, 1]
    r1x = c1 * flts[k, 0] - s1 * flts[k, 1]
    r1y = s1 * flts[k, 0] + c1 * flts[k, 1]
    r2x = c2 * flts[k, 2] - s2 * flts[k, 3]
    r2y = s2 * flts[k, 2] + c2 * flts[k, 3]
    wx = cd * flts[k, 4] - sd * flts[k, 5]
    wy = sd * flts[k, 4] + cd * flts[k, 5]
    return r1x, r1y, r2x, r2y, wx, wy, x1 + r1x - x2 - r2x, y1 + r1y - y2 - r2y


@njit
def rows_values(x, nb, ints, flts, out, row0):
    """m(x) of every row into ``out[row0:row0 + n]``."""
    rows_values_cs(x, nb, ints, flts, _rotations(x, nb), out, row0)


@njit
def rows_values_cs(x, nb, ints, flts, cs, out, row0):
    """:func:`rows_values` with the rotations ``cs`` of x (:func:`body_rotations`)."""
    for k in range(ints.shape[0]):
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = _row_parts(x, nb, ints, flts, cs, k)
        v = wx * dx + wy * dy + flts[k, 8]
        a, bb = ints[k, 3], ints[k, 4]
        if a < nb:
            v += flts[k, 6] * x[3 * a + 2]
        if bb < nb:
            v += flts[k, 7] * x[3 * bb + 2]
        out[row0 + k] = v


@njit
def rows_jacobian(x, nb, ints, flts, J, row0):
    """Add m_x of every row into ``J[row0:row0 + n, :]`` (J zeroed by the caller)."""
    rows_jacobian_cs(x, nb, ints, flts, _rotations(x, nb), J, row0)


@njit
def rows_jacobian_cs(x, nb, ints, flts, cs, J, row0):
    """:func:`rows_jacobian` with the rotations ``cs`` of x (:func:`body_rotations`)."""
    for k in range(ints.shape[0]):
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = _row_parts(x, nb, ints, flts, cs, k)
        r = row0 + k
        b1, b2, d, a, bb = ints[k, 0], ints[k, 1], ints[k, 2], ints[k, 3], ints[k, 4]
        if b1 < nb:
            J[r, 3 * b1] += wx
            J[r, 3 * b1 + 1] += wy
            J[r, 3 * b1 + 2] += wy * r1x - wx * r1y
        if b2 < nb:
            J[r, 3 * b2] -= wx
            J[r, 3 * b2 + 1] -= wy
            J[r, 3 * b2 + 2] += wx * r2y - wy * r2x
        if d < nb:
            J[r, 3 * d + 2] += wx * dy - wy * dx
        if a < nb:
            J[r, 3 * a + 2] += flts[k, 6]
        if bb < nb:
            J[r, 3 * bb + 2] += flts[k, 7]


@njit
def rows_quad(x, v, nb, ints, flts, out, row0):
    """Velocity-quadratic part of d2m/dt2 of every row into ``out[row0:row0 + n]``."""
    rows_quad_cs(x, v, nb, ints, flts, _rotations(x, nb), out, row0)


@njit
def rows_quad_cs(x, v, nb, ints, flts, cs, out, row0):
    """:func:`rows_quad` with the rotations ``cs`` of x (:func:`body_rotations`)."""
    for k in range(ints.shape[0]):
        r1x, r1y, r2x, r2y, wx, wy, dx, dy = _row_parts(x, nb, ints, flts, cs, k)
        if wx == 0.0 and wy == 0.0:
            out[row0 + k] = 0.0
            continue
        vx1, vy1, w1 = body_pose(v, nb, ints[k, 0])
        vx2, vy2, w2 = body_pose(v, nb, ints[k, 1])
        _, _, wd = body_pose(v, nb, ints[k, 2])
        ddx = vx1 - w1 * r1y - vx2 + w2 * r2y
        ddy = vy1 + w1 * r1x - vy2 - w2 * r2x
        out[row0 + k] = (-wd * wd * (wx * dx + wy * dy) + 2.0 * wd * (wx * ddy - wy * ddx)
                         + wx * (w2 * w2 * r2x - w1 * w1 * r1x)
                         + wy * (w2 * w2 * r2y - w1 * w1 * r1y))
