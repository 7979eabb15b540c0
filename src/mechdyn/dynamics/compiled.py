"""Compiled (Numba) evaluation of the exact equations of motion in any mode.

:class:`CompiledKernel` holds one mode's packed arrays and its work array and calls
the compiled functions of :mod:`mechdyn.kernels.lagrange_numba` (position solve,
analogs, Lagrange II in the mode's independent coordinates with the drives' rotor
and gear inertia, multipliers from the same factorization); the same mathematics as
:mod:`mechdyn.dynamics.lagrange` and :mod:`mechdyn.dynamics.mode_system` (the NumPy
references; tests check that they agree to 1e-12).  :func:`compile_mode_kernel`
packs a mode (its rows, :mod:`mechdyn.model.rows`; the loads,
:mod:`mechdyn.kernels.loads_numba`) and compiles the functions on first use -- once
for every model and every mode, cached on disk, announced on stderr when it takes a
while.
"""

from __future__ import annotations

import time

import numpy as np

from ..kernels.block_lu import block_order
from ..kernels.lagrange_numba import (
    D_NC,
    D_NI,
    D_NQ,
    N_FLAGS,
    W_COUNT,
    W_PIVOT,
    W_VALID,
    first_order,
    full,
    work_size,
)
from ..kernels.loads_numba import H_NTAB, LoadPacker, Unsupported
from ..kernels.rows_numba import NUMBA, compiling, rows_jacobian
from ..mechanism.mechanism import Mechanism
from ..model import Model
from ..model.forces import force_model
from ..model.rows import concat
from ..model.variable import lower, parse
from ..model.workspace import Workspace
from .loop_buffers import warm_up_dop853, warm_up_fixed_step

__all__ = ["compile_mode_kernel", "CompiledKernel", "numba_available", "ensure_compiled",
           "warm_up_groups", "GROUPS"]


_NUMBA = NUMBA  # the switch the package reads (tests turn it off)


def numba_available() -> bool:
    """Whether the compiled backend can be used."""
    return _NUMBA


class CompiledKernel:
    """Compiled evaluation of one mode's equations of motion, with its Newton cache.

    Attributes
    ----------
    compile_time : float
        Seconds spent compiling or loading the cached machine code (first use in a
        process; 0 afterwards).
    status : int
        Status of the last call (0 ok, 1 position solve failed, 2 singular mass
        matrix, 3 non-finite).
    """

    def __init__(self, ip, fp, ri, rf, dims, n_x, compile_time):
        self.ip, self.fp, self.ri, self.rf, self.dims = ip, fp, ri, rf, dims
        self._arrays = (ip, fp, ri, rf, dims)
        self.n_x, self.n_i = n_x, int(dims[D_NI])
        self.ws = np.zeros(work_size(n_x, self.n_i, int(ip[H_NTAB])))
        self.compile_time = compile_time
        self.status = 0
        self._st = np.zeros(1, dtype=np.int64)
        # the parts of ``full``'s extended output: x'' | q | q' | q'' | lambda | F
        nq, nc = int(dims[D_NQ]), int(dims[D_NC])
        ends = np.cumsum([0, n_x, nq, nq, nq, nc, n_x]).tolist()
        self._ext_size = ends[-1]
        self._ext_parts = tuple(zip(ends[:-1], ends[1:], strict=True))

    @property
    def arrays(self) -> tuple:
        """The packed arrays ``(ip, fp, ri, rf, dims)`` the compiled functions take."""
        return self._arrays

    @property
    def x(self) -> np.ndarray:
        """The last solved pose (n_x,) (a view)."""
        return self.ws[:self.n_x]

    @property
    def xdot(self) -> np.ndarray:
        """Body velocities (n_x,) of the last evaluation (a view)."""
        o = self.n_x + self.n_i + self.n_x * self.n_i
        return self.ws[o:o + self.n_x]

    @property
    def pivot_ratio(self) -> float:
        """min |u_ii| / max |u_ii| of the LU of the scaled position Jacobian (a cheap
        indicator of a near-singular position)."""
        return float(self.ws[-N_FLAGS + W_PIVOT])

    @property
    def B(self) -> np.ndarray:
        """Velocity analogs (n_x, n_i) of the last evaluation."""
        o = self.n_x + self.n_i
        return self.ws[o:o + self.n_x * self.n_i].reshape(self.n_x, self.n_i)

    def reset(self, x) -> None:
        """Restart the Newton continuation from pose x."""
        self.ws[:self.n_x] = x
        self.ws[-N_FLAGS + W_VALID] = 0.0

    def _run(self, fn, t, *args):
        """``fn(t, *args, <packed arrays>, status)``; False where the kernel failed (see
        ``status``)."""
        try:
            self._out = fn(float(t), *args, self._st)
        except ZeroDivisionError:  # e.g. a spring whose ends meet: the NumPy path names it
            self._st[0] = 3
        self.status = int(self._st[0])
        return not self.status

    def rhs(self, t, q, qdot):
        """(q_I'', array([P_nc])) or None on failure (see ``status``)."""
        n = self.n_i
        self.ensure("first-order f")
        y = np.concatenate([q, qdot, [0.0]])
        if not self._run(first_order, t, y, *self._arrays, self.ws):
            return None
        return self._out[n:2 * n], self._out[2 * n:]

    def evaluation(self, t, q, qdot):
        """Everything at one state, or None on failure (see ``status``): ``(x, xdot,
        xddot, q, qdot, qddot, lam, F)``, x and its rates (n_x,), every declared
        coordinate (n_q,), the multipliers (n_c,) of the constraint rows
        (M x'' + h - F = Phi_x^T lambda) and the applied forces with the drives (n_x,)."""
        ext = np.empty(self._ext_size)
        if not self._run(full, t, np.asarray(q, np.float64), np.asarray(qdot, np.float64),
                         *self._arrays, self.ws, np.empty(2 * self.n_i + 1), ext):
            return None
        return (self.x.copy(), self.xdot.copy(), *(ext[a:b] for a, b in self._ext_parts))

    def ensure(self, group: str) -> None:
        """Compile ``group`` (:data:`GROUPS`) on its first use in this process, its time
        added to :attr:`compile_time` (the segment loop asks for the group of its
        compiled loop, :mod:`mechdyn.simulate.compiled_loop`)."""
        if group not in _COMPILED:
            self.compile_time += ensure_compiled(group)

    def snapshot(self) -> np.ndarray:
        """A copy of the workspace (last pose, analogs, flags), for :meth:`restore`."""
        return self.ws.copy()

    def restore(self, saved: np.ndarray) -> None:
        """Put back a :meth:`snapshot` (the evaluation count goes on): evaluations made in
        between (a dense output probed by a check) leave the run as it was."""
        count = self.ws[-N_FLAGS + W_COUNT]
        self.ws[:] = saved
        self.ws[-N_FLAGS + W_COUNT] = count

    @property
    def evaluations(self) -> int:
        """Evaluations of the equations by this kernel so far."""
        return int(self.ws[-N_FLAGS + W_COUNT])

    def first_order_function(self, on_failure):
        """A function ``fun(t, y) -> y'`` for y = (q_I, q_I', w) calling the kernel directly
        (the path with the least Python per evaluation); ``on_failure(t, y)`` is called
        (and must return y' or raise) when the kernel reports a failure."""
        self.ensure("first-order f")
        ip, fp, ri, rf, dims, ws, st = (self.ip, self.fp, self.ri, self.rf, self.dims,
                                        self.ws, self._st)
        kern = first_order

        def fun(t, y):
            try:
                out = kern(t, y, ip, fp, ri, rf, dims, ws, st)
            except ZeroDivisionError:  # the NumPy path (on_failure) names the cause
                st[0] = 3
            if st[0]:
                self.status = int(st[0])
                return on_failure(t, y)
            return out

        return fun


