"""Static indeterminacy by influence coefficients (issue 12, item 5): beams on three
supports against the closed forms of the indeterminate beam, with and without lift-off."""

import numpy as np
import pytest

from mechdyn.contact.compliance import (
    beam_on_supports,
    check_compliance,
    share_by_compliance,
    solve_supports,
)
from mechdyn.errors import ModelError

# a rigid beam on three springs of different stiffness
X = np.array([0.0, 1.5, 4.0])  # m
K = np.array([2e6, 5e6, 3e6])  # N/m
P = 10e3  # N


def _three_springs(xi):
    """Closed form: w = w0 + phi x, lambda_i = k_i w(x_i), sum lambda = P, sum lambda x = P xi."""
    s0, s1, s2 = K.sum(), (K * X).sum(), (K * X * X).sum()
    det = s0 * s2 - s1 * s1
    w0 = P * (s2 - xi * s1) / det
    phi = P * (xi * s0 - s1) / det
    return K * (w0 + phi * X), w0, phi


def test_rigid_beam_on_three_springs_of_different_stiffness():
    lam, w0, phi = _three_springs(2.0)
    assert np.all(lam > 0)
    s = beam_on_supports(X, K, loads=[(2.0, P)]).solve()
    np.testing.assert_allclose(s.forces, lam, rtol=1e-12)
    np.testing.assert_allclose(s.motion, [w0, phi], rtol=1e-12)
    np.testing.assert_allclose(s.gaps, 0.0, atol=1e-18)
    assert s.closed.all()


def test_rigid_beam_lifts_off_its_far_support_and_becomes_determinate():
    xi = 0.3
    lam3, _, _ = _three_springs(xi)
    assert lam3[2] < 0  # the three-spring solution would pull on support 3
    s = beam_on_supports(X, K, loads=[(xi, P)]).solve()
    # statically determinate on supports 1 and 2: the lever rule
    r1 = P * (X[1] - xi) / (X[1] - X[0])
    r2 = P * (xi - X[0]) / (X[1] - X[0])
    np.testing.assert_allclose(s.forces, [r1, r2, 0.0], rtol=1e-12, atol=1e-9)
    # the beam turns about the compressed springs 1 and 2: support 3 opens by -w(x3)
    w1, w2 = r1 / K[0], r2 / K[1]
    w3 = w1 + (w2 - w1) * (X[2] - X[0]) / (X[1] - X[0])
    np.testing.assert_allclose(s.gaps[2], -w3, rtol=1e-12)
    assert s.gaps[2] > 0 and s.closed.tolist() == [True, True, False]
    # held down (bilateral supports): the three-spring solution with its negative force
    sb = beam_on_supports(X, K, loads=[(xi, P)], bilateral=[True] * 3).solve()
    np.testing.assert_allclose(sb.forces, lam3, rtol=1e-12)


def test_a_support_with_clearance_takes_load_only_once_it_is_closed():
    k, k2, g0 = 1e6, 4e6, 1e-3
    for p in (1500.0, 6000.0):
        s = beam_on_supports([-1.0, 0.0, 1.0], [k, k2, k], loads=[(0.0, p)],
                             gaps=[0.0, g0, 0.0]).solve()
        w = p / (2 * k)
        if w > g0:  # closed: 2 k w + k2 (w - g0) = P
            w = (p + k2 * g0) / (2 * k + k2)
        np.testing.assert_allclose(s.forces, [k * w, k2 * max(w - g0, 0.0), k * w],
                                   rtol=1e-12, atol=1e-9)
    assert s.closed.all()


# a flexible two-span continuous beam: spans L, supports A (0), B (L), C (2L)
L, EI = 3.0, 2.0e6  # m, N m^2


def test_influence_coefficients_of_the_beam_are_the_textbook_ones():
    pb = beam_on_supports([0.0, L, 2 * L], EI=EI)
    # simply supported on A and C (span 2L): delta_BB = (2L)^3 / (48 EI)
    np.testing.assert_allclose(pb.C[1, 1], (2 * L) ** 3 / (48 * EI), rtol=1e-14)
    np.testing.assert_allclose(pb.C[[0, 2]], 0.0, atol=1e-20)


