"""Hairer's DOP853 step control, written once for Python and for the compiled loop.

The starting step of order 8 (:func:`initial_guess`, then :func:`initial_step` from one
trial evaluation), the error norm of the embedded orders 5 and 3 (:func:`error_norm`) and
the step factors within [``FAC_MIN``, ``FAC_MAX``] = [1/6, 3] with safety ``SAFETY`` = 0.9
(:func:`error_factor`, :func:`too_large`, :func:`shrunk`, :func:`next_step`), as in
Hairer's code DOP853, over the states ``y`` and rates ``f`` of a step; no evaluations here
(the steppers make them).

These are plain Python functions that Numba can compile: scalar loops over NumPy arrays,
module constants, no calls to other functions of this package and nothing Python-only.
The Python stepper (:func:`mechdyn.integrate.dop853.dop853_steps`) calls them as they
are; :mod:`mechdyn.kernels.dop853_control` compiles these same functions with the
kernels' ``njit`` for the compiled loop (:mod:`mechdyn.kernels.dop853_numba`), so both
take the same steps.  A compiled function resolves its globals in the module it is
defined in, so none of these calls another plain function: each is whole in itself, and
the constants it reads become constants of the compiled code (this file is part of the
kernels' cache digest, :func:`mechdyn.kernels.sources_digest`).

Examples
--------
>>> import numpy as np
>>> y, f, atol = np.array([1.0, 0.0]), np.array([0.0, -1.0]), np.full(2, 1e-8)
>>> h, dnf = initial_guess(y, f, atol, 1e-6, np.inf)
>>> f1 = np.array([-h, -1.0])  # the rates of y'' = -y at t + h, y + h f
>>> bool(0.0 < initial_step(y, f, f1, h, dnf, atol, 1e-6, np.inf) < 1.0)
True
"""

from __future__ import annotations

import numpy as np

from .dop853_tableau import E3, E5, N_STAGES

__all__ = ["SAFETY", "FAC_MIN", "FAC_MAX", "ERR_MIN", "initial_guess", "initial_step",
           "error_norm", "error_factor", "too_large", "shrunk", "next_step"]

#: Hairer's safety factor and the bounds of the step factor h / h_next
SAFETY, FAC_MIN, FAC_MAX = 0.9, 1.0 / 6.0, 3.0
#: the least error kept for the PI control of the next step
ERR_MIN = 1e-4


def initial_guess(y: np.ndarray, f: np.ndarray, atol: np.ndarray, rtol: float,
                  hmax: float) -> tuple[float, float]:
    """Hairer's starting step of order 8, first part: a guess from the sizes of ``y`` and
    ``f`` in the error weights ``1 / (atol_i + rtol |y_i|)``.

    Parameters
    ----------
    y, f : ndarray, shape (m,)
        State and rates at the start (units of y, and of y per second).
    atol : ndarray, shape (m,)
        Absolute tolerances (units of y).
    rtol : float
        Relative tolerance.
    hmax : float
        Largest step, s.

    Returns
    -------
    h : float
        The guess, s, for the trial evaluation at ``(t + h, y + h f)``.
    dnf : float
        ``|f|^2`` in the weights, for :func:`initial_step`.

    Examples
    --------
    >>> import numpy as np
    >>> h, dnf = initial_guess(np.ones(2), np.full(2, 10.0), np.zeros(2), 1e-6, 1.0)
    >>> float(h), float(dnf)  # 0.01 |y| / |f|; 2 (10 / 1e-6)^2
    (0.001, 200000000000000.0)
    """
    dny = 0.0
    dnf = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        dnf += (f[i] / sk) ** 2
        dny += (y[i] / sk) ** 2
    h = 1e-6 if (dnf <= 1e-10 or dny <= 1e-10) else 0.01 * np.sqrt(dny / dnf)
    return min(h, hmax), dnf


def initial_step(y: np.ndarray, f: np.ndarray, f1: np.ndarray, h: float, dnf: float,
                 atol: np.ndarray, rtol: float, hmax: float) -> float:
    """Hairer's starting step of order 8, second part, from the rates ``f1`` at
    ``(t + h, y + h f)`` (``h``, ``dnf``: :func:`initial_guess`).

    Parameters
    ----------
    y, f, f1 : ndarray, shape (m,)
        State and rates at the start, rates at the trial point.
    h, dnf : float
        The guess, s, and ``|f|^2`` in the error weights.
    atol, rtol, hmax
        The tolerances and the largest step, as for :func:`initial_guess`.

    Returns
    -------
    float
        The starting step, s: at most 100 h and ``hmax``.

    Examples
    --------
    >>> import numpy as np
    >>> y, f = np.zeros(1), np.ones(1)  # y' = 1: no second derivative
    >>> float(initial_step(y, f, f, 1e-6, 1e16, np.ones(1) * 1e-8, 1e-6, 1e-5))  # hmax
    1e-05
    """
    acc = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        acc += ((f1[i] - f[i]) / sk) ** 2
    der2 = np.sqrt(acc) / h
    der12 = max(der2, np.sqrt(dnf))
    h1 = max(1e-6, h * 1e-3) if der12 <= 1e-15 else (0.01 / der12) ** (1.0 / 8.0)
    return min(100.0 * h, h1, hmax)