#: the groups of compiled functions, each compiled (or loaded from the disk cache) on its
#: first use in a process: what it is called on stderr and what runs it on the warm-up
#: pendulum (:func:`_pendulum_kernel`).  A run compiles only the groups it uses: a
#: DOP853 run the dynamics and the DOP853 loop, not the fixed-step loop or SciPy's f.
GROUPS = {
    "dynamics": "numba kernels of the dynamics",
    "integration loop": "compiled integration loop (DOP853) of the dynamics",
    "fixed-step loop": "compiled fixed-step loop (RK4, Wilson) of the dynamics",
    "first-order f": "compiled first-order f of the dynamics (SciPy's methods)",
    "turning check": "compiled position Jacobian of the turning-point check",
}

#: the seconds each group took to compile (or load) in this process, once compiled
_COMPILED: dict[str, float] = {}


def _pendulum_kernel() -> CompiledKernel:
    """The kernel of a small pendulum (a bar pinned to the ground, its angle as
    coordinate, gravity) the groups are compiled on: the kernels are generic over their
    arrays, so compiling them on this model compiles them for every model -- and never
    evaluates a user's model at a position its run does not visit (a spring whose ends
    meet at the sketch ...)."""
    mech = Mechanism("warm-up pendulum", gravity=(0.0, -9.81))
    mech.add_body("bar", mass=1.0, inertia=0.1, com=(0.5, 0.0), pose=(0.0, 0.0, 0.0))
    mech.add_revolute("O", "ground", "bar")
    mech.add_coordinate("theta", kind="angle", body="bar")
    model = Model(mech)
    ri, rf = concat(model.n_bodies, model.joint_rows, model.coordinate_rows,
                    model.coordinate_rows).packed()
    dims = np.array([len(model.joint_rows), 1, 1, 0], dtype=np.int64)
    kernel = CompiledKernel(*LoadPacker(model, force_model(model)).pack(), ri, rf, dims,
                            model.n_x, 0.0)
    kernel.reset(model.x_sketch)
    return kernel


