"""The kinematic sweep: dead positions, bookkeeping, the fast kernel, tables and plots."""

import re

import numpy as np
import pytest

from mechdyn import Mechanism, ModelError, SingularPositionError
from mechdyn.kernels import rows_numba
from mechdyn.kinematics import branch_sign, residual
from mechdyn.kinematics.continuation import Kernel
from mechdyn.kinematics.sweep import (
    KinematicSweep,
    _anchor_indices,
    _hermite5,
    analyze,
    initial_coordinates,
    sweep,
)
from mechdyn.model import Model
from mechdyn.model.constraints import coordinates

A_, B_, C_, D_ = 0.02, 0.07, 0.05, 0.06


def four_bar(drive="crank", phi0=1.0):
    """Crank-rocker: ground pivots (0, 0) and (d, 0); crank a, coupler b, rocker c."""
    m = Mechanism("four-bar")
    B = A_ * np.array([np.cos(phi0), np.sin(phi0)])
    e = np.hypot(D_ - B[0], B[1])
    u = np.array([D_ - B[0], -B[1]]) / e
    along = (B_**2 - C_**2 + e**2) / (2 * e)
    C = B + along * u + np.sqrt(B_**2 - along**2) * np.array([-u[1], u[0]])
    m.add_body("crank", com=(0.01, 0.0), points={"B": (A_, 0.0)}, pose=(0.0, 0.0, phi0))
    m.add_body("coupler", points={"C": (B_, 0.0)},
               pose=(B[0], B[1], np.arctan2(C[1] - B[1], C[0] - B[0])))
    m.add_body("rocker", points={"C": (C_, 0.0)}, pose=(D_, 0.0, np.arctan2(C[1], C[0] - D_)))
    m.add_revolute("A", "ground", "crank")
    m.add_revolute("B", "crank", "coupler", "B", (0.0, 0.0))
    m.add_revolute("C", "coupler", "rocker", "C", "C")
    m.add_revolute("D", "ground", "rocker", (D_, 0.0), (0.0, 0.0))
    if drive == "crank":
        m.add_coordinate("phi", "angle", body="crank")
    else:
        m.add_coordinate("psi", "angle", body="rocker")
    return m


def rocker_limit(r):
    """Rocker angle (upper branch) where |A C| = r: crank and coupler in line."""
    return np.pi - np.arccos((D_**2 + C_**2 - r**2) / (2 * D_ * C_))


def five_bar():
    """Two cranks (phi1 at (0,0), phi2 at (0.05,0)) and two links meeting at P: 2 DOF."""
    m = Mechanism("five-bar")
    r1, r2, l1, l2, d = 0.02, 0.02, 0.06, 0.06, 0.05
    p1, p2 = 1.2, 1.6
    B = r1 * np.array([np.cos(p1), np.sin(p1)])
    D = np.array([d, 0.0]) + r2 * np.array([np.cos(p2), np.sin(p2)])
    e = np.linalg.norm(D - B)
    u = (D - B) / e
    along = (l1**2 - l2**2 + e**2) / (2 * e)
    P = B + along * u + np.sqrt(l1**2 - along**2) * np.array([-u[1], u[0]])
    m.add_body("c1", points={"B": (r1, 0.0)}, pose=(0.0, 0.0, p1))
    m.add_body("c2", points={"D": (r2, 0.0)}, pose=(d, 0.0, p2))
    m.add_body("l1", points={"P": (l1, 0.0)}, pose=(*B, np.arctan2(*(P - B)[::-1])))
    m.add_body("l2", points={"P": (l2, 0.0)}, pose=(*D, np.arctan2(*(P - D)[::-1])))
    m.add_revolute("A", "ground", "c1")
    m.add_revolute("E", "ground", "c2", (d, 0.0), (0.0, 0.0))
    m.add_revolute("B", "c1", "l1", "B", (0.0, 0.0))
    m.add_revolute("D", "c2", "l2", "D", (0.0, 0.0))
    m.add_revolute("P", "l1", "l2", "P", "P")
    m.add_coordinate("phi1", "angle", body="c1")
    m.add_coordinate("phi2", "angle", body="c2")
    return m


