"""The block triangular LU of the position Jacobian (:mod:`mechdyn.kernels.block_lu`).

Oracles: LAPACK's solve (numpy.linalg.solve) of the same Jacobians, straight and
transposed, at random poses of every bundled example's first mode and of the press
mounted on its isolators (its slider on a turning guide: a 2 x 2 block, and a larger
closed loop); the determinant as the product of the blocks' pivots; a singular matrix
reported as such.
"""

import warnings

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.dynamics.compiled import numba_available
from mechdyn.foundation import FloorFrameWarning, mounted
from mechdyn.kernels.block_lu import (
    D_NS,
    block_order,
    fac_size,
    factor,
    solve,
    solve_transposed,
    solve_unit,
)
from mechdyn.kernels.rows_numba import rows_jacobian
from mechdyn.model.rows import concat

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")


def _square_rows(model):
    """The rows of the sketch's mode: joints and the declared coordinates that make it
    square (the first ones in the order of a QR with pivoting, as a mode chooses)."""
    import scipy.linalg

    x = model.x_sketch
    Phi = model.joint_rows
    n = model.n_x
    Jp = np.zeros((len(Phi), n))
    rows_jacobian(x, model.n_bodies, *Phi.packed(), Jp, 0)
    G = np.zeros((model.n_q, n))
    rows_jacobian(x, model.n_bodies, *model.coordinate_rows.packed(), G, 0)
    null = scipy.linalg.null_space(Jp)
    pick = scipy.linalg.qr((G @ null).T, pivoting=True)[2][:n - len(Phi)]
    return concat(model.n_bodies, Phi, model.coordinate_rows.take(np.sort(pick)))


def _models():
    out = {name: examples.load(name).compile() for name in examples.names()}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FloorFrameWarning)
        out["press_cycle mounted"] = mounted(examples.load("press_cycle")).compile()
    return out


MODELS = _models()


@pytest.mark.parametrize("name", sorted(MODELS))
def test_solves_as_lapack_at_random_poses(name):
    model = MODELS[name]
    rows = _square_rows(model)
    ri, rf = rows.packed()
    n, nb = model.n_x, model.n_bodies
    if len(rows) != n:
        pytest.skip("redundant joints: no square block")
    form = block_order(ri, rf, nb)
    assert form.size and form[0] >= 1
    dims = np.concatenate([[0, 0, 0, 0], form]).astype(np.int64)
    rng = np.random.default_rng(7)
    for _ in range(5):
        x = model.x_sketch + rng.normal(scale=0.05, size=n)
        J = np.zeros((n, n))
        rows_jacobian(x, nb, ri, rf, J, 0)
        J[:, 2::3] *= model.length_scale
        fac, piv = np.empty(fac_size(n)), np.empty(n + 1, dtype=np.int64)
        Jk = J.copy()
        ratio = factor(Jk, fac, piv, dims, n)
        assert piv[n] == 0 and 0.0 < ratio <= 1.0
        np.testing.assert_array_equal(Jk, J)  # the blocks are factored aside
        b = rng.normal(size=n)
        y = b.copy()
        solve(Jk, fac, piv, dims, y, n)
        want = np.linalg.solve(J, b)
        np.testing.assert_allclose(y, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))
        z = b.copy()
        solve_transposed(Jk, fac, piv, dims, z, n)
        want = np.linalg.solve(J.T, b)
        np.testing.assert_allclose(z, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))
        first = n - 2 if n > 2 else 0  # the analogs' right-hand sides: unit columns
        Y = np.empty((n, n - first))
        solve_unit(Jk, fac, piv, dims, first, Y, n, n - first)
        want = np.linalg.solve(J, np.eye(n)[:, first:])
        np.testing.assert_allclose(Y, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))


def test_mounted_press_has_blocks_beyond_single_entries():
    model = MODELS["press_cycle mounted"]
    form = block_order(*_square_rows(model).packed(), model.n_bodies)
    k = int(form[0])
    sizes = np.diff(form[1:k + 2])
    assert sizes.sum() == model.n_x and sizes.max() >= 2 and (sizes == 1).sum() >= 8


def test_determinant_is_the_product_of_the_block_pivots():
    model = MODELS["four_bar"]
    rows = _square_rows(model)
    ri, rf = rows.packed()
    n, nb = model.n_x, model.n_bodies
    dims = np.concatenate([[0, 0, 0, 0], block_order(ri, rf, nb)]).astype(np.int64)
    J = np.zeros((n, n))
    rows_jacobian(model.x_sketch, nb, ri, rf, J, 0)
    fac, piv = np.empty(fac_size(n)), np.empty(n + 1, dtype=np.int64)
    factor(J.copy(), fac, piv, dims, n)
    k = int(dims[D_NS])
    starts = dims[D_NS + 1:D_NS + k + 2]
    det, off = 1.0, 0
    for a0, a1 in zip(starts[:-1], starts[1:], strict=True):
        s = int(a1 - a0)
        B = fac[off:off + s * s].reshape(s, s)
        swaps = sum(1 for i in range(s) if piv[a0 + i] != i)
        det *= (-1.0) ** swaps * np.prod(np.diag(B))
        off += s * s
    # the permutation of rows and columns only changes the sign
    assert abs(det) == pytest.approx(abs(np.linalg.det(J)), rel=1e-12)


def test_singular_and_unordered_matrices():
    n = 3
    J = np.array([[1.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]])  # third column empty
    fac, piv = np.empty(fac_size(n)), np.empty(n + 1, dtype=np.int64)
    dims = np.array([0, 0, 0, 0], dtype=np.int64)  # no form: the whole matrix, in place
    assert factor(J.copy(), fac, piv, dims, n) == 0.0 and piv[n] == 1
    A = np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]])
    Af = A.copy()
    assert factor(Af, fac, piv, dims, n) > 0.0
    b = np.array([1.0, 2.0, 3.0])
    y = b.copy()
    solve(Af, fac, piv, dims, y, n)
    np.testing.assert_allclose(A @ y, b, rtol=1e-14)
    z = b.copy()
    solve_transposed(Af, fac, piv, dims, z, n)
    np.testing.assert_allclose(A.T @ z, b, rtol=1e-14)
    Y = np.empty((n, 2))
    solve_unit(Af, fac, piv, dims, 1, Y, n, 2)
    np.testing.assert_allclose(A @ Y, np.eye(n)[:, 1:], atol=1e-15)
