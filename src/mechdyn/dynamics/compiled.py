"""Compiled (Numba) evaluation of the exact equations of motion in any mode.

One call of the kernel does, for a state (t, q_I, q_I'), q_I the independent
coordinates of the mode: the Newton position solve of [Phi(x); g_I(x) - q_I] = 0
from the last pose (with the linear predictor x + B (q_I - q_last)), the velocity
analogs B and the acceleration bias b (x'' = B q_I'' + b), the declared
coordinates q = g(x) with their rates and their analogs G B, the mass matrix
A = B_c^T M B_c + sum_drives J_e (G_k B)^T (G_k B) (motor rotor and gear
inertia J_e reduced to the driven coordinate k, whether it is independent or
not), the bias c, the applied forces and Q = B^T (F + G^T Q_drive), the Cholesky
solve for q_I'' and the power of the non-conservative forces.  It is the same
mathematics as :mod:`mechdyn.dynamics.lagrange` (the NumPy reference; tests check
that both agree to 1e-12), written as loops over small dense arrays.

Everything model-specific is data: the constraint rows and coordinate rows of
:mod:`mechdyn.model.rows` (evaluated by :mod:`mechdyn.kernels.rows_numba`) and
the packed loads of :mod:`mechdyn.kernels.loads_numba`.  The compiled functions
are therefore generic: they compile once (cached on disk) for every model and
every mode.  The first use in a fresh installation compiles them, which takes
a while and is announced on stderr.
"""

from __future__ import annotations

import time

import numpy as np

from ..kernels.linalg import cholesky_solve, lu_factor, lu_solve, lu_solve_transposed
from ..kernels.loads_numba import (
    FR_BODY,
    FR_DRV,
    H_FOFF,
    H_IOFF,
    H_NB,
    H_NDRV,
    IR_DRV,
    IR_VAL,
    S_BODY,
    S_DRV,
    LoadPacker,
    Unsupported,
    forces,
)
from ..kernels.rows_numba import (
    NUMBA,
    compiling,
    njit,
    rows_jacobian,
    rows_quad,
    rows_values,
)
from ..mechanism.mechanism import Mechanism
from ..model import Model
from ..model.rows import concat
from ..model.variable import lower, parse
from .forces import force_model

__all__ = ["compile_kernel", "compile_mode_kernel", "CompiledKernel", "numba_available"]


# dims: n_c (constraint rows), n_i (independent coordinates), n_q (declared coordinates),
# n_v (rows of table variables); the row arrays hold these four blocks in this order
D_NC, D_NI, D_NQ, D_NV = range(4)
# flags at the end of the work array
W_VALID = 0  # B_last valid
W_PIVOT = 1  # pivot ratio of the last factorisation
W_ITER = 2  # Newton iterations of the last solve
W_ERR = 3  # last Newton residual
W_COUNT = 4  # evaluations of the equations
N_FLAGS = 5


_NUMBA = NUMBA  # the switch the package reads (tests turn it off)


def numba_available() -> bool:
    """Whether the compiled backend can be used."""
    return _NUMBA


def _work_size(n_x: int, n_i: int) -> int:
    """Work array: x | q_last (n_i) | B_last (n_x n_i) | xdot | x_good | flags."""
    return n_x + n_i + n_x * n_i + 2 * n_x + N_FLAGS


# ----------------------------------------------------------------------------- kernels
@njit
def _system(x, qi, ri, rf, dims, nb, F, J):
    """Residual [Phi; g_I - q_I] (F) and Jacobian (J) at pose x."""
    nc, ni = dims[D_NC], dims[D_NI]
    nx = 3 * nb
    for r in range(nx):
        for c in range(nx):
            J[r, c] = 0.0
    rows_values(x, nb, ri[:nc + ni], rf[:nc + ni], F, 0)
    rows_jacobian(x, nb, ri[:nc + ni], rf[:nc + ni], J, 0)
    for c in range(ni):
        F[nc + c] -= qi[c]