def every_joint_model():
    m = Mechanism("all joints")
    m.add_body("a", com=(0.1, 0.02), points={"P": (0.3, 0.05)}, pose=(0.1, 0.2, 0.4))
    m.add_body("b", points={"Q": (-0.1, 0.07)}, pose=(0.4, 0.5, 1.1))
    m.add_body("c", pose=(0.6, 0.1, -0.3))
    m.add_body("d", pose=(0.2, 0.3, 0.2))
    m.add_body("e", pose=(-0.2, 0.1, 0.5))
    m.add_revolute("R", "a", "b", "P", "Q")
    m.add_prismatic("S", "b", "c", (0.05, -0.02), (0.6, 0.8), (0.01, 0.03))
    m.add_prismatic("T", "ground", "d", (0.1, 0.1), (1.0, 0.3), (0.02, 0.0))
    m.add_revolute("E", "ground", "e", (-0.1, 0.0), (0.1, 0.05))
    m.add_lock("L", "ground", "a")
    m.add_coordinate("s", kind="travel", joint="S")
    m.add_coordinate("rel", kind="relative_angle", joint="R")
    m.add_coordinate("t", kind="travel", joint="T")
    m.add_coordinate("th", kind="angle", body="e")
    return Model(m)  # not assembled: the equations hold at any pose


# ---------------------------------------------------------------- dead positions
@pytest.mark.parametrize("direction, limit", [(+1, rocker_limit(B_ - A_)),
                                               (-1, rocker_limit(B_ + A_))],
                         ids=["folded", "stretched"])
def test_driving_a_four_bar_from_its_rocker_past_its_range_stops_at_the_dead_position(
        direction, limit):
    model = four_bar(drive="psi").compile()
    psi0 = model.x0[3 * model.body_index("rocker") + 2]
    values = psi0 + direction * np.linspace(0.0, 1.5, 301)
    sw = sweep(model, values=values)
    assert sw.status == "singular-position" and not sw.ok
    # every value short of the limit is kept, none beyond it
    n_before = int(np.sum(direction * (values - limit) < 0))
    assert len(sw) == n_before and sw.stats["n_requested"] == 301
    ev = sw.events[0]
    assert ev["kind"] == "dead-position" and abs(ev["at"] - limit) < 1e-8
    # the message names the coordinate and where, in degrees
    m = re.search(r"dead position at psi = ([-0-9.]+) deg", sw.message)
    assert m and abs(float(m.group(1)) - np.rad2deg(limit)) < 1e-5
    assert set(ev["joints"]) >= {"A", "B"}
    with pytest.raises(SingularPositionError) as err:
        sw.raise_for_status()
    assert err.value.coordinates == ["psi"]
    assert np.max(np.abs(residual(model, sw.x))) < 1e-12


def test_a_full_turn_of_the_crank_meets_no_dead_position():
    sw = sweep(four_bar())
    assert sw.ok and sw.message == "" and sw.events == ()
    assert sw.raise_for_status() is sw


# ---------------------------------------------------------------- bookkeeping
def test_default_values_are_a_full_turn_from_the_assembled_value():
    model = four_bar(phi0=0.7).compile()
    sw = sweep(model)
    assert sw.over == "phi" and len(sw) == 361
    assert np.isclose(sw.values[0], 0.7) and np.isclose(sw.values[-1] - sw.values[0], 2 * np.pi)
    assert np.allclose(np.diff(sw.values), np.deg2rad(1.0))
    assert sw.q.shape == (361, 1) and sw.x.shape == (361, 9) and sw.B.shape == (361, 9, 1)
    # one full turn brings every body back to its pose (angles modulo 2 pi)
    d = sw.x[-1] - sw.x[0]
    d[2::3] = (d[2::3] + np.pi) % (2 * np.pi) - np.pi
    assert np.max(np.abs(d)) < 1e-12


def test_records_are_frozen_and_read_only():
    sw = sweep(four_bar(), values=np.linspace(0, 1, 5))
    assert isinstance(sw, KinematicSweep)
    with pytest.raises(AttributeError):
        sw.status = "x"
    with pytest.raises(ValueError):
        sw.x[0, 0] = 1.0


def test_back_and_forth_values_return_to_the_same_poses():
    go = np.linspace(0.0, np.pi, 91)
    values = np.concatenate([go, go[::-1][1:]])
    sw = sweep(four_bar(), values=values)
    assert sw.ok
    assert np.max(np.abs(sw.x[:91] - sw.x[90:][::-1])) < 1e-13


