"""The compiled (Numba) equations of motion of one mode, over packed arrays.

For a state (t, q_I, q_I'), q_I the independent coordinates of the mode:
:func:`evaluate` does the Newton position solve of [Phi(x); g_I(x) - q_I] = 0 from
the last pose (with the linear predictor x + B (q_I - q_last)), the velocity
analogs B and the acceleration bias b (x'' = B q_I'' + b), the declared
coordinates q = g(x) with their rates and their analogs G B, the mass matrix
A = B^T M_x B + sum_drives J_e (G_k B)^T (G_k B) (motor rotor and gear inertia
J_e reduced to the driven coordinate k, whether it is independent or not), the
bias c, the applied forces and Q = B^T (F + G^T Q_drive), the Cholesky solve for
q_I'' and the power of the non-conservative forces; with ``full``, also the
multipliers of the rows from the transposed solve with the same factors.  The
position Jacobian is factored in its block triangular form
(:mod:`mechdyn.kernels.block_lu`: the order kept at the end of ``dims``).

The arrays: ``ip``, ``fp`` the packed loads (:mod:`mechdyn.kernels.loads_numba`);
``ri``, ``rf`` the packed rows (:meth:`mechdyn.model.rows.Rows.packed`) in four
blocks -- constraint rows, independent coordinates, declared coordinates, table
variables -- of the sizes in ``dims``; ``ws`` the work array (:func:`work_size`).
The functions are generic over these arrays: they compile once for every model
and every mode.  :mod:`mechdyn.dynamics.compiled` wraps them.
"""

from __future__ import annotations

import numpy as np

from .block_lu import fac_size, factor, solve, solve_transposed, solve_unit
from .linalg import cholesky_solve
from .loads_numba import (
    FR_DRV,
    H_FOFF,
    H_IOFF,
    H_NB,
    H_NDRV,
    IR_DRV,
    IR_VAL,
    S_BODY,
    S_DRV,
    body_inertia,
    forces,
)
from .rows_numba import (
    body_rotations,
    copy_into,
    njit,
    njit_inline,
    rows_jacobian_cs,
    rows_quad_cs,
    rows_values_cs,
)

__all__ = ["evaluate", "evaluate_into", "scratch_size", "first_order", "full", "work_size",
           "held_pieces", "table_inputs",
           "D_NC", "D_NI", "D_NQ", "D_NV", "W_VALID", "W_PIVOT", "W_COUNT", "N_FLAGS"]

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


def work_size(n_x: int, n_i: int, n_t: int = 0) -> int:
    """Work array: x | q_last (n_i) | B_last (n_x n_i) | xdot | b_last (n_x) | q_I'_last
    (n_i) | held table pieces (2 n_t, see :func:`held_pieces`) | x_good | flags."""
    return 2 * n_i + n_x * n_i + 4 * n_x + 2 * n_t + N_FLAGS


@njit
def held_pieces(ws, nx, ni):
    """The block of the work array with the table pieces that the loads evaluate on
    (:mod:`mechdyn.kernels.table_regions`; all zero outside the DOP853 loop: none)."""
    o = _bias_offset(nx, ni) + nx + ni
    return ws[o:ws.size - N_FLAGS - nx]


@njit
def _bias_offset(nx, ni):
    """Where b_last begins in the work array (after x, q_last, B_last and xdot)."""
    return nx + ni + nx * ni + nx


@njit
def _last_bias(ws, nx, ni):
    """The acceleration bias b (n_x) and the rates q_I' (n_i) of the last evaluation in
    the work array: the pose's second derivative along q_I' is b (J b = -quad)."""
    o = _bias_offset(nx, ni)
    return ws[o:o + nx], ws[o + nx:o + nx + ni]


@njit
def _system(x, qi, ri, rf, dims, nb, F, J, cs):
    """Residual [Phi; g_I - q_I] (F) and Jacobian (J) at pose x; ``cs`` receives the
    bodies' rotations there (:func:`~mechdyn.kernels.rows_numba.body_rotations`)."""
    nc, ni = dims[D_NC], dims[D_NI]
    nx = 3 * nb
    for r in range(nx):
        for c in range(nx):
            J[r, c] = 0.0
    body_rotations(x, nb, cs)
    rows_values_cs(x, nb, ri[:nc + ni], rf[:nc + ni], cs, F, 0)
    rows_jacobian_cs(x, nb, ri[:nc + ni], rf[:nc + ni], cs, J, 0)
    for c in range(ni):
        F[nc + c] -= qi[c]


