"""The friction law of pairs (dynamics/friction.py) against hand-written cases, and its
derivative with respect to the multipliers against central differences."""

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.errors import ModelError
from mechdyn.friction.law import FrictionSet, friction_joints


def _block(L=0.12, mu=0.2, c=3.0, smoothing=0.0):
    """A block on a horizontal guide of the ground; joint point (0.2, 0.1) in its frame."""
    m = Mechanism("block")
    m.add_body("block", mass=1.0, inertia=0.1, pose=(0.5, -0.1, 0.0))
    m.add_prismatic("guide", "ground", "block", (0.0, 0.0), (1.0, 0.0), (0.2, 0.1),
                    friction=mu, guide_length=L, viscous=c, smoothing=smoothing)
    m.add_coordinate("s", kind="travel", joint="guide")
    return m.compile()


def test_prismatic_edge_loads_by_hand():
    fs = FrictionSet(_block())
    x = np.array([0.5, -0.1, 0.0])
    xdot = np.array([0.3, 0.0, 0.0])          # sliding at +0.3 m/s
    # rows: the normal row (multiplier = normal force, up to its sign) and the angle
    # row (multiplier = moment about the joint point, up to its sign)
    lam = np.array([40.0, 6.0])              # |N| = 40 N, |M| = 6 N m, L = 0.12 m
    S = abs(20.0 - 6.0 / 0.12) + abs(20.0 + 6.0 / 0.12)   # 30 + 70 = 100 N
    f = -(0.2 * S * 1.0 + 3.0 * 0.3)         # -20.9 N along +x on the block
    F, _ = fs.generalized(x, xdot, lam)
    # at the joint point, arm (0.2, 0.1) from the block origin: moment -0.1 f
    np.testing.assert_allclose(F, [f, 0.0, -0.1 * f], rtol=0, atol=1e-13)
    np.testing.assert_allclose(fs.power_lost(x, xdot, lam)["guide"], -f * 0.3, rtol=1e-15)
    # the edge loads of one sign: S = |N| (L = 0 gives the same)
    lam = np.array([40.0, 1.0])
    F, _ = fs.generalized(x, xdot, lam)
    assert F[0] == pytest.approx(-(0.2 * 40.0 + 0.9), abs=1e-13)
    F0, _ = FrictionSet(_block(L=0.0)).generalized(x, xdot, np.array([40.0, 6.0]))
    assert F0[0] == pytest.approx(-(0.2 * 40.0 + 0.9), abs=1e-13)


def test_smoothing_and_rest():
    x = np.array([0.5, -0.1, 0.0])
    lam = np.array([40.0, 0.0])
    F, _ = FrictionSet(_block(c=0.0, smoothing=0.01)).generalized(
        x, np.array([0.005, 0.0, 0.0]), lam)
    assert F[0] == pytest.approx(-0.2 * 40.0 * np.tanh(0.5), rel=1e-14)
    F, dF = FrictionSet(_block(c=0.0)).generalized(x, np.zeros(3), lam)
    assert not F.any() and not dF.any()      # true Coulomb at rest: no sliding force


def test_slip_direction_of_a_mode_at_zero_or_reverse_speed():
    """signs={joint: s}: where the speed is zero or against s, the Coulomb part is that of
    sgn(v) = s (mu S s by hand), the viscous part that of the actual speed; with the speed
    along s, the law as it is."""
    fs = FrictionSet(_block())
    x, lam = np.array([0.5, -0.1, 0.0]), np.array([40.0, 6.0])
    S = 100.0  # as in test_prismatic_edge_loads_by_hand
    for v, s, want in ((0.0, 1.0, -0.2 * S), (0.0, -1.0, 0.2 * S),
                       (-0.1, 1.0, -0.2 * S + 0.3), (0.3, 1.0, -0.2 * S - 0.9)):
        F, _ = fs.generalized(x, np.array([v, 0.0, 0.0]), lam, signs={"guide": s})
        assert F[0] == pytest.approx(want, abs=1e-13)
    # prepared once at a pose and rates, evaluated at several multipliers
    law = fs.prepare(x, np.array([0.3, 0.0, 0.0]))
    for lam in (np.array([40.0, 6.0]), np.array([-10.0, 2.0])):
        for a, b in zip(law.generalized(lam), fs.generalized(x, np.array([0.3, 0.0, 0.0]), lam),
                        strict=True):
            np.testing.assert_array_equal(a, b)


def _crank_rod():
    """Crank (pin O to the ground) and rod (pin A on the crank), both pins with friction."""
    m = Mechanism("crank-rod")
    m.add_body("crank", mass=1.0, inertia=0.01, points={"A": (0.1, 0.0)}, pose=(0, 0, 0.3))
    m.add_body("rod", mass=1.0, inertia=0.02,
               pose=(0.1 * np.cos(0.3), 0.1 * np.sin(0.3), -0.4))
    m.add_revolute("O", "ground", "crank", friction=0.1, pin_radius=0.01, viscous=0.5)
    m.add_revolute("A", "crank", "rod", "A", (0.0, 0.0), friction=0.15, pin_radius=0.02)
    m.add_coordinate("phi", kind="angle", body="crank")
    m.add_coordinate("psi", kind="angle", body="rod")
    return m.compile()