def test_two_span_beam_with_a_load_in_one_span_indeterminate_and_lifting_off():
    a = 1.2
    b = L - a
    # three-moment equation: M_B = -P a b (L + a) / (4 L^2)
    mb = -P * a * b * (L + a) / (4 * L * L)
    ra, rc = P * b / L + mb / L, mb / L
    rb = P - ra - rc
    held = beam_on_supports([0.0, L, 2 * L], EI=EI, loads=[(a, P)],
                            bilateral=[True] * 3).solve()
    np.testing.assert_allclose(held.forces, [ra, rb, rc], rtol=1e-12)
    assert rc < 0  # C pulls: a support that only pushes lifts off
    free = beam_on_supports([0.0, L, 2 * L], EI=EI, loads=[(a, P)]).solve()
    # statically determinate: span AB simply supported, BC an unloaded overhang
    np.testing.assert_allclose(free.forces, [P * b / L, P * a / L, 0.0], rtol=1e-12,
                               atol=1e-9)
    # the overhang turns with the slope at B of the simple span: theta_B = P a (L^2 - a^2)
    # / (6 L EI), so C rises by theta_B L
    np.testing.assert_allclose(free.gaps[2], P * a * (L * L - a * a) / (6 * EI), rtol=1e-12)
    assert free.closed.tolist() == [True, True, False]


def test_two_span_beam_loaded_in_both_spans_on_elastic_supports():
    loads = [(1.0, 8e3), (4.5, 5e3)]
    k = np.array([4e6, 9e6, 2.5e6])
    s = beam_on_supports([0.0, L, 2 * L], k, EI=EI, loads=loads).solve()
    # force method, redundant R_B: on the base (span 2L on A and C)
    #   deflection at B by a load Q at t: Q t (3 L^2 - t^2) / (12 EI) for t <= L (mirror for
    #   t > L), by R_B: R_B (2L)^3 / (48 EI); statics: R_A = (sum Q (2L - t) - R_B L) / 2L,
    #   R_C = (sum Q t - R_B L) / 2L; compatibility: beam at B relative to the chord AC
    #   equals the settlement of B minus the mean settlement of A and C.
    def d_b(t):
        t = t if t <= L else 2 * L - t
        return t * (3 * L * L - t * t) / (12 * EI)

    dbp = sum(q * d_b(t) for t, q in loads)
    dbb = (2 * L) ** 3 / (48 * EI)
    ra0 = sum(q * (2 * L - t) for t, q in loads) / (2 * L)
    rc0 = sum(q * t for t, q in loads) / (2 * L)
    # dbp - R_B dbb = R_B / kB - ((ra0 - R_B/2) / kA + (rc0 - R_B/2) / kC) / 2
    rb = (dbp + 0.5 * (ra0 / k[0] + rc0 / k[2])) / (
        dbb + 1 / k[1] + 0.25 * (1 / k[0] + 1 / k[2]))
    ra, rc = ra0 - rb / 2, rc0 - rb / 2
    assert min(ra, rb, rc) > 0
    np.testing.assert_allclose(s.forces, [ra, rb, rc], rtol=1e-12)


def test_redundant_bilateral_reactions_shared_by_compliance():
    # three parallel bars (compliances c_i) under a rigid plate pulled by F: each strain equal
    c = np.array([1e-8, 2e-8, 4e-8])
    F = 7e3
    lam = share_by_compliance(np.ones((1, 3)), [F], np.diag(c))
    np.testing.assert_allclose(lam, F * (1 / c) / np.sum(1 / c), rtol=1e-13)


@pytest.mark.parametrize("C, msg", [
    ([[1.0, 0.5], [0.4, 1.0]], "not symmetric"),
    ([[1.0, 2.0], [2.0, 1.0]], "not positive semidefinite"),
    ([[1.0, 0.0, 0.0]], "square"),
    ([[np.inf]], "non-finite"),
])
def test_bad_compliance_matrices_are_named(C, msg):
    with pytest.raises(ModelError, match=msg):
        check_compliance(C)


