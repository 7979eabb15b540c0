"""The planar vector formulas every layer uses, written once (NumPy, batched).

A body's frame is turned by its angle theta: a vector s given in the body frame is
A(theta) s in the ground frame, with A(theta) = [[cos, -sin], [sin, cos]].  Its
perpendicular (s turned by +90 deg) and the z component of a cross product a x b
(the moment of a force b at an arm a) are the other two formulas.  The compiled kernels
(:mod:`mechdyn.kernels.rows_numba`) inline the same three formulas on scalars.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rotate", "rotate_back", "perp", "cross"]


def rotate(th, s) -> np.ndarray:
    """A(th) s: vectors s turned by the angles th.

    Parameters
    ----------
    th : float or array_like, shape (...)
        Angles, rad (counter-clockwise positive).
    s : array_like, shape (2,) or (..., 2)
        Vectors (one for every angle, or broadcast against ``th``), any length unit.

    Returns
    -------
    ndarray, shape (..., 2)
        In the unit of ``s``.

    Examples
    --------
    >>> rotate(np.pi / 2, [1.0, 0.0]).round(12) + 0.0
    array([0., 1.])
    >>> rotate(np.array([0.0, np.pi]), [2.0, 1.0]).round(12) + 0.0
    array([[ 2.,  1.],
           [-2., -1.]])
    """
    s = np.asarray(s, dtype=float)
    c, sn = np.cos(th), np.sin(th)
    out = np.empty(np.broadcast_shapes(np.shape(th), s.shape[:-1]) + (2,))
    out[..., 0] = c * s[..., 0] - sn * s[..., 1]
    out[..., 1] = sn * s[..., 0] + c * s[..., 1]
    return out


def rotate_back(th, v) -> np.ndarray:
    """A(th)^T v: ground-frame vectors v expressed in a frame turned by th (the inverse
    of :func:`rotate`).

    Parameters
    ----------
    th : float or array_like, shape (...)
        Angles of the frames, rad.
    v : array_like, shape (2,) or (..., 2)
        Vectors in the ground frame.

    Returns
    -------
    ndarray, shape (..., 2)

    Examples
    --------
    >>> rotate_back(np.pi / 2, [0.0, 1.0]).round(12) + 0.0
    array([1., 0.])
    """
    return rotate(-np.asarray(th, dtype=float), v)


def perp(v) -> np.ndarray:
    """Vectors (..., 2) turned by +90 deg: (-v_y, v_x).

    Examples
    --------
    >>> perp(np.array([3.0, 4.0]))
    array([-4.,  3.])
    """
    v = np.asarray(v, dtype=float)
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross(a, b) -> np.ndarray:
    """z component of a x b for planar vectors (..., 2) -> (...): the moment of a force
    b at the arm a (N m for N and m).

    Examples
    --------
    >>> float(cross(np.array([0.5, 0.0]), np.array([0.0, 10.0])))
    5.0
    """
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
