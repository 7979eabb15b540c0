"""Exact constraint Jacobians and acceleration terms against finite differences."""

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.model.constraints import (
    coordinates,
    coordinates_gamma,
    coordinates_jacobian,
    gamma,
    jacobian,
    residual,
)


def every_joint_mechanism():
    """Bodies joined by a revolute, a prismatic with offset points and a lock."""
    m = Mechanism("all joints")
    m.add_body("a", mass=1, inertia=0.1, com=(0.1, 0.02), points={"P": (0.3, 0.05)},
               pose=(0.1, 0.2, 0.4))
    m.add_body("b", mass=2, inertia=0.2, points={"Q": (-0.1, 0.07)}, pose=(0.4, 0.5, 1.1))
    m.add_body("c", mass=1, inertia=0.1, pose=(0.6, 0.1, -0.3))
    m.add_revolute("R", "a", "b", "P", "Q")
    m.add_prismatic("S", "b", "c", (0.05, -0.02), (0.6, 0.8), (0.01, 0.03))
    m.add_lock("L", "ground", "a")
    m.add_coordinate("s", kind="travel", joint="S")
    m.add_coordinate("rel", kind="relative_angle", joint="R")
    return m


@pytest.fixture(scope="module")
def model():
    mech = every_joint_mechanism()
    from mechdyn.model import Model

    return Model(mech)  # not assembled: the checks hold at any pose


def test_jacobian_matches_central_differences(model):
    rng = np.random.default_rng(1)
    x = rng.normal(size=model.n_x)
    J = np.concatenate([jacobian(model, x), coordinates_jacobian(model, x)])
    h = 1e-6
    Jfd = np.empty_like(J)
    for k in range(model.n_x):
        e = np.zeros(model.n_x)
        e[k] = h
        fp = np.concatenate([residual(model, x + e), coordinates(model, x + e)])
        fm = np.concatenate([residual(model, x - e), coordinates(model, x - e)])
        Jfd[:, k] = (fp - fm) / (2 * h)
    assert np.max(np.abs(J - Jfd)) < 1e-8


def test_gamma_is_minus_second_derivative_along_a_path(model):
    # along x(t) = x0 + v t (xddot = 0): d^2 Phi/dt^2 = Phi_x xddot - gamma = -gamma
    rng = np.random.default_rng(2)
    x0, v = rng.normal(size=model.n_x), rng.normal(size=model.n_x)
    h = 1e-4

    def f(t):
        x = x0 + v * t
        return np.concatenate([residual(model, x), coordinates(model, x)])

    second = (f(h) - 2 * f(0) + f(-h)) / h**2
    g = np.concatenate([gamma(model, x0, v), coordinates_gamma(model, x0, v)])
    assert np.max(np.abs(second + g)) < 1e-5


def test_batched_evaluation_equals_pointwise(model):
    rng = np.random.default_rng(3)
    xs = rng.normal(size=(4, 3, model.n_x))
    vs = rng.normal(size=(4, 3, model.n_x))
    Jb, gb = jacobian(model, xs), gamma(model, xs, vs)
    for i in range(4):
        for j in range(3):
            assert np.allclose(Jb[i, j], jacobian(model, xs[i, j]), rtol=0, atol=1e-15)
            assert np.allclose(gb[i, j], gamma(model, xs[i, j], vs[i, j]), rtol=0, atol=1e-15)