@njit
def _scale_cols(J, nx, ls):
    for r in range(nx):
        for b in range(nx // 3):
            J[r, 3 * b + 2] *= ls


@njit
def _newton(qi, fp, ri, rf, dims, ws, J, piv, F, nb):
    """Solve the positions at q_I from the pose in ws; leaves the LU of the scaled
    Jacobian at the solution in (J, piv).  Returns 0 or 1 (no convergence)."""
    nx = 3 * nb
    ni = dims[D_NI]
    ls = fp[2]
    tol = fp[3]
    x = ws[:nx]
    ql = ws[nx:nx + ni]
    Bl = ws[nx + ni:nx + ni + nx * ni]
    flags = ws[ws.size - N_FLAGS:]
    xg = ws[ws.size - N_FLAGS - nx:ws.size - N_FLAGS]
    for r in range(nx):
        xg[r] = x[r]
    if flags[W_VALID] == 1.0:
        for r in range(nx):
            s = 0.0
            for c in range(ni):
                s += Bl[r * ni + c] * (qi[c] - ql[c])
            x[r] += s
    prev = np.inf
    status = 1
    for it in range(40):
        _system(x, qi, ri, rf, dims, nb, F, J)
        err = 0.0
        for r in range(nx):
            a = abs(F[r])
            if not a <= err:  # catches NaN
                err = a if a == a else np.inf
        _scale_cols(J, nx, ls)
        flags[W_PIVOT] = lu_factor(J, piv, nx)
        flags[W_ITER] = it
        flags[W_ERR] = err
        if err <= tol or (err >= 0.5 * prev and err <= 1e3 * tol):
            status = 0
            break
        if not err < np.inf or flags[W_PIVOT] == 0.0:
            break
        prev = err
        lu_solve(J, piv, F, nx)
        for b in range(nb):
            F[3 * b + 2] *= ls
        for r in range(nx):
            x[r] -= F[r]
    if status == 0:
        for c in range(ni):
            ql[c] = qi[c]
    else:  # keep the last good pose for the next start and the diagnosis
        for r in range(nx):
            x[r] = xg[r]
    flags[W_VALID] = 0.0
    return status


@njit
def _body_inertia(fp, ob, b, x):
    """Mass, inertia about the centre of mass and the centre-of-mass arm A(theta) c
    (ground frame) of body b at pose x."""
    m = fp[ob + FR_BODY * b]
    Jc = fp[ob + FR_BODY * b + 1]
    cx, cy = fp[ob + FR_BODY * b + 2], fp[ob + FR_BODY * b + 3]
    th = x[3 * b + 2]
    co, si = np.cos(th), np.sin(th)
    return m, Jc, co * cx - si * cy, si * cx + co * cy


@njit
def _solve_scaled(J, piv, col, nx, nb, ls):
    lu_solve(J, piv, col, nx)
    for b in range(nb):
        col[3 * b + 2] *= ls


@njit
def _evaluate(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, full):
    """q_I'' and P_nc at (t, q_I, q_I'); out = [q_I' | q_I'' | P_nc].  Status: 0 ok,
    1 position solve failed, 2 mass matrix not positive definite, 3 non-finite.

    With ``full``, ``ext`` receives [x'' (n_x) | q | q' | q'' (n_q each) | lambda (n_c) |
    F (n_x)]: the accelerations, every declared coordinate, the multipliers of the
    constraint rows from the same factorization (M x'' + h - F = Phi_x^T lambda, solved
    with the transposed LU of the position Jacobian) and the applied forces on the
    poses, drives included."""
    nb = ip[H_NB]
    nx = 3 * nb
    nc, ni, nq, nv = dims[D_NC], dims[D_NI], dims[D_NQ], dims[D_NV]
    ls = fp[2]
    J = np.empty((nx, nx))
    piv = np.empty(nx, dtype=np.int64)
    F = np.empty(nx)
    ws[ws.size - N_FLAGS + W_COUNT] += 1.0
    st = _newton(qi, fp, ri, rf, dims, ws, J, piv, F, nb)
    if st != 0:
        return st
    x = ws[:nx]
    Bl = ws[nx + ni:nx + ni + nx * ni]
    v = ws[nx + ni + nx * ni:nx + ni + nx * ni + nx]
    flags = ws[ws.size - N_FLAGS:]
    # velocity analogs B (row r, column c stored at r * ni + c)
    col = np.empty(nx)
    for c in range(ni):
        for r in range(nx):
            col[r] = 0.0
        col[nc + c] = 1.0
        _solve_scaled(J, piv, col, nx, nb, ls)
        for r in range(nx):
            Bl[r * ni + c] = col[r]
    flags[W_VALID] = 1.0
    for r in range(nx):
        s = 0.0
        for c in range(ni):
            s += Bl[r * ni + c] * qdi[c]
        v[r] = s
    # acceleration bias: J b = -quad
    bb = np.empty(nx)
    rows_quad(x, v, nb, ri[:nc + ni], rf[:nc + ni], bb, 0)
    for r in range(nx):
        bb[r] = -bb[r]
    _solve_scaled(J, piv, bb, nx, nb, ls)
    # declared coordinates, their rates, analogs G B and bias G b + quad_g
    gi, gf = ri[nc + ni:nc + ni + nq], rf[nc + ni:nc + ni + nq]
    q = np.empty(nq)
    G = np.zeros((nq, nx))
    qdot = np.zeros(nq)
    Gb = np.empty(nq)
    GB = np.zeros((nq, ni))
    rows_values(x, nb, gi, gf, q, 0)
    rows_jacobian(x, nb, gi, gf, G, 0)
    rows_quad(x, v, nb, gi, gf, Gb, 0)
    for k in range(nq):
        for r in range(nx):
            g = G[k, r]
            if g != 0.0:
                qdot[k] += g * v[r]
                Gb[k] += g * bb[r]
                for c in range(ni):
                    GB[k, c] += g * Bl[r * ni + c]
    # mass matrix and c from the centre-of-mass analogs
    A = np.zeros((ni, ni))
    cc = np.zeros(ni)
    ob = ip[H_FOFF + S_BODY]
    bcx = np.empty(ni)
    bcy = np.empty(ni)
    for b in range(nb):
        m, Jc, ax, ay = _body_inertia(fp, ob, b, x)
        w = v[3 * b + 2]
        for i in range(ni):
            bcx[i] = Bl[(3 * b) * ni + i] - ay * Bl[(3 * b + 2) * ni + i]
            bcy[i] = Bl[(3 * b + 1) * ni + i] + ax * Bl[(3 * b + 2) * ni + i]
        sx = bb[3 * b] - ay * bb[3 * b + 2] - w * w * ax
        sy = bb[3 * b + 1] + ax * bb[3 * b + 2] - w * w * ay
        sw = bb[3 * b + 2]
        for i in range(ni):
            bwi = Bl[(3 * b + 2) * ni + i]
            cc[i] += m * (bcx[i] * sx + bcy[i] * sy) + Jc * bwi * sw
            for j in range(i, ni):
                A[i, j] += m * (bcx[i] * bcx[j] + bcy[i] * bcy[j]) + \
                    Jc * bwi * Bl[(3 * b + 2) * ni + j]
    # rotor and gear inertia of the drives, on their (declared) coordinate
    od_i, od_f = ip[H_IOFF + S_DRV], ip[H_FOFF + S_DRV]
    for k in range(ip[H_NDRV]):
        c = ip[od_i + IR_DRV * k + IR_VAL]
        je = fp[od_f + FR_DRV * k + 2]
        if je != 0.0:
            for i in range(ni):
                cc[i] += je * GB[c, i] * Gb[c]
                for j in range(i, ni):
                    A[i, j] += je * GB[c, i] * GB[c, j]
    # forces
    Fa = np.empty(nx)
    Fnc = np.empty(nx)
    Qd = np.empty(nq)
    varv = np.empty(nv)
    rows_values(x, nb, ri[nc + ni + nq:], rf[nc + ni + nq:], varv, 0)
    forces(t, q, qdot, x, v, ip, fp, Fa, Fnc, Qd, varv)
    rhs = np.empty(ni)
    P = 0.0
    for r in range(nx):
        P += Fnc[r] * v[r]
    for k in range(nq):
        P += Qd[k] * qdot[k]
    for c in range(ni):
        s = -cc[c]
        for r in range(nx):
            s += Bl[r * ni + c] * Fa[r]
        for k in range(nq):
            s += GB[k, c] * Qd[k]
        rhs[c] = s
    if not cholesky_solve(A, rhs, ni):
        return 2
    if full:
        _reactions(x, v, bb, rhs, q, Bl, G, GB, Gb, Fa, Qd, J, piv, ip, fp, nb, nc, ni, nq, ext)
    ok = P == P
    for c in range(ni):
        out[c] = qdi[c]
        out[ni + c] = rhs[c]
        ok = ok and (rhs[c] - rhs[c] == 0.0)
    out[2 * ni] = P
    if not ok:
        return 3
    return 0


@njit
def _reactions(x, v, bb, qdd, q, Bl, G, GB, Gb, Fa, Qd, J, piv, ip, fp, nb, nc, ni, nq, ext):
    """Fill ``ext`` (see :func:`_evaluate`) after the solve for q_I''."""
    nx = 3 * nb
    ls = fp[2]
    xdd = ext[:nx]
    for r in range(nx):
        s = bb[r]
        for c in range(ni):
            s += Bl[r * ni + c] * qdd[c]
        xdd[r] = s
    o = nx
    rows_q = ext[o:o + nq]
    rows_v = ext[o + nq:o + 2 * nq]
    rows_a = ext[o + 2 * nq:o + 3 * nq]
    for k in range(nq):
        s = Gb[k]
        for c in range(ni):
            s += GB[k, c] * qdd[c]
        rows_a[k] = s
        rows_q[k] = q[k]
        sq = 0.0
        for r in range(nx):
            sq += G[k, r] * v[r]
        rows_v[k] = sq
    # residual of the free bodies: M x'' + h - F (F with the drives on their coordinates)
    z = np.empty(nx)
    Ftot = ext[o + 3 * nq + nc:o + 3 * nq + nc + nx]
    ob = ip[H_FOFF + S_BODY]
    for r in range(nx):
        s = Fa[r]
        for k in range(nq):
            s += G[k, r] * Qd[k]
        Ftot[r] = s
    for b in range(nb):
        m, Jc, ax, ay = _body_inertia(fp, ob, b, x)
        w = v[3 * b + 2]
        al = xdd[3 * b + 2]
        acx = xdd[3 * b] - al * ay - w * w * ax
        acy = xdd[3 * b + 1] + al * ax - w * w * ay
        z[3 * b] = m * acx - Ftot[3 * b]
        z[3 * b + 1] = m * acy - Ftot[3 * b + 1]
        z[3 * b + 2] = Jc * al + m * (ax * acy - ay * acx) - Ftot[3 * b + 2]
    od_i, od_f = ip[H_IOFF + S_DRV], ip[H_FOFF + S_DRV]
    for k in range(ip[H_NDRV]):
        c = ip[od_i + IR_DRV * k + IR_VAL]
        je = fp[od_f + FR_DRV * k + 2]
        if je != 0.0:
            for r in range(nx):
                z[r] += je * rows_a[c] * G[c, r]
    # Phi_x^T lambda = z with J = [Phi_x; g_I,x] factored with scaled rotation columns
    for b in range(nb):
        z[3 * b + 2] *= ls
    lu_solve_transposed(J, piv, z, nx)
    for r in range(nc):
        ext[o + 3 * nq + r] = z[r]


@njit
def _first_order(t, y, ip, fp, ri, rf, dims, ws, status):
    """y = (q_I, q_I', w) -> y' = (q_I', q_I'', P_nc); status[0] receives the status."""
    ni = dims[D_NI]
    out = np.empty(2 * ni + 1)
    status[0] = _evaluate(t, y[:ni], y[ni:2 * ni], ip, fp, ri, rf, dims, ws, out,
                          np.empty(0), False)
    return out


@njit
def _full(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, status):
    status[0] = _evaluate(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, True)


@njit
def _positions(qi, ip, fp, ri, rf, dims, ws):
    nb = ip[H_NB]
    nx = 3 * nb
    J = np.empty((nx, nx))
    piv = np.empty(nx, dtype=np.int64)
    F = np.empty(nx)
    return _newton(qi, fp, ri, rf, dims, ws, J, piv, F, nb)


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

    STATUS = {0: "ok", 1: "position solve failed", 2: "mass matrix not positive definite",
              3: "non-finite values"}

    def __init__(self, ip, fp, ri, rf, dims, n_x, compile_time):
        self.ip, self.fp, self.ri, self.rf, self.dims = ip, fp, ri, rf, dims
        self.n_x, self.n_i = n_x, int(dims[D_NI])
        self.ws = np.zeros(_work_size(n_x, self.n_i))
        self.compile_time = compile_time
        self.status = 0
        self._st = np.zeros(1, dtype=np.int64)

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

    def positions(self, q):
        """Solve the positions at q_I; returns x (a copy) or None on failure."""
        self.status = _positions(np.asarray(q, dtype=np.float64), self.ip, self.fp, self.ri,
                                 self.rf, self.dims, self.ws)
        return None if self.status else self.ws[:self.n_x].copy()

    def rhs(self, t, q, qdot):
        """(q_I'', array([P_nc])) or None on failure (see ``status``)."""
        n = self.n_i
        y = np.empty(2 * n + 1)
        y[:n] = q
        y[n:2 * n] = qdot
        out = _first_order(float(t), y, self.ip, self.fp, self.ri, self.rf, self.dims,
                           self.ws, self._st)
        self.status = int(self._st[0])
        if self.status:
            return None
        return out[n:2 * n], out[2 * n:]

    def evaluation(self, t, q, qdot):
        """Everything at one state, or None on failure (see ``status``).

        Returns
        -------
        dict with ``x``, ``xdot``, ``xddot`` (n_x,), ``q``, ``qdot``, ``qddot`` (n_q,,
        every declared coordinate), ``qddot_i`` (n_i,), ``lam`` (n_c,) multipliers of the
        constraint rows (M x'' + h - F = Phi_x^T lambda), ``F`` (n_x,) applied forces
        with the drives, ``power_nc`` (W).
        """
        n, nx, nq = self.n_i, self.n_x, int(self.dims[D_NQ])
        nc = int(self.dims[D_NC])
        out = np.empty(2 * n + 1)
        ext = np.empty(nx + 3 * nq + nc + nx)
        _full(float(t), np.asarray(q, np.float64), np.asarray(qdot, np.float64), self.ip,
              self.fp, self.ri, self.rf, self.dims, self.ws, out, ext, self._st)
        self.status = int(self._st[0])
        if self.status:
            return None
        o = nx
        return dict(x=self.x.copy(), xdot=self.xdot.copy(), xddot=ext[:nx].copy(),
                    q=ext[o:o + nq].copy(), qdot=ext[o + nq:o + 2 * nq].copy(),
                    qddot=ext[o + 2 * nq:o + 3 * nq].copy(),
                    lam=ext[o + 3 * nq:o + 3 * nq + nc].copy(),
                    F=ext[o + 3 * nq + nc:].copy(), qddot_i=out[n:2 * n].copy(),
                    power_nc=float(out[2 * n]))

    @property
    def evaluations(self) -> int:
        """Evaluations of the equations by this kernel so far."""
        return int(self.ws[-N_FLAGS + W_COUNT])

    def first_order_function(self, on_failure):
        """A function ``fun(t, y) -> y'`` for y = (q_I, q_I', w) calling the kernel directly
        (the path with the least Python per evaluation); ``on_failure(t, y)`` is called
        (and must return y' or raise) when the kernel reports a failure."""
        ip, fp, ri, rf, dims, ws, st = (self.ip, self.fp, self.ri, self.rf, self.dims,
                                        self.ws, self._st)
        kern = _first_order

        def fun(t, y):
            out = kern(t, y, ip, fp, ri, rf, dims, ws, st)
            if st[0]:
                self.status = int(st[0])
                return on_failure(t, y)
            return out

        return fun


_COMPILED = {"done": False, "time": 0.0}


def _pendulum_arrays():
    """The packed arrays of a small pendulum (a bar pinned to the ground, its angle as
    coordinate, gravity): the kernels are generic over their arrays, so compiling them
    on this model compiles them for every model -- and never evaluates a user's model
    at a position its run does not visit (a spring whose ends meet at the sketch ...)."""
    mech = Mechanism("warm-up pendulum", gravity=(0.0, -9.81))
    mech.add_body("bar", mass=1.0, inertia=0.1, com=(0.5, 0.0), pose=(0.0, 0.0, 0.0))
    mech.add_revolute("O", "ground", "bar")
    mech.add_coordinate("theta", kind="angle", body="bar")
    model = Model(mech)
    ip, fp = LoadPacker(model, force_model(model)).pack()
    ri, rf = concat(model.n_bodies, model.joint_rows, model.coordinate_rows,
                    model.coordinate_rows).packed()
    dims = np.array([len(model.joint_rows), 1, 1, 0], dtype=np.int64)
    x0 = np.array(model.x_sketch, dtype=float)
    return ip, fp, ri, rf, dims, model.n_x, x0


def _warm_up() -> float:
    """Compile (or load from the disk cache) the kernels, once per process, on a small
    pendulum; a compilation that takes longer than a few seconds is announced on stderr
    (it happens on the first run of a fresh installation only)."""
    if _COMPILED["done"]:
        return 0.0
    t0 = time.perf_counter()
    with compiling("numba kernels of the dynamics"):
        ip, fp, ri, rf, dims, n_x, x0 = _pendulum_arrays()
        ni, nq, nc = int(dims[D_NI]), int(dims[D_NQ]), int(dims[D_NC])
        ws = np.zeros(_work_size(n_x, ni))
        ws[:n_x] = x0
        q, qd = np.array([0.3]), np.array([1.0])
        st = np.zeros(1, dtype=np.int64)
        _positions(q, ip, fp, ri, rf, dims, ws)
        _first_order(0.0, np.concatenate([q, qd, [0.0]]), ip, fp, ri, rf, dims, ws, st)
        _full(0.0, q, qd, ip, fp, ri, rf, dims, ws, np.empty(2 * ni + 1),
              np.empty(2 * n_x + 3 * nq + nc), st)
    _COMPILED["done"] = True
    _COMPILED["time"] = time.perf_counter() - t0
    return _COMPILED["time"]


def compile_mode_kernel(model, force_model, constraint_rows, independent):
    """The compiled kernel of a mode, or ``(None, reason)``.

    Parameters
    ----------
    model : Model
    force_model : ForceModel
        The model's loads (:func:`mechdyn.dynamics.forces.force_model`).
    constraint_rows : Rows
        The mode's independent constraint rows (joints, engaged locks, closed stops
        and contacts, sticking rows), n_c of them.
    independent : sequence of int
        Indices of the declared coordinates that are independent in the mode
        (n_i of them, n_c + n_i = n_x).

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
    packer = LoadPacker(model, force_model, variable=lambda name: _variable(model, name))
    try:
        ip, fp = packer.pack()
    except Unsupported as exc:
        return None, str(exc)
    crd = model.coordinate_rows
    var = concat(model.n_bodies, *packer.variable_rows)
    ri, rf = concat(model.n_bodies, constraint_rows, crd.take(independent), crd, var).packed()
    dims = np.array([len(constraint_rows), independent.size, model.n_q, len(var)],
                    dtype=np.int64)
    ct = _warm_up()
    return CompiledKernel(ip, fp, ri, rf, dims, model.n_x, ct), ""


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


def compile_kernel(model, layout):
    """The compiled kernel of a fixed-structure model in one layout (every declared
    coordinate independent), or ``(None, reason)``."""
    return compile_mode_kernel(model, force_model(model), layout.rowset, np.arange(model.n_q))
