"""The arrays a mode's kernel runs the compiled loops on, and the warm-up runs of the loops.

The compiled DOP853 loop (:mod:`mechdyn.kernels.dop853_numba`) and the fixed-step loop
(:mod:`mechdyn.kernels.fixed_step_numba`) take a kernel's packed arrays and its work
array with the buffers of :class:`LoopBuffers` (allocated once per kernel, made on first
use by :func:`buffers`).  The segment loop drives them
(:mod:`mechdyn.simulate.compiled_loop`); here are the arrays, whose types are the loops'
compiled signature, and the warm-up runs that compile (or load) the loops on them
(:func:`warm_up_dop853`, :func:`warm_up_fixed_step`: the groups ``"integration loop"``
and ``"fixed-step loop"`` of :data:`mechdyn.dynamics.compiled.GROUPS`), so that a kernel
compiles its loop on first use and ``mechdyn.warmup()`` compiles the types a run passes.
"""

from __future__ import annotations

import numpy as np

from ..kernels import dop853_numba as L
from ..kernels import fixed_step_numba as F
from ..kernels.dop853_dense import kept_offsets
from ..kernels.lagrange_numba import D_NC, D_NQ, scratch_size
from ..kernels.loads_numba import H_NTAB

__all__ = ["LoopBuffers", "buffers", "warm_up_dop853", "warm_up_fixed_step", "BATCH_SAMPLES",
           "KEEP_STEPS"]

#: output samples per call of the compiled loop
BATCH_SAMPLES = 1024
#: steps per call of the compiled loop in a segment with event functions: the steps of a
#: call after an event are taken in vain, and a call costs little beside the Python checks
#: of a step (press_cycle 0.4 s: 1 -> 9228 evaluations and 0.10 s in the loop, 4 -> 9844,
#: 64 -> 12307 and 0.15 s)
KEEP_STEPS = 1


class LoopBuffers:
    """The arrays of one kernel's loop (allocated once per kernel and reused).

    Attributes
    ----------
    dims : tuple of int
        ``(n_x, n_i, n_q, n_c, m)``, m = 2 n_i + 1 the size of the state (q_I, q_I', w).
    par, ipar : ndarray
        The loops' scalars (float and int; the DOP853 loop's, then the fixed-step's).
    hist : ndarray, shape (3, 2 m + 1)
        The last three accepted steps' ends, t | y | f.
    dns : ndarray, shape (7, m)
        The dense output of the last step.
    o_t, o_y, o_x, o_xd, o_ext : ndarray
        The output samples of a call: times, states, poses, body rates and the extended
        evaluation (x'' | q | q' | q'' | lambda | F).
    kept : ndarray
        The steps kept by a call in a segment with event functions
        (:func:`mechdyn.kernels.dop853_dense.kept_parts`).
    """

    def __init__(self, kernel):
        nx, ni = kernel.n_x, kernel.n_i
        nq, nc = int(kernel.dims[D_NQ]), int(kernel.dims[D_NC])
        m = 2 * ni + 1
        n_ext = nx + 3 * nq + nc + nx
        cap = BATCH_SAMPLES
        self.dims = (nx, ni, nq, nc, m)
        self.f, self.ynew, self.ys = np.empty(m), np.empty(m), np.empty(m)
        self.K = np.empty((16, m))
        self.hist = np.zeros((3, 2 * m + 1))
        self.dns = np.zeros((7, m))
        self.o_t, self.o_y = np.empty(cap), np.empty((cap, m))
        self.o_x, self.o_xd, self.o_ext = np.empty((cap, nx)), np.empty((cap, nx)), \
            np.empty((cap, n_ext))
        self.ext, self.ext_end, self.x_end = np.empty(n_ext), np.empty(n_ext), np.empty(3 * nx)
        self.sc = np.empty(scratch_size(nx, ni, nq, int(kernel.dims[3])))
        self.piv = np.empty(nx + 1, dtype=np.int64)
        self.par = np.zeros(F.N_PAR_FIXED)  # the DOP853 loop's scalars, then the fixed-step's
        self.ipar = np.zeros(F.N_IPAR_FIXED, dtype=np.int64)
        self.kept = np.empty((KEEP_STEPS, kept_offsets(m)[-1] + kernel.ws.size))
        self.kv = np.zeros(4 * int(kernel.ip[H_NTAB]))  # held table pieces

    def restart(self) -> None:
        """Clear what a new set of buffers has cleared (for a kernel used again)."""
        self.hist[:] = 0.0
        self.dns[:] = 0.0
        self.par[:] = 0.0
        self.ipar[:] = 0


def buffers(kernel) -> LoopBuffers:
    """The loop's arrays of ``kernel`` (a :class:`~mechdyn.dynamics.compiled.CompiledKernel`;
    made on first use, kept on the kernel)."""
    b = getattr(kernel, "_loop_buffers", None)
    if b is None:
        b = kernel._loop_buffers = LoopBuffers(kernel)
    return b


def _warm_up_buffers(kernel):
    """The loop buffers of ``kernel`` and a start state (q_I = 0.3, q_I' = 1) for a warm-up
    run of a compiled loop."""
    b = buffers(kernel)
    _, ni, _, _, m = b.dims
    y = np.zeros(m)
    y[:ni], y[ni:2 * ni] = 0.3, 1.0
    b.par[:], b.ipar[:] = 0.0, 0
    b.par[L.P_LAST] = -np.inf
    b.ipar[L.I_MAXSTEPS] = 10
    return b, y


def warm_up_dop853(kernel) -> None:
    """Compile (or load) the DOP853 loop on a kernel: one short run without output."""
    b, y = _warm_up_buffers(kernel)
    m = y.size
    b.par[L.P_TEND], b.par[L.P_RTOL], b.par[L.P_HMAX] = 1e-3, 1e-6, np.inf
    L.run(y, b.f, np.full(m, 1e-9), b.par, b.ipar, b.K, b.ynew, b.ys, b.hist, b.dns,
          np.zeros(0), b.o_t, b.o_y, b.o_x, b.o_xd, b.o_ext, b.ext, b.ext_end, b.x_end,
          *kernel.arrays, kernel.ws, b.sc, b.piv, b.kept, b.kv)


def warm_up_fixed_step(kernel) -> None:
    """Compile (or load) the fixed-step loop on a kernel: a short run of RK4 and one of
    Wilson's method (one compilation for both)."""
    for method in (F.RK4, F.WILSON):
        b, y = _warm_up_buffers(kernel)
        b.par[F.P_TOL], b.par[F.P_THETA] = 1e-12, 1.0
        b.ipar[F.I_METHOD], b.ipar[F.I_ITER] = method, 2
        F.run(y, b.f, np.linspace(0.0, 1e-3, 3), b.par, b.ipar, b.K, b.ynew, b.ys, b.hist,
              np.zeros(0), b.o_t, b.o_y, b.o_x, b.o_xd, b.o_ext, b.ext, b.ext_end, b.x_end,
              *kernel.arrays, kernel.ws, b.sc, b.piv, b.kept)