def test_start_away_from_the_sketch_and_coarse_values():
    # values 40 deg apart and starting far from the sketch: continuation steps in between
    values = np.deg2rad(np.arange(200.0, 560.0, 40.0))
    sw = sweep(four_bar(phi0=1.0), values=values)
    ref = sweep(four_bar(phi0=1.0), values=np.deg2rad(np.arange(200.0, 560.0, 1.0)))
    assert sw.ok and np.max(np.abs(sw.x - ref.x[::40])) < 1e-13


def test_speed_scales_velocities_and_accelerations():
    unit = sweep(four_bar(), values=np.linspace(0, 6, 61))
    fast = sweep(four_bar(), values=np.linspace(0, 6, 61), speed=12.5)
    assert np.allclose(fast.xdot, 12.5 * unit.xdot, rtol=1e-13, atol=1e-15)
    assert np.allclose(fast.xddot, 12.5**2 * unit.xddot, rtol=1e-12, atol=1e-12)
    assert np.allclose(fast.B, unit.B, rtol=0, atol=1e-15)


def test_two_dof_sweep_keeps_the_other_coordinate_and_uses_all_rates():
    mech = five_bar()
    model = mech.compile()
    sw = sweep(model, "phi1", 1.2 + np.linspace(0, 0.5, 26), speed={"phi1": 2.0, "phi2": -3.0})
    assert sw.ok
    assert np.allclose(sw.q[:, 1], 1.6, atol=1e-14)
    assert np.allclose(sw.qdot, [2.0, -3.0])
    # accelerations with both rates: second difference of positions along q + qdot t
    i, h = 10, 1e-4
    q, qd = sw.q[i], sw.qdot[i]
    xs = [analyze(model, q + s * h * qd, qd, x_guess=sw.x[i]).x for s in (-1, 0, 1)]
    fd = (xs[2] - 2 * xs[1] + xs[0]) / h**2
    assert np.max(np.abs(fd - sw.xddot[i])) < 1e-6 * np.max(np.abs(sw.xddot[i]))
    # the initial value of the other coordinate can come from the model file data
    mech.extras["initial"] = {"q": {"phi2": 1.5}}
    model2 = mech.compile()
    assert np.isclose(initial_coordinates(model2)[1], 1.5)
    sw2 = sweep(model2, "phi1", [1.2, 1.3])
    assert np.allclose(sw2.q[:, 1], 1.5) and sw2.ok


def test_multi_dof_needs_over_and_names_are_checked():
    model = five_bar().compile()
    with pytest.raises(ModelError, match="phi1"):
        sweep(model)
    with pytest.raises(ModelError, match="valid coordinate names"):
        sweep(model, "phi3")
    with pytest.raises(ModelError, match="coordinate"):
        sweep(model, "phi1", [1.2], speed={"nope": 1.0})


def test_analyze_matches_the_sweep():
    model = four_bar().compile()
    sw = sweep(model, values=np.linspace(1.0, 3.0, 21), speed=3.0)
    pt = analyze(model, sw.q[7], sw.qdot[7], x_guess=sw.x[7])
    assert np.allclose(pt.x, sw.x[7], atol=1e-14)
    assert np.allclose(pt.xdot, sw.xdot[7], atol=1e-13)
    assert np.allclose(pt.xddot, sw.xddot[7], atol=1e-11)
    r, v, a = pt.point("coupler", "C")
    R, V, Acc = sw.point("coupler", "C")
    assert np.allclose(r, R[7]) and np.allclose(v, V[7]) and np.allclose(a, Acc[7])


# ---------------------------------------------------------------- internals
def test_anchors_are_at_most_max_step_apart_and_keep_turning_points():
    v = np.linspace(0, 2 * np.pi, 3601)
    a = _anchor_indices(v, np.deg2rad(5.0))
    assert a[0] == 0 and a[-1] == 3600
    assert np.max(np.diff(v[a])) <= np.deg2rad(5.0) * (1 + 1e-9)
    assert len(a) == 73
    w = np.concatenate([np.linspace(0, 1, 11), np.linspace(1, 0.5, 6)[1:]])
    assert 10 in _anchor_indices(w, 0.3)