def test_revolute_friction_circle_by_hand():
    model = _crank_rod()
    fs = FrictionSet(model)
    assert fs.names == ("O", "A") == friction_joints(model)
    x = model.x_sketch
    xdot = np.array([0.0, 0.0, 2.0, -0.2 * np.sin(0.3), 0.2 * np.cos(0.3), -1.0])
    lam = np.array([0.0, 0.0, 30.0, -40.0])  # pin A: |R| = 50 N; pin O unloaded
    F, _ = fs.generalized(x, xdot, lam)
    MA = -(0.15 * 0.02 * 50.0 * np.sign(-1.0 - 2.0))        # on the rod: +0.15 N m
    MO = -(0.1 * 0.01 * 0.0 + 0.5 * 2.0)                   # viscous only: -1 N m on the crank
    np.testing.assert_allclose(F, [0, 0, MO - MA, 0, 0, MA], rtol=0, atol=1e-14)
    P = fs.power_lost(x, xdot, lam)
    assert P["A"] == pytest.approx(0.15 * 3.0, rel=1e-14)
    assert P["O"] == pytest.approx(2.0, rel=1e-14)


def _slider_crank_friction():
    r, l, e, phi0 = 0.08, 0.25, -0.02, 0.6
    A = r * np.array([np.cos(phi0), np.sin(phi0)])
    xb = A[0] + np.sqrt(l**2 - (e - A[1]) ** 2)
    m = Mechanism("slider-crank")
    m.add_ground({"O": (0.0, 0.0), "guide": (0.0, e)})
    m.add_body("crank", mass=0.8, inertia=0.001, points={"A": (r, 0.0)}, pose=(0, 0, phi0))
    m.add_body("rod", mass=1.2, inertia=0.008, points={"B": (l, 0.0)},
               pose=(A[0], A[1], np.arctan2(e - A[1], xb - A[0])))
    m.add_body("slider", mass=2.0, inertia=0.0, pose=(xb, e, 0.0))
    m.add_revolute("O", "ground", "crank", "O", friction=0.1, pin_radius=0.01)
    m.add_revolute("A", "crank", "rod", "A", friction=0.1, pin_radius=0.012, smoothing=0.5)
    m.add_revolute("B", "rod", "slider", "B", friction=0.1, pin_radius=0.008, viscous=0.01)
    m.add_prismatic("guide", "ground", "slider", "guide", (1.0, 0.0), (0.03, 0.01),
                    friction=0.15, guide_length=0.06, smoothing=0.05)
    m.add_coordinate("phi", kind="angle", body="crank")
    return m.compile()


def test_derivative_against_central_differences_batched():
    model = _slider_crank_friction()
    fs = FrictionSet(model)
    rng = np.random.default_rng(1)
    n, n_rows = 5, len(model.joint_rows)
    x = model.x_sketch + 0.02 * rng.standard_normal((n, model.n_x))
    xdot = rng.standard_normal((n, model.n_x))
    lam = 100.0 * rng.standard_normal((n, n_rows))
    F, dF = fs.generalized(x, xdot, lam)
    assert F.shape == (n, model.n_x) and dF.shape == (n, model.n_x, n_rows)
    h = 1e-4
    for r in range(n_rows):
        e = np.zeros(n_rows)
        e[r] = h
        fd = (fs.generalized(x, xdot, lam + e)[0] - fs.generalized(x, xdot, lam - e)[0]) / (2 * h)
        np.testing.assert_allclose(dF[..., r], fd, rtol=0, atol=1e-8 * np.abs(F).max())
    # batched = one position at a time
    F1, dF1 = fs.generalized(x[2], xdot[2], lam[2])
    np.testing.assert_allclose(F1, F[2], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(dF1, dF[2], rtol=1e-14, atol=1e-14)
    # the friction forces' power on the motion is minus the power lost in the pairs
    lost = sum(fs.power_lost(x, xdot, lam).values())
    np.testing.assert_allclose(np.einsum("nx,nx->n", F, xdot), -lost, rtol=1e-12)
    assert all((p >= 0).all() for p in fs.power_lost(x, xdot, lam).values())


def test_unknown_joint_named():
    with pytest.raises(ModelError, match="revolute or prismatic"):
        FrictionSet(_crank_rod(), joints=["Q"])


def test_rows_of_a_layout_and_missing_rows():
    model = _slider_crank_friction()
    fs = FrictionSet(model)
    lay = model.layout()
    rng = np.random.default_rng(2)
    x, xdot = model.x_sketch, rng.standard_normal(model.n_x)
    lam = rng.standard_normal(lay.n_rows)
    F, dF = fs.generalized(x, xdot, lam)
    F2, dF2 = fs.generalized(x, xdot, lam, lay)
    np.testing.assert_array_equal(F, F2)
    np.testing.assert_array_equal(dF, dF2)
    with pytest.raises(ValueError, match="'guide'"):
        fs.generalized(x, xdot, lam, {"O": [0, 1], "A": [2, 3], "B": [4, 5]})


def test_bad_friction_keywords_in_python_are_named_errors():
    m = Mechanism("m")
    m.add_body("a")
    with pytest.raises(ModelError, match=r"prismatic joint 'P'.*'compliance'.*'guide_length'"):
        m.add_prismatic("P", "ground", "a", compliance=1e-9)
    with pytest.raises(ModelError, match=r"revolute joint 'O'.*'frction'.*'friction'"):
        m.add_revolute("O", "ground", "a", frction=0.1)
    m.add_revolute("O", "ground", "a", friction="0.1", pin_radius=0.01)
    assert any("friction must be a finite number >= 0, got '0.1'" in p for p in m.problems())


def test_too_few_multipliers_name_the_joint():
    fs = FrictionSet(_block())
    with pytest.raises(ModelError, match=r"lam has 1 multiplier.*joint 'guide'"):
        fs.generalized(np.zeros(3), np.zeros(3), np.zeros(1))
