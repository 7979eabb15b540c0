"""The row evaluators (NumPy and Numba) against central differences.

The one oracle for every joint's formulas: the Jacobian is the derivative of
the value, and the quadratic term is d(m_x xdot)/dt - m_x xddot along a path
x(t) = x + xdot t + xddot t^2 / 2, both by fourth-order central differences, to 1e-9.
"""

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.kernels import rows_numba as RB
from mechdyn.kernels import rows_numpy as RN
from mechdyn.model import rows as R


def _random_rows(rng, nb, n=40):
    parts = []
    g = nb  # ground

    def body():
        return int(rng.integers(0, nb + 1))

    def vec():
        return tuple(rng.normal(size=2))

    for k in range(n):
        kind = k % 7
        if kind == 0:
            parts.append(R.revolute(f"r{k}", body(), vec(), body(), vec(), nb=nb))
        elif kind == 1:
            parts.append(R.prismatic(f"p{k}", body(), vec(), vec(), body(), vec(),
                                     float(rng.normal()), nb=nb))
        elif kind == 2:
            parts.append(R.weld(f"w{k}", body(), vec(), body(), float(rng.normal()), nb=nb))
        elif kind == 3:
            parts.append(R.line(f"l{k}", body(), vec(), body(), vec(), vec(),
                                normal=bool(k % 2), offset=float(rng.normal()), nb=nb))
        elif kind == 4:
            parts.append(R.point(f"pt{k}", body(), vec(), k % 2, nb=nb).scaled(-1.0, 0.3))
        elif kind == 5:
            parts.append(R.relative_angle(f"ra{k}", body(), body(), 0.2, nb=nb))
        else:
            parts.append(R.angle(f"a{k}", min(body(), g), -0.1, nb=nb))
    return R.concat(nb, *parts)


def _example_rows():
    out = []
    for name in examples.names():
        m = examples.load(name).compile()
        out.append((name, R.concat(m.n_bodies, m.joint_rows, *m.weld_rows.values(),
                                   m.coordinate_rows)))
    return out


def _derivative(f, h):
    """Fourth-order central difference of f at 0."""
    return (8.0 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12.0 * h)


def _check(rows, x, xd, xdd, values, jacobian, quad):
    h = 1e-3
    n_x = rows.n_x
    J = jacobian(x)
    Jfd = np.empty_like(J)
    for c in range(n_x):
        e = np.zeros(n_x)
        e[c] = 1.0
        Jfd[:, c] = _derivative(lambda t, e=e: values(x + e * t), h)
    assert np.max(np.abs(J - Jfd)) < 1e-9

    # d/dt (m_x xdot) along x(t) = x + xd t + xdd t^2 / 2 is m_x xdd + quad
    def rate(t):
        return jacobian(x + xd * t + 0.5 * xdd * t * t) @ (xd + xdd * t)

    quad_fd = _derivative(rate, h) - J @ xdd
    assert np.max(np.abs(quad(x, xd) - quad_fd)) < 1e-9


def _numpy_funcs(rows):
    return (lambda x: RN.values(rows, x), lambda x: RN.jacobian(rows, x),
            lambda x, xd: RN.quad(rows, x, xd))


def _numba_funcs(rows):
    ints, flts = rows.packed()
    n, nb = len(rows), rows.nb

    def values(x):
        out = np.empty(n)
        RB.rows_values(np.asarray(x, float), nb, ints, flts, out, 0)
        return out

    def jacobian(x):
        J = np.zeros((n, rows.n_x))
        RB.rows_jacobian(np.asarray(x, float), nb, ints, flts, J, 0)
        return J

    def quad(x, xd):
        out = np.empty(n)
        RB.rows_quad(np.asarray(x, float), np.asarray(xd, float), nb, ints, flts, out, 0)
        return out

    return values, jacobian, quad


def _numba_shared_rotations_funcs(rows):
    """The compiled evaluators with the bodies' rotations computed once per pose."""
    ints, flts = rows.packed()
    n, nb = len(rows), rows.nb

    def rotations(x):
        cs = np.empty((nb + 1, 2))
        RB.body_rotations(np.asarray(x, float), nb, cs)
        return cs

    def values(x):
        out = np.empty(n)
        RB.rows_values_cs(np.asarray(x, float), nb, ints, flts, rotations(x), out, 0)
        return out

    def jacobian(x):
        J = np.zeros((n, rows.n_x))
        RB.rows_jacobian_cs(np.asarray(x, float), nb, ints, flts, rotations(x), J, 0)
        return J

    def quad(x, xd):
        out = np.empty(n)
        RB.rows_quad_cs(np.asarray(x, float), np.asarray(xd, float), nb, ints, flts,
                        rotations(x), out, 0)
        return out

    return values, jacobian, quad


FUNCS = [_numpy_funcs, _numba_funcs, _numba_shared_rotations_funcs]
IDS = ["numpy", "numba", "numba-shared-rotations"]


@pytest.mark.parametrize("funcs", FUNCS, ids=IDS)
def test_random_rows_match_central_differences(funcs):
    rng = np.random.default_rng(7)
    for nb in (1, 3, 5):
        rows = _random_rows(rng, nb)
        for _ in range(3):
            x, xd, xdd = (rng.normal(size=3 * nb) for _ in range(3))
            _check(rows, x, xd, xdd, *funcs(rows))


@pytest.mark.parametrize("funcs", FUNCS, ids=IDS)
def test_every_bundled_example_matches_central_differences(funcs):
    rng = np.random.default_rng(3)
    for _name, rows in _example_rows():
        x, xd, xdd = (rng.normal(size=rows.n_x) for _ in range(3))
        _check(rows, x, xd, xdd, *funcs(rows))


def test_batched_evaluation_equals_pose_by_pose():
    rng = np.random.default_rng(11)
    rows = _random_rows(rng, 4)
    x = rng.normal(size=(3, 2, rows.n_x))
    xd = rng.normal(size=(3, 2, rows.n_x))
    v, J, q = RN.evaluate(rows, x, xd)
    for a in range(3):
        for b in range(2):
            v1, J1, q1 = RN.evaluate(rows, x[a, b], xd[a, b])
            assert np.allclose(v[a, b], v1, rtol=0, atol=1e-14)
            assert np.allclose(J[a, b], J1, rtol=0, atol=1e-14)
            assert np.allclose(q[a, b], q1, rtol=0, atol=1e-13)


def test_revolute_rows_vanish_when_the_points_coincide():
    # body 0 at the origin turned 90 deg: its point (0.1, 0) is at (0, 0.1)
    r = R.revolute("A", 0, (0.1, 0.0), 2, (0.0, 0.1), nb=2)
    assert np.allclose(RN.values(r, [0.0, 0.0, np.pi / 2, 5.0, 5.0, 0.0]), 0.0, atol=1e-15)