def test_quintic_hermite_is_exact_for_quintics():
    rng = np.random.default_rng(3)
    c = rng.normal(size=6)
    p = np.polynomial.Polynomial(c)
    q0, h = 0.3, 0.7
    d1, d2 = p.deriv(1), p.deriv(2)
    t = np.linspace(-0.5, 2.0, 11)[:, None]
    got = _hermite5(t, h, p(q0), d1(q0), d2(q0), p(q0 + h), d1(q0 + h), d2(q0 + h))
    assert np.allclose(got[:, 0], p(q0 + h * t[:, 0]), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("mode", [frozenset(), frozenset({"L"})])
def test_kernel_jacobian_and_gamma_are_derivatives_of_its_residual(mode):
    # the kernel's own consistency: J = dF/dx and gamma = -d2F/dt2 along x + v t,
    # by fourth-order central differences (the joint formulas are the rows' own)
    model = every_joint_model()
    lay = model.layout(mode)
    kern = Kernel(model, lay)
    assert kern.rows.labels == lay.rowset.labels + model.coordinate_rows.labels
    rng = np.random.default_rng(5)
    x, q, v = rng.normal(size=model.n_x), rng.normal(size=model.n_q), rng.normal(size=model.n_x)
    h = 1e-3

    def d(f):
        return (8.0 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12.0 * h)

    F, J = kern.system(x[None], q[None])
    assert np.allclose(F[0, lay.n_rows:] + q, coordinates(model, x), rtol=0, atol=1e-15)
    E = np.eye(model.n_x)
    J_fd = np.stack([d(lambda t, e=e: kern.system((x + t * e)[None], q[None])[0][0])
                     for e in E], axis=1)
    assert np.max(np.abs(J[0] - J_fd)) < 1e-9
    # F(x + v t) has second derivative (J v)' = -gamma at zero acceleration
    rate = d(lambda t: kern.system((x + t * v)[None], q[None])[1][0] @ v)
    assert np.max(np.abs(kern.gamma(x[None], v[None])[0] + rate)) < 1e-9


def test_kernel_paths_agree_single_and_batched_compiled_and_numpy():
    model = every_joint_model()
    kern = Kernel(model, model.layout())
    rng = np.random.default_rng(8)
    x = rng.normal(size=(3, model.n_x))
    q = rng.normal(size=(3, model.n_q))
    v = rng.normal(size=(3, model.n_x))
    kern.compiled = False  # the NumPy evaluator, as without numba
    F, J = kern.system(x, q)
    g = kern.gamma(x, v)
    for compiled in sorted({False, rows_numba.NUMBA}):
        kern.compiled = compiled
        Fc, Jc = kern.system(x, q)
        assert np.allclose(Fc, F, rtol=0, atol=1e-15) and np.allclose(Jc, J, rtol=0, atol=1e-15)
        assert np.allclose(kern.gamma(x, v), g, rtol=0, atol=1e-14)
        for k in range(3):
            F1, J1 = kern.system(x[k], q[k])
            assert np.allclose(F1, F[k], rtol=0, atol=1e-15)
            assert np.allclose(J1, J[k], rtol=0, atol=1e-15)
            assert np.allclose(kern.gamma(x[k], v[k]), g[k], rtol=0, atol=1e-14)


@pytest.mark.parametrize("compiled", sorted({False, rows_numba.NUMBA}))
def test_kernel_solves_and_signs_equal_dense_ones(compiled):
    model = every_joint_model()
    lay = model.layout()
    kern = Kernel(model, lay)
    kern.compiled = compiled
    assert kern.square
    rng = np.random.default_rng(6)
    x = rng.normal(size=(50, model.n_x))
    _, J = kern.system(x, np.zeros((50, model.n_q)))
    rhs = rng.normal(size=(50, kern.n_eq, 3))
    fac = kern.factor(J)
    assert np.allclose(kern.apply(J, fac, rhs), np.linalg.solve(J, rhs), rtol=1e-9, atol=1e-9)
    assert np.array_equal(fac[2], branch_sign(model, x, lay))
    for k in range(5):
        fac = kern.factor(J[k])
        assert fac[2] == branch_sign(model, x[k], lay)
        assert np.allclose(kern.apply(J[k], fac, rhs[k]), np.linalg.solve(J[k], rhs[k]))


# ---------------------------------------------------------------- tables and plots
def test_dataframe_columns_carry_units():
    sw = sweep(four_bar(), values=np.linspace(0, 1, 4), speed=2.0)
    df = sw.to_dataframe()
    for col in ("phi_rad", "phi_deg", "phi_dot_rad_s", "theta_coupler_rad", "omega_rocker_rad_s",
                "alpha_rocker_rad_s2", "x_coupler_C_m", "vy_coupler_C_m_s", "ax_crank_com_m_s2",
                "dx_coupler_C_dphi_m", "dtheta_rocker_dphi_rad"):
        assert col in df.columns, col
    assert len(df) == 4
    assert np.allclose(df["phi_deg"], np.rad2deg(sw.values))
    r, v, _ = sw.point("coupler", "C")
    assert np.allclose(df["vy_coupler_C_m_s"], v[:, 1])
    assert np.allclose(df["dx_coupler_C_dphi_m"] * 2.0, v[:, 0])


def test_csv_and_png_are_written(tmp_path):
    from mechdyn.results.plot import plot
    from mechdyn.results.table import read_csv, unit_of_column, write_csv

    sw = sweep(four_bar(), values=np.linspace(0, 2 * np.pi, 37))
    path = write_csv(sw, tmp_path / "out" / "fb.csv")
    text = path.read_text()
    assert text.startswith("# mechdyn KinematicSweep of 'four-bar'")
    assert "vx_coupler_C_m_s [m/s]" in text
    df = read_csv(path)
    assert list(df.columns) == list(sw.to_dataframe().columns)
    assert np.allclose(df["x_coupler_C_m"], sw.point("coupler", "C")[0][:, 0], rtol=1e-11)
    assert unit_of_column("ax_rod_B_m_s2") == "m/s^2" and unit_of_column("phi_deg") == "deg"
    png = plot(sw, tmp_path / "fb.png", points=["coupler.C", ("rocker", "C")])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ModelError, match="valid point names"):
        plot(sw, tmp_path / "x.png", points=["coupler.Z"])


