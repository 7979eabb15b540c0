"""The inertia formulas of :mod:`mechdyn.kernels.inertia` against independent oracles:
the kinetic energy of the centre of mass for a body's block, the centre-of-mass analogs
for the reduced mass matrix, the virtual work for the reduced force."""

import numpy as np
import pytest

from mechdyn.kernels.inertia import (
    analog_mass,
    body_mass_block,
    centroidal_inertia,
    parallel_axis,
    reduced_force,
    reduced_mass,
)
from mechdyn.kernels.planar import perp

pytestmark = pytest.mark.timeout(30)


def test_body_block_is_the_kinetic_energy_of_the_centre_of_mass_and_the_spin():
    rng = np.random.default_rng(3)
    m, J, a = rng.uniform(0.5, 3, 10), rng.uniform(0.1, 2, 10), rng.normal(size=(10, 2))
    v = rng.normal(size=(10, 3))  # (vx, vy, omega) of the frame origins
    vc = v[:, :2] + v[:, 2, None] * perp(a)
    T = 0.5 * m * np.sum(vc**2, axis=1) + 0.5 * J * v[:, 2] ** 2
    Mb = body_mass_block(m, J, a)
    assert Mb.shape == (10, 3, 3)
    assert np.allclose(0.5 * np.einsum("ni,nij,nj->n", v, Mb, v), T, rtol=1e-13, atol=0)
    assert np.array_equal(Mb, np.swapaxes(Mb, -1, -2))


def test_parallel_axis_there_and_back():
    rng = np.random.default_rng(4)
    m, J, d = rng.uniform(0.5, 3, 8), rng.uniform(0.1, 2, 8), rng.normal(size=(8, 2))
    Jo = parallel_axis(J, m, d)
    assert np.allclose(Jo, J + m * np.hypot(d[:, 0], d[:, 1]) ** 2, rtol=1e-14, atol=0)
    assert np.allclose(centroidal_inertia(Jo, m, d), J, rtol=1e-13, atol=1e-15)


def test_reduced_mass_of_the_frames_is_the_analog_mass_and_the_force_the_virtual_work():
    rng = np.random.default_rng(5)
    nb, n = 3, 2
    m, J, a = rng.uniform(0.5, 3, nb), rng.uniform(0.1, 2, nb), rng.normal(size=(nb, 2))
    B = rng.normal(size=(3 * nb, n))
    M = np.zeros((3 * nb, 3 * nb))
    for b in range(nb):
        M[3 * b:3 * b + 3, 3 * b:3 * b + 3] = body_mass_block(m[b], J[b], a[b])
    V = B.T.reshape(n, nb, 3)
    vc = V[..., :2] + V[..., 2, None] * perp(a)
    assert np.allclose(reduced_mass(M, B), analog_mass(vc, V[..., 2], m, J), rtol=1e-12,
                       atol=1e-13)
    # batched like one at a time
    Bs = np.stack([B, 2 * B])
    assert np.allclose(reduced_mass(M, Bs)[1], 4 * reduced_mass(M, B), rtol=1e-14, atol=0)
    # f . dq is the virtual work of F - h - M b on dx = B dq
    F, h, bb = rng.normal(size=(3, 3 * nb))
    dq = rng.normal(size=n)
    f = reduced_force(B, F, h, M, bb)
    assert np.isclose(f @ dq, (F - h - M @ bb) @ (B @ dq), rtol=1e-12, atol=1e-13)
    assert np.allclose(reduced_force(Bs, np.stack([F, F]))[0], B.T @ F, rtol=1e-14, atol=0)
