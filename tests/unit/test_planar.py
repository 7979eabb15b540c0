"""The planar formulas against independent oracles: complex multiplication for the
rotation, the 3-D cross product of NumPy for the moment."""

import numpy as np
import pytest

from mechdyn.kernels.planar import cross, perp, rotate, rotate_back

pytestmark = pytest.mark.timeout(30)


def test_rotation_is_multiplication_by_a_unit_complex_number():
    rng = np.random.default_rng(7)
    th, s = rng.uniform(-7, 7, size=50), rng.normal(size=(50, 2))
    z = (s[:, 0] + 1j * s[:, 1]) * np.exp(1j * th)
    assert np.allclose(rotate(th, s), np.column_stack([z.real, z.imag]), rtol=0, atol=1e-14)
    # one vector for every angle broadcasts like one per angle
    assert np.array_equal(rotate(th, s[0]), rotate(th, np.broadcast_to(s[0], s.shape)))


def test_perpendicular_is_a_quarter_turn_and_cross_is_the_z_of_the_3d_product():
    rng = np.random.default_rng(8)
    a, b = rng.normal(size=(20, 2)), rng.normal(size=(20, 2))
    assert np.allclose(perp(a), rotate(np.pi / 2, a), rtol=0, atol=1e-15)
    a3, b3 = (np.column_stack([v, np.zeros(len(v))]) for v in (a, b))
    assert np.allclose(cross(a, b), np.cross(a3, b3)[:, 2], rtol=0, atol=1e-15)
    assert np.allclose(cross(a, b), np.einsum("ij,ij->i", perp(a), b), rtol=0, atol=1e-15)


def test_rotating_back_undoes_the_rotation():
    rng = np.random.default_rng(9)
    th, s = rng.uniform(-7, 7, size=30), rng.normal(size=(30, 2))
    assert np.allclose(rotate_back(th, rotate(th, s)), s, rtol=0, atol=1e-14)
    z = (s[:, 0] + 1j * s[:, 1]) * np.exp(-1j * th)
    assert np.allclose(rotate_back(th, s), np.column_stack([z.real, z.imag]), rtol=0,
                       atol=1e-14)
