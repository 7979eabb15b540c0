"""The dense output of order 7 of a DOP853 step, written once for Python and for the
compiled loop.

:func:`dense_coefficients` makes the seven coefficients of the continuous extension of a
step from its 16 stages (the twelve of the step, the rates at its end, and the three
more of the dense output, :data:`~mechdyn.integrate.dop853_tableau.D`);
:func:`dense_at` evaluates it.  Plain Python functions that Numba can compile (scalar
loops, nothing Python-only, no calls to other functions of this package): the Python
stepper's :class:`mechdyn.integrate.dop853.DenseDOP853` calls them as they are and
:mod:`mechdyn.kernels.dop853_dense` compiles these same functions for the compiled loop,
so both interpolate alike (this file is part of the kernels' cache digest,
:func:`mechdyn.kernels.sources_digest`).

Examples
--------
>>> import numpy as np
>>> K = np.ones((16, 1))  # y' = 1 from y = 0 over a step of 2 s
>>> dns = np.empty((7, 1))
>>> dense_coefficients(np.zeros(1), np.full(1, 2.0), K[0], K[12], K, 2.0, dns)
>>> out = np.empty(1)
>>> dense_at(dns, np.zeros(1), 0.0, 2.0, 0.5, out)
>>> out.round(12).tolist()
[0.5]
"""

from __future__ import annotations

import numpy as np

from .dop853_tableau import N_EXTENDED, D

__all__ = ["dense_coefficients", "dense_at"]


def dense_coefficients(y: np.ndarray, ynew: np.ndarray, f: np.ndarray, fnew: np.ndarray,
                       K: np.ndarray, h: float, dns: np.ndarray) -> None:
    """The seven coefficients of the dense output of a step into ``dns``.

    Parameters
    ----------
    y, ynew : ndarray, shape (m,)
        The step's start and end (units of y).
    f, fnew : ndarray, shape (m,)
        The rates there (units of y per second).
    K : ndarray, shape (16, m)
        The rates at the 16 stages (the 13th at the step's end, the last three those of
        the dense output).
    h : float
        The step, s.
    dns : ndarray, shape (7, m)
        Out: the coefficients (units of y), for :func:`dense_at`.

    Examples
    --------
    >>> import numpy as np
    >>> K, dns = np.zeros((16, 2)), np.empty((7, 2))  # y' = 0
    >>> dense_coefficients(np.ones(2), np.ones(2), K[0], K[12], K, 0.1, dns)
    >>> bool(np.all(dns == 0.0))
    True
    """
    for i in range(y.size):
        dy = ynew[i] - y[i]
        dns[0, i] = dy
        dns[1, i] = h * f[i] - dy
        dns[2, i] = 2.0 * dy - h * (f[i] + fnew[i])
        for k in range(4):
            acc = 0.0
            for j in range(N_EXTENDED):
                acc += D[k, j] * K[j, i]
            dns[3 + k, i] = h * acc


def dense_at(dns: np.ndarray, y_old: np.ndarray, t_old: float, h: float, ts: float,
             out: np.ndarray) -> None:
    """The dense output of a step at ``ts`` into ``out``.

    Parameters
    ----------
    dns : ndarray, shape (7, m)
        The step's coefficients (:func:`dense_coefficients`).
    y_old : ndarray, shape (m,)
        Its start (units of y).
    t_old, h : float
        Its start and size, s (``h`` 0: the step's end).
    ts : float
        The time, s, within the step.
    out : ndarray, shape (m,)
        Out: the state at ``ts``.

    Examples
    --------
    >>> import numpy as np
    >>> dns = np.zeros((7, 1))
    >>> dns[0] = 3.0  # y moves by 3 in the step: 1 at its end
    >>> out = np.empty(1)
    >>> dense_at(dns, np.full(1, -2.0), 1.0, 0.5, 1.5, out)
    >>> out.tolist()
    [1.0]
    """
    s = (ts - t_old) / h if h != 0.0 else 1.0
    s1 = 1.0 - s
    for i in range(y_old.size):
        out[i] = y_old[i] + s * (dns[0, i] + s1 * (dns[1, i] + s * (dns[2, i] + s1 * (
            dns[3, i] + s * (dns[4, i] + s1 * (dns[5, i] + s * dns[6, i]))))))
