"""The LU of a mode's position Jacobian in block triangular form.

Many rows of the position Jacobian J = [Phi_x; g_I,x] of a planar mechanism hold,
once a few unknowns are known, one or two unknowns only: the row of an independent
coordinate that is a body's angle or position (a crank's angle, the base's x of a
mounted machine), then the two rows of a pin to the ground or to a body already
placed, of a body whose angle is known, and so on.  Rows and columns permuted to the
order of that cascade make J block lower triangular,

    [J_11              ] [y_1]   [b_1]
    [J_21  J_22        ] [y_2] = [b_2]
    [ ...   ...   ...  ] [...]   [...]

with small diagonal blocks -- single entries, the 2 x 2 of a slider on a turning
guide, the closed loops -- each factored on its own (LU with partial pivoting), the
rest by substitution.  The blocks are the strongly connected parts of the rows'
structure (the entries that are not zero at random poses) under a perfect matching of
rows to columns (Duff and Reid's block triangular form): :func:`block_order` finds
them once per mode; the compiled :func:`factor`, :func:`solve` and
:func:`solve_transposed` stand in the kernel for
:func:`~mechdyn.kernels.linalg.lu_factor` and its solves.  det J is the product of
the blocks' determinants, and the inverse of every diagonal block is a block of
J^-1: a block is near-singular only where J is, so no pivot of the form is worse
than J itself.

The form is kept at the end of the kernel's ``dims`` array (see :func:`block_order`);
without it (``dims`` of length 4) the whole matrix is factored as before.
"""

from __future__ import annotations

import graphlib

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

from .linalg import (
    lu_factor,
    lu_factor_packed,
    lu_solve,
    lu_solve_packed,
    lu_solve_transposed,
    lu_solve_transposed_packed,
)
from .rows_numba import njit, rows_jacobian

__all__ = ["block_order", "factor", "solve", "solve_unit", "solve_transposed", "fac_size",
           "D_NS"]

#: index in ``dims`` of the number of diagonal blocks (the form follows it)
D_NS = 4


@njit
def fac_size(n):
    """Length of the float scratch of the factors: the diagonal blocks' LU (n^2 at
    most) and two vectors of n."""
    return n * n + 2 * n