@pytest.mark.parametrize("s", [1, 2, 3, 4, 5])
def test_lu_factors_solve_and_give_determinant_signs(s):
    from mechdyn.kernels.rows_sweep import lu_batch, lu_solve_batch

    rng = np.random.default_rng(s)
    A = rng.normal(size=(200, s, s))
    A[0] = 0.0  # exactly singular: sign 0, NaN solutions instead of an exception
    lu, piv, sign = A.copy(), np.empty((200, s), dtype=np.intp), np.empty(200)
    lu_batch(lu, piv, sign)
    y = rng.normal(size=(200, s, 2))
    x = y.copy()
    lu_solve_batch(lu, piv, x)
    assert np.allclose(x[1:], np.linalg.solve(A[1:], y[1:]), rtol=1e-9, atol=1e-9)
    assert np.array_equal(sign, np.sign(np.linalg.det(A))) and np.isnan(x[0]).all()


def test_x_start_chooses_the_branch():
    # start from the mirror image of the open four-bar: the crossed branch is followed
    model = four_bar().compile()
    open_ = sweep(model, values=np.linspace(1.0, 2.0, 11))
    crossed_model = four_bar().compile()
    x = np.array(open_.x[0])
    # reflect the coupler-rocker joint C about line B-D: rebuild poses of coupler and rocker
    B = np.array([A_ * np.cos(1.0), A_ * np.sin(1.0)])
    D = np.array([D_, 0.0])
    C = B + B_ * np.array([np.cos(x[5]), np.sin(x[5])])
    u = (D - B) / np.linalg.norm(D - B)
    Cm = B + 2 * np.dot(C - B, u) * u - (C - B)
    x[5] = np.arctan2(*(Cm - B)[::-1])
    x[8] = np.arctan2(*(Cm - D)[::-1])
    crossed = sweep(crossed_model, values=np.linspace(1.0, 2.0, 11), x_start=x)
    assert crossed.ok
    assert np.min(np.abs(crossed.x[:, 8] - open_.x[:, 8])) > 0.1
    assert np.max(np.abs(residual(crossed_model, crossed.x))) < 1e-12