def test_bad_problems_are_named():
    with pytest.raises(ModelError, match="q has 3 value"):
        solve_supports(np.eye(2), [0.0, 0.0, 0.0])
    with pytest.raises(ModelError, match=r"stiffness of support\(s\) \[1\]"):
        beam_on_supports([0.0, 1.0], [1e6, -1.0])
    with pytest.raises(ModelError, match="off the flexible beam"):
        beam_on_supports([0.0, 1.0], EI=1e5, loads=[(2.0, 1.0)])
    with pytest.raises(ModelError, match=r"load 1: expected a pair \(x, P\)"):
        beam_on_supports([0.0, 1.0], loads=[(0.5, 1.0), (0.5,)])
    with pytest.raises(ModelError, match="load 0: x and P must be finite"):
        beam_on_supports([0.0, 1.0], loads=[(0.5, np.nan)])
    # rigid beam on three rigid supports: nothing shares the load
    with pytest.raises(ModelError, match="not unique"):
        beam_on_supports(X, loads=[(2.0, P)]).solve()
    # a load beyond the only supports that can push: the beam tips over
    with pytest.raises(ModelError, match="no set of supports holds the body"):
        beam_on_supports([0.0, 1.0], [1e6, 1e6], loads=[(2.0, P)]).solve()


def test_random_problems_against_a_general_qp_solver_and_their_optimality_conditions():
    # a second formulation: SciPy's SLSQP on the same quadratic programme; and the
    # conditions themselves, checked here
    from scipy.optimize import minimize

    rng = np.random.default_rng(1)
    methods = set()
    for _ in range(40):
        k, m = int(rng.integers(3, 8)), int(rng.integers(0, 3))
        R = rng.normal(size=(k, k))
        C = R @ R.T * 1e-6 + np.eye(k) * 1e-8
        q = rng.normal(size=k) * 1e-3
        bil = rng.random(k) < 0.2
        A = rng.normal(size=(k, m))
        lam0 = rng.random(k)
        f = A.T @ lam0  # feasible
        s = solve_supports(C, q, bilateral=bil, equilibrium=(A, f) if m else None)
        methods.add(s.method)
        uni = ~bil
        g = C @ s.forces + q - A @ s.motion
        np.testing.assert_allclose(g, s.gaps, atol=1e-15)
        assert np.all(s.forces[uni] >= -1e-12) and np.all(g[uni] >= -1e-15)
        scale = np.abs(s.forces).max() * np.abs(q).max()
        assert np.max(np.abs(s.forces * g)) < 1e-12 * scale and np.all(s.gaps[s.closed] == 0)
        assert s.closed[bil].all() and np.all(s.forces[~s.closed] == 0)
        np.testing.assert_allclose(A.T @ s.forces, f, atol=1e-12)

        def obj(lam, C=C, q=q):
            return 0.5 * lam @ C @ lam + q @ lam

        cons = [{"type": "eq", "fun": lambda lam, A=A, f=f: A.T @ lam - f}] if m else []
        ref = minimize(obj, lam0, jac=lambda lam, C=C, q=q: C @ lam + q, method="SLSQP",
                       bounds=[(None, None) if b else (0, None) for b in bil],
                       constraints=cons, options=dict(ftol=1e-15, maxiter=1000))
        assert obj(s.forces) <= obj(ref.x) + 1e-12 * abs(obj(ref.x))
        np.testing.assert_allclose(s.forces, ref.x, atol=1e-4 * max(1, abs(s.forces).max()))
    assert methods == {"active-set", "enumeration"}  # both ways of finding the set run


@pytest.mark.parametrize("stiffness", [None, [1e20] * 3])
def test_a_support_standing_proud_of_rigid_supports_lifts_the_beam_off_the_far_one(stiffness):
    # rigid beam, supports at 0, 1, 2 m, the middle one 1 mm higher (gap -1 mm), 1 kN at
    # 0.5 m: the beam rests on the first two (statics of a beam on two supports: 500 N
    # each) and clears the third by 2 mm (the line through w(0) = 0, w(1) = -1 mm); the
    # supports only push, so the 1500 N / -500 N pair on the last two is not a solution
    s = beam_on_supports([0.0, 1.0, 2.0], stiffness, loads=[(0.5, 1000.0)],
                         gaps=[0.0, -1e-3, 0.0]).solve()
    assert s.closed.tolist() == [True, True, False]
    assert np.allclose(s.forces, [500.0, 500.0, 0.0], atol=1e-6)
    assert np.isclose(s.gaps[2], 2e-3, atol=1e-9)