def block_order(ri, rf, nb: int, samples: int = 3, seed: int = 0) -> np.ndarray:
    """The block triangular form of a square block of rows, as kept in ``dims``.

    Parameters
    ----------
    ri, rf : ndarray
        The packed rows (:meth:`mechdyn.model.rows.Rows.packed`), n = 3 nb of them.
    nb : int
        Bodies.
    samples, seed
        Random poses that give the structure (the entries that are not zero).

    Returns
    -------
    ndarray of int64
        ``[K, starts (K + 1), rows (n), columns (n), ptr (n + 1), idx]``: K diagonal
        blocks, block j holding the rows ``rows[starts[j]:starts[j + 1]]`` and the
        columns ``columns[starts[j]:starts[j + 1]]``; ``idx[ptr[p]:ptr[p + 1]]`` the
        columns of earlier blocks in the p-th row of ``rows``.  Empty where the rows
        are structurally singular (no perfect matching).

    Examples
    --------
    A bar pinned to the ground (index 1) at its point (-0.5, 0), its angle as
    coordinate: the angle row first, then the pin's x and y rows, one by one.

    >>> from mechdyn.model import rows as R
    >>> r = R.concat(1, R.revolute("O", 1, (0.0, 0.0), 0, (-0.5, 0.0), nb=1),
    ...              R.angle("theta", 0, nb=1))
    >>> form = block_order(*r.packed(), 1)
    >>> int(form[0]), form[1:5].tolist(), form[5:8].tolist(), form[8:11].tolist()
    (3, [0, 1, 2, 3], [2, 0, 1], [2, 0, 1])
    """
    n = 3 * nb
    if ri.shape[0] != n:
        raise ValueError(f"block_order: {ri.shape[0]} rows for {n} unknowns")
    rng = np.random.default_rng(seed)
    nz = np.zeros((n, n), bool)
    for _ in range(samples):
        J = np.zeros((n, n))
        rows_jacobian(rng.uniform(-1.0, 1.0, n), nb, ri, rf, J, 0)
        nz |= J != 0.0
    col_of = maximum_bipartite_matching(sp.csr_array(nz.astype(np.int8)), perm_type="column")
    if n == 0 or (col_of < 0).any():
        return np.zeros(0, dtype=np.int64)
    row_of = np.empty(n, dtype=np.int64)
    row_of[col_of] = np.arange(n)
    # row r needs the row matched to every other column of its pattern
    dep = nz.copy()
    dep[np.arange(n), col_of] = False
    need = np.zeros((n, n), bool)
    rr, cc = np.nonzero(dep)
    need[rr, row_of[cc]] = True
    k, label = connected_components(sp.csr_array(need.astype(np.int8)), directed=True,
                                    connection="strong")
    graph = {j: set() for j in range(k)}
    for r, r2 in zip(*np.nonzero(need), strict=True):
        if label[r] != label[r2]:
            graph[label[r]].add(label[r2])
    rows, starts = [], [0]
    block_of = np.empty(n, dtype=np.int64)
    for j, blk in enumerate(graphlib.TopologicalSorter(graph).static_order()):
        members = np.flatnonzero(label == blk).tolist()
        rows += members
        starts.append(len(rows))
        block_of[members] = j
    cols = col_of[rows].tolist()
    ptr, idx = [0], []
    for r in rows:
        earlier = [int(c) for c in np.flatnonzero(nz[r]) if block_of[row_of[c]] < block_of[r]]
        idx += earlier
        ptr.append(len(idx))
    return np.array([k, *starts, *rows, *cols, *ptr, *idx], dtype=np.int64)


@njit
def _layout(dims, n):
    """Blocks, and where their starts, rows, columns, ptr and idx begin in ``dims``."""
    nblk = dims[D_NS]
    st = D_NS + 1
    rp = st + nblk + 1
    return nblk, st, rp, rp + n, rp + 2 * n, rp + 3 * n + 1


@njit
def _vectors(fac, n):
    """The two vectors of n after the blocks' LU in ``fac``."""
    return fac[n * n:n * n + n], fac[n * n + n:n * n + 2 * n]


@njit
def factor(J, fac, piv, dims, n):
    """Factor J (n, n) for :func:`solve`: the diagonal blocks' LU into ``fac`` and
    ``piv`` (J kept), or -- without a form in ``dims`` -- J's LU in place (``piv[n]`` =
    1).  Returns min |u_ii| / max |u_ii| over the pivots (0 if singular)."""
    if dims.size <= D_NS:
        piv[n] = 1
        return lu_factor(J, piv, n)
    piv[n] = 0
    nblk, st, rp, cp, _, _ = _layout(dims, n)
    umin = np.inf
    umax = 0.0
    off = 0
    for j in range(nblk):
        a0, a1 = dims[st + j], dims[st + j + 1]
        s = a1 - a0
        if s == 1:
            u = J[dims[rp + a0], dims[cp + a0]]
            fac[off] = u
            u = abs(u)
            if u == 0.0:
                return 0.0
            umin = min(umin, u)
            umax = max(umax, u)
            off += 1
            continue
        for a in range(s):
            r = dims[rp + a0 + a]
            for b in range(s):
                fac[off + a * s + b] = J[r, dims[cp + a0 + b]]
        lo, hi = lu_factor_packed(fac, off, s, piv, a0)
        if lo == 0.0:
            return 0.0
        umin = min(umin, lo)
        umax = max(umax, hi)
        off += s * s
    return umin / umax if umax > 0.0 else 0.0