def _compile_group(group: str, kernel: CompiledKernel) -> None:
    """Run the functions of ``group`` once on the pendulum ``kernel``."""
    if group == "dynamics":
        kernel.evaluation(0.0, [0.3], [1.0])
    elif group == "first-order f":  # (not through kernel.rhs, which would ask for it)
        first_order(0.0, np.array([0.3, 1.0, 0.0]), *kernel._arrays, kernel.ws, kernel._st)
    elif group == "integration loop":
        warm_up_dop853(kernel)
    elif group == "fixed-step loop":
        warm_up_fixed_step(kernel)
    else:  # the rows' Jacobian as the turning-point check calls it (dead_position)
        _, _, ri, rf, _ = kernel.arrays
        rows_jacobian(np.zeros(kernel.n_x), kernel.n_x // 3, ri, rf,
                      np.zeros((len(ri), kernel.n_x)), 0)


def ensure_compiled(*groups: str) -> float:
    """Compile (or load from the disk cache) the ``groups`` (keys of :data:`GROUPS`) not
    compiled yet in this process, each announced on stderr when it takes longer than a
    few seconds (the first run of a fresh installation); returns the seconds it took.

    Examples
    --------
    >>> ensure_compiled("dynamics") >= 0.0
    True
    """
    todo = [g for g in groups if g not in _COMPILED]
    if not todo or not _NUMBA:
        return 0.0
    t0 = time.perf_counter()
    kernel = _pendulum_kernel()
    for group in todo:
        t1 = time.perf_counter()
        with compiling(GROUPS[group]):
            _compile_group(group, kernel)
        _COMPILED[group] = time.perf_counter() - t1
    return time.perf_counter() - t0


def warm_up_groups() -> dict[str, float]:
    """Compile (or load) every group of compiled functions of the dynamics now
    (:data:`GROUPS`); returns the wall time of each, s (0 for groups compiled earlier in
    this process).

    Examples
    --------
    >>> sorted(warm_up_groups()) == sorted(GROUPS) if numba_available() else True
    True
    """
    fresh = [g for g in GROUPS if g not in _COMPILED]
    ensure_compiled(*GROUPS)
    return {g: (_COMPILED.get(g, 0.0) if g in fresh else 0.0) for g in GROUPS}


def compile_mode_kernel(model, force_model, constraint_rows, independent, *, kept=None):
    """The compiled kernel of a mode, or ``(None, reason)``.

    Parameters
    ----------
    model : Model
    force_model : ForceModel
        The model's loads (:func:`mechdyn.model.forces.force_model`).
    constraint_rows : Rows
        The mode's independent constraint rows (joints, engaged locks, closed stops
        and contacts, sticking rows), n_c of them.
    independent : sequence of int
        Indices of the declared coordinates that are independent in the mode
        (n_i of them, n_c + n_i = n_x).
    kept : dict, optional
        Where the packed arrays of the modes of a run are kept
        (:attr:`Workspace.kernels <mechdyn.model.workspace.Workspace>`).

    Returns
    -------
    kernel : CompiledKernel or None
    note : str
        Why the compiled path is not used, or ``""``.
    """
    if not _NUMBA:
        return None, "numba is not installed (pip install mechdyn[fast])"
    independent = np.asarray(independent, dtype=np.int64).reshape(-1)
    if model.n_x == 0 or independent.size == 0:
        return None, "nothing to compile"
    if len(constraint_rows) + independent.size != model.n_x:
        return None, "redundant constraints (non-square position Jacobian)"
    # the packed arrays of a mode are kept in ``kept``: a run (or the next run given the
    # same workspace) that meets the same rows again (the same targets) only allocates a
    # new kernel workspace
    ints, flts = constraint_rows.packed()
    key = None if kept is None else (independent.tobytes(), ints.tobytes(), flts.tobytes())
    packed = None if key is None else kept.get(key)
    if packed is None:
        packer = LoadPacker(model, force_model, variable=lambda name: _variable(model, name))
        try:
            ip, fp = packer.pack()
        except Unsupported as exc:
            packed = str(exc)
        else:
            crd = model.coordinate_rows
            var = concat(model.n_bodies, *packer.variable_rows)
            ri, rf = concat(model.n_bodies, constraint_rows, crd.take(independent), crd,
                            var).packed()
            n_sq = len(constraint_rows) + independent.size  # the square block
            order = block_order(ri[:n_sq], rf[:n_sq], model.n_bodies)
            dims = np.concatenate([[len(constraint_rows), independent.size, model.n_q,
                                    len(var)], order]).astype(np.int64)
            packed = (ip, fp, ri, rf, dims)
        if kept is not None:
            Workspace.keep(kept, key, packed)
    if isinstance(packed, str):
        return None, packed
    return CompiledKernel(*packed, model.n_x, ensure_compiled("dynamics")), ""


def _variable(model, name: str):
    """A table variable for :class:`LoadPacker`, read with the one grammar
    (:mod:`mechdyn.model.variable`): ``(kind, ref)``."""
    var = parse(name, model.coordinate_names)
    if var.kind == "time":
        return "t", None
    if var.kind == "coordinate":
        return ("qdot" if var.rate else "q"), model.coordinate_index(var.name)
    if var.kind == "distance" or var.rate:
        return None, None
    return "row", lower(model, var)
