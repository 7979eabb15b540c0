"""The step control of the compiled DOP853 loop (:mod:`mechdyn.kernels.dop853_numba`).

Hairer's DOP853 (the error norm of orders 5 and 3, step factors within [1/6, 3] with
safety 0.9, the starting step of order 8), over the states y and rates f of the loop; no
kernel evaluations here (the loop makes them).  It is the one step control of the loop,
with and without event functions (SciPy's variant runs only as ``scipy-dop853``).
"""

from __future__ import annotations

import numpy as np

from ..integrate.dop853_tableau import E3, E5, N_STAGES
from .rows_numba import njit

__all__ = ["initial_guess", "initial_step", "error_norm", "too_large", "shrunk", "next_step"]


@njit
def _sizes2(y, f, atol, rtol):
    """(|y|^2, |f|^2) in the error weights 1 / (atol_i + rtol |y_i|), for the starting
    step."""
    dny = 0.0
    dnf = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        dnf += (f[i] / sk) ** 2
        dny += (y[i] / sk) ** 2
    return dny, dnf


@njit
def initial_guess(y, f, atol, rtol, hmax):
    """Hairer's starting step for order 8, first part: ``(h, |f|^2)``."""
    dny, dnf = _sizes2(y, f, atol, rtol)
    h = 1e-6 if (dnf <= 1e-10 or dny <= 1e-10) else 0.01 * np.sqrt(dny / dnf)
    return min(h, hmax), dnf


@njit
def _change2(y, f, f1, atol, rtol):
    """sum_i ((f1_i - f_i) / (atol_i + rtol |y_i|))^2, for the starting step."""
    acc = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        acc += ((f1[i] - f[i]) / sk) ** 2
    return acc


@njit
def initial_step(y, f, f1, h, dnf, atol, rtol, hmax):
    """Hairer's starting step, second part, from f1 = f(t + h, y + h f)."""
    der2 = np.sqrt(_change2(y, f, f1, atol, rtol)) / h
    der12 = max(der2, np.sqrt(dnf))
    h1 = max(1e-6, h * 1e-3) if der12 <= 1e-15 else (0.01 / der12) ** (1.0 / 8.0)
    return min(100.0 * h, h1, hmax)


@njit
def error_norm(y, ynew, K, atol, rtol, h):
    """The error of the step of size ``h`` from ``y`` to ``ynew`` with the stages ``K``:
    the embedded orders 5 and 3 combined as in DOP853, in the weights atol_i + rtol
    max(|y_i|, |ynew_i|); inf where it is NaN."""
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


@njit
def too_large(err):
    """Whether a step of error ``err`` is rejected."""
    return err > 1.0


@njit
def shrunk(h, err, fac11):
    """The step to try after a rejected step ``h`` of error ``err`` (``fac11``: err to the
    power 1/8 - beta / 5)."""
    return h / min(3.0, fac11 / 0.9)


@njit
def next_step(h, err, fac11, beta, err_old):
    """``(h_next, err_kept)``: the step after an accepted step ``h`` of error ``err``
    (the PI control with ``beta`` over the error kept from the step before, ``err_old``;
    beta 0: from ``err`` alone) and the error to keep for the next one."""
    fac = fac11 / err_old ** beta if beta != 0.0 else fac11
    fac = max(1.0 / 6.0, min(3.0, fac / 0.9))
    return h / fac, max(err, 1e-4)