@njit
def solve(J, fac, piv, dims, b, n):
    """Solve J y = b with the factors of :func:`factor` (b, by rows, overwritten by y,
    by columns)."""
    if piv[n] == 1:
        lu_solve(J, piv, b, n)
        return
    nblk, st, rp, cp, pp, ix = _layout(dims, n)
    y, w = _vectors(fac, n)
    off = 0
    for j in range(nblk):
        a0, a1 = dims[st + j], dims[st + j + 1]
        s = a1 - a0
        for a in range(s):
            p = a0 + a
            r = dims[rp + p]
            acc = b[r]
            for e in range(dims[pp + p], dims[pp + p + 1]):
                c = dims[ix + e]
                acc -= J[r, c] * y[c]
            w[a] = acc
        if s == 1:
            y[dims[cp + a0]] = w[0] / fac[off]
        else:
            lu_solve_packed(fac, off, s, piv, a0, w)
            for a in range(s):
                y[dims[cp + a0 + a]] = w[a]
        off += s * s
    for i in range(n):
        b[i] = y[i]


@njit
def solve_unit(J, fac, piv, dims, first, Y, n, m):
    """Solve J Y = E for the m unit columns E[:, c] = e_(first + c) (by rows of J) with
    the factors of :func:`factor`, Y (n, m) overwritten (by columns of J): the velocity
    analogs, each row's substitution shared among the m right-hand sides."""
    y, w = _vectors(fac, n)
    if piv[n] == 1:
        for c in range(m):
            for i in range(n):
                y[i] = 0.0
            y[first + c] = 1.0
            lu_solve(J, piv, y, n)
            for i in range(n):
                Y[i, c] = y[i]
        return
    nblk, st, rp, cp, pp, ix = _layout(dims, n)
    off = 0
    for j in range(nblk):
        a0, a1 = dims[st + j], dims[st + j + 1]
        s = a1 - a0
        for a in range(s):  # row a's right-hand sides, kept in its column's place
            p = a0 + a
            r = dims[rp + p]
            ca = dims[cp + p]
            for c in range(m):
                Y[ca, c] = 1.0 if r == first + c else 0.0
            for e in range(dims[pp + p], dims[pp + p + 1]):
                k = dims[ix + e]
                g = J[r, k]
                for c in range(m):
                    Y[ca, c] -= g * Y[k, c]
        if s == 1:
            ca = dims[cp + a0]
            for c in range(m):
                Y[ca, c] = Y[ca, c] / fac[off]
        else:
            for c in range(m):
                for a in range(s):
                    w[a] = Y[dims[cp + a0 + a], c]
                lu_solve_packed(fac, off, s, piv, a0, w)
                for a in range(s):
                    Y[dims[cp + a0 + a], c] = w[a]
        off += s * s


@njit
def solve_transposed(J, fac, piv, dims, b, n):
    """Solve J^T z = b with the factors of :func:`factor` (b, by columns, overwritten by
    z, by rows)."""
    z, w = _vectors(fac, n)
    if piv[n] == 1:
        lu_solve_transposed(J, piv, b, n)
        return
    for i in range(n):
        w[i] = b[i]
    nblk, st, rp, cp, pp, ix = _layout(dims, n)
    off = 0
    for j in range(nblk):
        off += (dims[st + j + 1] - dims[st + j]) ** 2
    for j in range(nblk - 1, -1, -1):
        a0, a1 = dims[st + j], dims[st + j + 1]
        s = a1 - a0
        off -= s * s
        for a in range(s):
            b[a] = w[dims[cp + a0 + a]]
        if s == 1:
            b[0] /= fac[off]
        else:
            lu_solve_transposed_packed(fac, off, s, piv, a0, b)
        for a in range(s):  # the block's rows, and their share of the earlier columns
            p = a0 + a
            r = dims[rp + p]
            z[r] = b[a]
            for e in range(dims[pp + p], dims[pp + p + 1]):
                c = dims[ix + e]
                w[c] -= J[r, c] * z[r]
    for i in range(n):
        b[i] = z[i]