@njit
def _fac(sc, nx):
    """The factors' scratch (:func:`mechdyn.kernels.block_lu.fac_size`) at the end of
    the scratch of :func:`evaluate_into`."""
    return sc[sc.size - fac_size(nx):]


@njit
def _rot(sc, nx):
    """The bodies' rotations (nb + 1, 2) in the scratch of :func:`evaluate_into`, just
    before the factors."""
    o = sc.size - fac_size(nx)
    return sc[o - 2 * (nx // 3 + 1):o].reshape((nx // 3 + 1, 2))


@njit
def _solve_scaled(J, fac, piv, dims, col, nx, nb, ls):
    """Solve with the factors of the Jacobian with scaled rotation columns (col
    overwritten)."""
    solve(J, fac, piv, dims, col, nx)
    for b in range(nb):
        col[3 * b + 2] *= ls


@njit
def _newton(qi, fp, ri, rf, dims, ws, J, fac, piv, F, nb, cs):
    """Solve the positions at q_I from the pose in ws; leaves the factors of the scaled
    Jacobian at the solution in (J, fac, piv) (:mod:`mechdyn.kernels.block_lu`).
    Returns 0 or 1 (no convergence)."""
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
        # predictor of second order: x_l + B dq + b tau^2 / 2, tau the time at the last
        # rates q_I' that covers the part of dq along them (b: the path's curvature there;
        # the rest of dq comes from the accelerations, an order higher), the second-order
        # term only where it is smaller than the first
        bl, qdl = _last_bias(ws, nx, ni)
        dd = 0.0
        tau = 0.0
        for c in range(ni):
            dd += qdl[c] * qdl[c]
            tau += qdl[c] * (qi[c] - ql[c])
        h2 = 0.5 * (tau / dd) ** 2 if dd > 0.0 else 0.0
        d1 = 0.0
        d2 = 0.0
        for r in range(nx):
            s = 0.0
            for c in range(ni):
                s += Bl[r * ni + c] * (qi[c] - ql[c])
            x[r] += s
            d1 = max(d1, abs(s))
            d2 = max(d2, abs(h2 * bl[r]))
        if d2 <= 0.5 * d1:  # (not NaN)
            for r in range(nx):
                x[r] += h2 * bl[r]
    prev = np.inf
    status = 1
    for it in range(40):
        _system(x, qi, ri, rf, dims, nb, F, J, cs)
        err = 0.0
        for r in range(nx):
            a = abs(F[r])
            if not a <= err:  # catches NaN
                err = a if a == a else np.inf
        for r in range(nx):  # rotation columns scaled by the length scale
            for b in range(nb):
                J[r, 3 * b + 2] *= ls
        flags[W_PIVOT] = factor(J, fac, piv, dims, nx)
        flags[W_ITER] = it
        flags[W_ERR] = err
        if err <= tol or (err >= 0.5 * prev and err <= 1e3 * tol):
            status = 0
            break
        if not err < np.inf or flags[W_PIVOT] == 0.0:
            break
        prev = err
        _solve_scaled(J, fac, piv, dims, F, nx, nb, ls)
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
def scratch_size(n_x, n_i, n_q, n_v):
    """Length of the scratch array of :func:`evaluate_into` (every intermediate of one
    evaluation, so that a compiled loop evaluates without allocating)."""
    return n_x * n_x + 6 * n_x + 4 * n_q + n_q * n_x + n_q * n_i + n_i * n_i + 4 * n_i + n_v \
        + 2 * (n_x // 3 + 1) + fac_size(n_x)


@njit
def table_inputs(sc, nx, ni, nq, nv):
    """Views into the scratch of :func:`evaluate_into` of the declared coordinates, their
    rates and the measured table variables of its last evaluation: ``(q, qdot, varv)``."""
    o = nx * nx + 6 * nx
    q, qdot = sc[o:o + nq], sc[o + nq:o + 2 * nq]
    o += 4 * nq + nq * nx + nq * ni + ni * ni + 4 * ni
    return q, qdot, sc[o:o + nv]


@njit_inline
def evaluate(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, full):
    """q_I'' and P_nc at (t, q_I, q_I'); out = [q_I' | q_I'' | P_nc].  Status: 0 ok,
    1 position solve failed, 2 mass matrix not positive definite, 3 non-finite.

    With ``full``, ``ext`` receives [x'' (n_x) | q | q' | q'' (n_q each) | lambda (n_c) |
    F (n_x)]: the accelerations, every declared coordinate, the multipliers of the
    constraint rows from the same factorization (M x'' + h - F = Phi_x^T lambda, solved
    with the transposed LU of the position Jacobian) and the applied forces on the
    poses, drives included.  (Allocates its scratch; :func:`evaluate_into` does not.)"""
    # (``full`` is a runtime boolean in every call of the package: a literal True or False
    # would compile this and evaluate_into once more for each -- seconds of first use)
    nx = 3 * ip[H_NB]
    sc = np.empty(scratch_size(nx, dims[D_NI], dims[D_NQ], dims[D_NV]))
    piv = np.empty(nx + 1, dtype=np.int64)
    return evaluate_into(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, full, sc, piv)


@njit
def evaluate_into(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, full, sc, piv):
    """:func:`evaluate` with the caller's scratch arrays: ``sc`` (float,
    :func:`scratch_size`) and ``piv`` (int64, n_x + 1)."""
    nb = ip[H_NB]
    nx = 3 * nb
    nc, ni, nq, nv = dims[D_NC], dims[D_NI], dims[D_NQ], dims[D_NV]
    ls = fp[2]
    o = nx * nx
    J = sc[:o].reshape((nx, nx))
    F, bb = sc[o:o + nx], sc[o + 2 * nx:o + 3 * nx]
    Fa, Fnc, z = sc[o + 3 * nx:o + 4 * nx], sc[o + 4 * nx:o + 5 * nx], sc[o + 5 * nx:o + 6 * nx]
    o += 6 * nx
    q, qdot, varv = table_inputs(sc, nx, ni, nq, nv)
    Gb, Qd = sc[o + 2 * nq:o + 3 * nq], sc[o + 3 * nq:o + 4 * nq]
    o += 4 * nq
    G = sc[o:o + nq * nx].reshape((nq, nx))
    o += nq * nx
    GB = sc[o:o + nq * ni].reshape((nq, ni))
    o += nq * ni
    A = sc[o:o + ni * ni].reshape((ni, ni))
    o += ni * ni
    cc, bcx, bcy, rhs = sc[o:o + ni], sc[o + ni:o + 2 * ni], sc[o + 2 * ni:o + 3 * ni], \
        sc[o + 3 * ni:o + 4 * ni]
    ws[ws.size - N_FLAGS + W_COUNT] += 1.0
    fac = _fac(sc, nx)
    cs = _rot(sc, nx)  # of the pose Newton ends at
    st = _newton(qi, fp, ri, rf, dims, ws, J, fac, piv, F, nb, cs)
    if st != 0:
        return st
    x = ws[:nx]
    Bl = ws[nx + ni:nx + ni + nx * ni]
    v = ws[nx + ni + nx * ni:nx + ni + nx * ni + nx]
    flags = ws[ws.size - N_FLAGS:]
    # velocity analogs B (row r, column c stored at r * ni + c): J B = [0; I]
    solve_unit(J, fac, piv, dims, nc, Bl.reshape((nx, ni)), nx, ni)
    for b in range(nb):
        for c in range(ni):
            Bl[(3 * b + 2) * ni + c] *= ls
    flags[W_VALID] = 1.0
    for r in range(nx):
        s = 0.0
        for c in range(ni):
            s += Bl[r * ni + c] * qdi[c]
        v[r] = s
    # acceleration bias: J b = -quad
    rows_quad_cs(x, v, nb, ri[:nc + ni], rf[:nc + ni], cs, bb, 0)
    for r in range(nx):
        bb[r] = -bb[r]
    _solve_scaled(J, fac, piv, dims, bb, nx, nb, ls)
    bl, qdl = _last_bias(ws, nx, ni)  # for the predictor of the next solve
    for r in range(nx):
        bl[r] = bb[r]
    for c in range(ni):
        qdl[c] = qdi[c]
    # declared coordinates, their rates, analogs G B and bias G b + quad_g
    _declared(x, v, bb, Bl, ri, rf, dims, cs, q, qdot, G, GB, Gb, nb)
    # mass matrix and c (the bodies', the drives' inertia)
    _mass_matrix(v, bb, Bl, GB, Gb, ip, fp, cs, A, cc, bcx, bcy, nb, ni)
    # forces
    rows_values_cs(x, nb, ri[nc + ni + nq:], rf[nc + ni + nq:], cs, varv, 0)
    forces(t, q, qdot, x, v, ip, fp, Fa, Fnc, Qd, varv, held_pieces(ws, nx, ni), cs)
    P = _generalized_forces(v, qdot, Bl, GB, Fa, Fnc, Qd, cc, rhs, nx, ni, nq)
    if not cholesky_solve(A, rhs, ni):
        return 2
    if full:
        _reactions(x, v, bb, rhs, q, qdot, Bl, G, GB, Gb, Fa, Qd, J, fac, piv, dims, ip, fp, nb,
                   nc, ni, nq, ext, z, cs)
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
def _declared(x, v, bb, Bl, ri, rf, dims, cs, q, qdot, G, GB, Gb, nb):
    """The declared coordinates q = g(x) at the pose ``x`` (rates ``v``, analogs ``Bl``,
    bias ``bb``), their rates, their Jacobian G, their analogs G B and their bias
    G b + quad_g."""
    nc, ni, nq = dims[D_NC], dims[D_NI], dims[D_NQ]
    nx = 3 * nb
    gi, gf = ri[nc + ni:nc + ni + nq], rf[nc + ni:nc + ni + nq]
    for k in range(nq):
        qdot[k] = 0.0
        for r in range(nx):
            G[k, r] = 0.0
        for c in range(ni):
            GB[k, c] = 0.0
    rows_values_cs(x, nb, gi, gf, cs, q, 0)
    rows_jacobian_cs(x, nb, gi, gf, cs, G, 0)
    rows_quad_cs(x, v, nb, gi, gf, cs, Gb, 0)
    for k in range(nq):
        for r in range(nx):
            g = G[k, r]
            if g != 0.0:
                qdot[k] += g * v[r]
                Gb[k] += g * bb[r]
                for c in range(ni):
                    GB[k, c] += g * Bl[r * ni + c]


@njit
def _mass_matrix(v, bb, Bl, GB, Gb, ip, fp, cs, A, cc, bcx, bcy, nb, ni):
    """The mass matrix A (its upper triangle) and the bias c of the equations in q_I:
    the bodies' from their centre-of-mass analogs (``bcx``, ``bcy``: scratch), the
    drives' rotor and gear inertia on their (declared) coordinates.  The NumPy twin of
    the bodies' part: :func:`mechdyn.kernels.inertia.analog_mass`."""
    for i in range(ni):
        cc[i] = 0.0
        for j in range(ni):
            A[i, j] = 0.0
    ob = ip[H_FOFF + S_BODY]
    for b in range(nb):
        m, Jc, ax, ay = body_inertia(fp, ob, b, cs)
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


@njit
def _generalized_forces(v, qdot, Bl, GB, Fa, Fnc, Qd, cc, rhs, nx, ni, nq):
    """The right-hand side Q - c = B^T F + (G B)^T Q_drive - c of the solve for q_I''
    (into ``rhs``); returns the power of the non-conservative forces."""
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
    return P


@njit
def _reactions(x, v, bb, qdd, q, qdot, Bl, G, GB, Gb, Fa, Qd, J, fac, piv, dims, ip, fp, nb, nc,
               ni, nq, ext, z, cs):
    """Fill ``ext`` (see :func:`evaluate`) after the solve for q_I''."""
    nx = 3 * nb
    ls = fp[2]
    xdd = ext[:nx]
    for r in range(nx):
        s = bb[r]
        for c in range(ni):
            s += Bl[r * ni + c] * qdd[c]
        xdd[r] = s
    o = nx
    copy_into(ext[o:o + nq], q)
    copy_into(ext[o + nq:o + 2 * nq], qdot)
    rows_a = ext[o + 2 * nq:o + 3 * nq]
    for k in range(nq):
        s = Gb[k]
        for c in range(ni):
            s += GB[k, c] * qdd[c]
        rows_a[k] = s
    # residual of the free bodies: M x'' + h - F (F with the drives on their coordinates)
    Ftot = ext[o + 3 * nq + nc:o + 3 * nq + nc + nx]
    ob = ip[H_FOFF + S_BODY]
    for r in range(nx):
        s = Fa[r]
        for k in range(nq):
            s += G[k, r] * Qd[k]
        Ftot[r] = s
    for b in range(nb):
        m, Jc, ax, ay = body_inertia(fp, ob, b, cs)
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
    solve_transposed(J, fac, piv, dims, z, nx)
    for r in range(nc):
        ext[o + 3 * nq + r] = z[r]


@njit
def first_order(t, y, ip, fp, ri, rf, dims, ws, status):
    """y = (q_I, q_I', w) -> y' = (q_I', q_I'', P_nc); status[0] receives the status."""
    ni = dims[D_NI]
    out = np.empty(2 * ni + 1)
    status[0] = evaluate(t, y[:ni], y[ni:2 * ni], ip, fp, ri, rf, dims, ws, out,
                          np.empty(0), status.size < 0)  # a runtime False (one compilation)
    return out


@njit
def full(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext, status):
    status[0] = evaluate(t, qi, qdi, ip, fp, ri, rf, dims, ws, out, ext,
                         status.size > 0)  # a runtime True (one compilation of evaluate)