def error_norm(y: np.ndarray, ynew: np.ndarray, K: np.ndarray, atol: np.ndarray,
               rtol: float, h: float) -> float:
    """The error of the step of size ``h`` from ``y`` to ``ynew`` with the stages ``K``:
    the embedded orders 5 and 3 combined as in DOP853, in the weights ``atol_i + rtol
    max(|y_i|, |ynew_i|)``; inf where it is NaN.

    Parameters
    ----------
    y, ynew : ndarray, shape (m,)
        The step's start and end (units of y).
    K : ndarray, shape (>= 12, m)
        The rates at the stages (units of y per second).
    atol : ndarray, shape (m,)
        Absolute tolerances (units of y).
    rtol, h : float
        Relative tolerance; the step, s.

    Returns
    -------
    float
        The error in units of the tolerance (the step is rejected above 1,
        :func:`too_large`).

    Examples
    --------
    >>> import numpy as np
    >>> K = np.ones((12, 2))  # constant rates: both embedded errors vanish
    >>> float(error_norm(np.zeros(2), np.ones(2), K, np.full(2, 1e-8), 1e-6, 1.0)) < 1e-6
    True
    >>> float(error_norm(np.zeros(1), np.zeros(1), np.full((12, 1), np.nan), np.ones(1),
    ...                  1e-6, 1.0))
    inf
    """
    m = y.size
    e5n = 0.0
    e3n = 0.0
    for i in range(m):
        sk = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
        a5 = 0.0
        a3 = 0.0
        for j in range(N_STAGES):
            a5 += E5[j] * K[j, i]
            a3 += E3[j] * K[j, i]
        e5n += (a5 / sk) ** 2
        e3n += (a3 / sk) ** 2
    deno = e5n + 0.01 * e3n
    err = abs(h) * e5n / np.sqrt(m * (deno if deno > 0.0 else 1.0))
    if not err == err:
        err = np.inf
    return err


def error_factor(err: float, beta: float) -> float:
    """``err ** (1/8 - beta / 5)``: the factor of the error in the step control (beta 0:
    Hairer's DOP853, from the last error alone; else the PI control).

    Parameters
    ----------
    err : float
        The step's error in units of the tolerance (:func:`error_norm`).
    beta : float
        Exponent of the PI control.

    Returns
    -------
    float

    Examples
    --------
    >>> error_factor(256.0, 0.0)
    2.0
    """
    return err ** (0.125 - 0.2 * beta)


def too_large(err: float) -> bool:
    """Whether a step of error ``err`` (in units of the tolerance) is rejected.

    Examples
    --------
    >>> too_large(1.0), too_large(1.5)
    (False, True)
    """
    return err > 1.0


def shrunk(h: float, err: float, fac11: float) -> float:
    """The step to try after a rejected step ``h`` of error ``err``.

    Parameters
    ----------
    h, err, fac11 : float
        The rejected step, s, its error in units of the tolerance and the
        :func:`error_factor` of that error.

    Returns
    -------
    float
        The shorter step, s (at least ``h / FAC_MAX``).

    Examples
    --------
    >>> shrunk(0.3, 1e9, error_factor(1e9, 0.0))
    0.09999999999999999
    """
    return h / min(FAC_MAX, fac11 / SAFETY)


def next_step(h: float, err: float, fac11: float, beta: float,
              err_old: float) -> tuple[float, float]:
    """The step after an accepted step ``h`` of error ``err``, and the error to keep.

    Parameters
    ----------
    h, err, fac11 : float
        The accepted step, s, its error in units of the tolerance and the
        :func:`error_factor` of that error.
    beta : float
        Exponent of the PI control over the error kept from the step before (0: from
        ``err`` alone, Hairer's DOP853).
    err_old : float
        The error kept from the step before.

    Returns
    -------
    h_next : float
        The next step to try, s (h / 3 to 6 h; the caller keeps it no longer than ``h``
        right after a rejection).
    err_kept : float
        ``max(err, ERR_MIN)``, the ``err_old`` of the next step.

    Examples
    --------
    >>> next_step(0.1, 0.0, error_factor(0.0, 0.0), 0.0, ERR_MIN)
    (0.6000000000000001, 0.0001)
    """
    fac = fac11 / err_old ** beta if beta != 0.0 else fac11
    fac = max(FAC_MIN, min(FAC_MAX, fac / SAFETY))
    return h / fac, max(err, ERR_MIN)
