"""The quintic Hermite interpolant of a step, compiled: the output samples of the
fixed-step loops (:mod:`mechdyn.kernels.fixed_step_numba`) between their steps, as the
Python steppers take them (:func:`mechdyn.integrate.base.hermite_dense`)."""

from __future__ import annotations

from .rows_numba import njit

__all__ = ["hermite_at"]


@njit
def hermite_at(t0, y0, f0, t1, y1, f1, ni, s, out):
    """The quintic Hermite interpolant of q (from q, q', q'' at both ends), its
    derivative for q', and the cubic one of w, at ``s``, into ``out`` (y = (q, q', w),
    f = (q', q'', p)): that of :func:`mechdyn.integrate.base.hermite_dense`."""
    h = t1 - t0
    m = y0.size
    if h == 0.0:
        for i in range(m):
            out[i] = y1[i]
        return
    u = (s - t0) / h
    u2 = u * u
    u3 = u2 * u
    # the basis at u (the rows of base._QUINTIC on 1, u, ..., u^5, in Horner's form) and
    # its slopes d/du
    b3 = u3 * (10.0 + u * (-15.0 + 6.0 * u))
    b0 = 1.0 - b3
    b1 = u + u3 * (-6.0 + u * (8.0 - 3.0 * u))
    b2 = 0.5 * u2 + u3 * (-1.5 + u * (1.5 - 0.5 * u))
    b4 = u3 * (-4.0 + u * (7.0 - 3.0 * u))
    b5 = u3 * (0.5 + u * (-1.0 + 0.5 * u))
    d3 = u2 * (30.0 + u * (-60.0 + 30.0 * u))
    d0 = -d3
    d1 = 1.0 + u2 * (-18.0 + u * (32.0 - 15.0 * u))
    d2 = u + u2 * (-4.5 + u * (6.0 - 2.5 * u))
    d4 = u2 * (-12.0 + u * (28.0 - 15.0 * u))
    d5 = u2 * (1.5 + u * (-4.0 + 2.5 * u))
    hh = h * h
    for i in range(ni):
        q0, v0, a0 = y0[i], h * y0[ni + i], hh * f0[ni + i]
        q1, v1, a1 = y1[i], h * y1[ni + i], hh * f1[ni + i]
        out[i] = b0 * q0 + b1 * v0 + b2 * a0 + b3 * q1 + b4 * v1 + b5 * a1
        out[ni + i] = (d0 * q0 + d1 * v0 + d2 * a0 + d3 * q1 + d4 * v1 + d5 * a1) / h
    c2 = u2 * (3.0 - 2.0 * u)
    c0 = 1.0 - c2
    c1 = u * (1.0 + u * (-2.0 + u))
    c3 = u2 * (-1.0 + u)
    for i in range(2 * ni, m):
        out[i] = c0 * y0[i] + c1 * h * f0[i] + c2 * y1[i] + c3 * h * f1[i]
