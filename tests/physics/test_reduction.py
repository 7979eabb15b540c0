"""The reduction method (lecture notes, METHOD.md §2) against independent oracles.

* slider-crank J_red(phi): the closed form J_O1 + m2 |v_c2/omega|^2 + J_c2 (omega_2/omega)^2
  + m3 (dx_B/dphi)^2 with the closed-form x_B(phi) and rod angle (lecture notes eq. 6.8),
  and the colleague's generalized mass matrix A(q) = B_c^T M B_c;
* dJ_red/dphi (exact, from the acceleration bias) against central differences of the
  closed form;
* M_red by equal power: gravity's reduced torque is -dU/dphi of the closed-form potential;
* link of reduction and reduced mass at a point: J = m_red l_OA^2 (eq. 7.11);
* the belt drive and the two-stage gear train of the lecture notes (eqs. 5.16, 6.9),
  through the transmission API of velocity ratios (mechdyn has no belt or gear-mesh
  joint, so that is the honest model);
* the reduced equation J phi'' + 1/2 J' phi'^2 = M against the full Lagrange
  simulation, against energy conservation and against the energy form.
"""

import math

import numpy as np
import pytest

from mechdyn import Mechanism
from mechdyn.errors import ModelError
from mechdyn.mechanism import Drive, TorqueSpeedCurve
from mechdyn.reduction.reduce import (
    Member,
    MemberLoad,
    ReducedMachine,
    energy_speed,
    mode_mechanism,
    reduce_model,
    run_reduced,
)

GEOM = dict(r=0.05, l=0.2, e=0.012, m1=2.0, J1=0.01, c1=0.02, m2=3.0, J2=0.02,
            c2=(0.08, 0.01), m3=5.0)


def slider_crank(r, l, e, m1, J1, c1, m2, J2, c2, m3, phi_s=0.5, gravity=(0.0, 0.0)):
    """Offset slider-crank: crank O-A (com c1 on OA), rod A-B (com c2 in its frame), slider
    on the line y = e; coordinate phi = crank angle."""
    m = Mechanism("offset slider-crank", gravity=gravity)
    xa, ya = r * math.cos(phi_s), r * math.sin(phi_s)
    xb = xa + math.sqrt(l * l - (e - ya) ** 2)
    beta = math.atan2(e - ya, xb - xa)
    m.add_body("crank", mass=m1, inertia=J1, com=(c1, 0.0), points={"A": (r, 0.0)},
               pose=(0, 0, phi_s))
    m.add_body("rod", mass=m2, inertia=J2, com=c2, points={"B": (l, 0.0)}, pose=(xa, ya, beta))
    m.add_body("slider", mass=m3, inertia=0.0, pose=(xb, e, 0.0))
    m.add_revolute("O", "ground", "crank")
    m.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    m.add_revolute("B", "rod", "slider", "B", (0.0, 0.0))
    m.add_prismatic("P", "ground", "slider", (0.0, e), (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("phi", kind="angle", body="crank")
    return m


def closed_form(phi, r, l, e, m1, J1, c1, m2, J2, c2, m3):
    """Closed-form kinematics of the offset slider-crank: (J_red, beta, dbeta, xB, dxB, rc2)."""
    phi = np.asarray(phi, float)
    beta = np.arcsin((e - r * np.sin(phi)) / l)  # rod angle, branch with x_B > x_A
    dbeta = -r * np.cos(phi) / (l * np.cos(beta))
    dA = np.stack([-r * np.sin(phi), r * np.cos(phi)], axis=-1)
    arm = np.stack([np.cos(beta) * c2[0] - np.sin(beta) * c2[1],
                    np.sin(beta) * c2[0] + np.cos(beta) * c2[1]], axis=-1)
    dc2 = dA + dbeta[:, None] * np.stack([-arm[:, 1], arm[:, 0]], axis=-1)
    xb = r * np.cos(phi) + l * np.cos(beta)
    dxb = -r * np.sin(phi) - l * np.sin(beta) * dbeta
    J = J1 + m1 * c1**2 + m2 * np.sum(dc2**2, axis=-1) + J2 * dbeta**2 + m3 * dxb**2
    rc2 = np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1) + arm
    return J, beta, dbeta, xb, dxb, rc2


@pytest.fixture(scope="module")
def model():
    return slider_crank(**GEOM).compile()


@pytest.fixture(scope="module")
def table(model):
    return reduce_model(model, steps=361)


def test_reduced_inertia_equals_closed_form_slider_crank(table):
    J, *_ = closed_form(table.phi, **GEOM)
    np.testing.assert_allclose(table.J_red, J, rtol=1e-12, atol=0)


def test_reduced_inertia_of_lecture_inline_slider_crank_equals_eq_6_8():
    # the lecture notes' example: in-line slider-crank, crank inertia J_O1 about O
    g = dict(GEOM, e=0.0, c1=0.0, c2=(0.07, 0.0))
    red = reduce_model(slider_crank(**g).compile(), steps=181)
    phi = red.phi
    lam = g["r"] / g["l"]
    beta = np.arcsin(-lam * np.sin(phi))
    w2 = -lam * np.cos(phi) / np.cos(beta)          # omega_2 / omega_1
    vB = -g["r"] * np.sin(phi - beta) / np.cos(beta)  # u_c3 / omega_1 (slider)
    vA = g["r"] * np.stack([-np.sin(phi), np.cos(phi)], -1)
    vC2 = vA + 0.07 * w2[:, None] * np.stack([-np.sin(beta), np.cos(beta)], -1)
    J68 = g["J1"] + g["m2"] * np.sum(vC2**2, -1) + g["J2"] * w2**2 + g["m3"] * vB**2
    np.testing.assert_allclose(red.J_red, J68, rtol=1e-12)


def test_reduced_inertia_equals_generalized_mass_matrix(model, table):
    lagrange = pytest.importorskip("mechdyn.dynamics.lagrange")
    from mechdyn.kinematics.analogs import velocity_analogs
    from mechdyn.kinematics.assembly import solve_position

    x = model.x0
    for phi, J in zip(table.phi[::10], table.J_red[::10], strict=True):
        x = solve_position(model, np.array([phi]), x)
        A = lagrange.mass_matrix(model, x, velocity_analogs(model, x))
        assert A.shape == (1, 1)
        assert abs(A[0, 0] - J) <= 1e-12 * J


def test_derivative_of_reduced_inertia_is_exact(table):
    h = 1e-5
    Jp, *_ = closed_form(table.phi + h, **GEOM)
    Jm, *_ = closed_form(table.phi - h, **GEOM)
    fd = (Jp - Jm) / (2 * h)
    scale = np.max(np.abs(fd))
    np.testing.assert_allclose(table.dJ_red_dphi, fd, rtol=0, atol=1e-8 * scale)
    # and it integrates back to J over the cycle (periodic)
    assert abs(np.trapezoid(table.dJ_red_dphi, table.phi)) < 1e-6 * scale


def test_reduced_torque_of_gravity_is_minus_potential_gradient():
    g = (0.0, -9.81)
    red = reduce_model(slider_crank(**GEOM, gravity=g).compile(), steps=73)

    def U(phi):  # closed-form potential of the crank and rod centres of mass
        _, _, _, _, _, rc2 = closed_form(phi, **GEOM)
        yc1 = GEOM["c1"] * np.sin(phi)
        return 9.81 * (GEOM["m1"] * yc1 + GEOM["m2"] * rc2[:, 1])  # slider height constant

    h = 1e-6
    dU = (U(red.phi + h) - U(red.phi - h)) / (2 * h)
    np.testing.assert_allclose(red.M_forces, -dU, rtol=0, atol=1e-7)
    np.testing.assert_allclose(red.M_red, red.M_forces)
    assert not np.any(red.M_drive)


def test_reduced_torque_by_equal_power_of_a_slider_force_and_a_drive():
    from mechdyn.mechanism import Force

    mech = slider_crank(**GEOM)
    mech.add(Force("press", "slider", (0.0, 0.0), 250.0, (-1.0, 0.0)))
    mech.add(Drive("motor", "phi", TorqueSpeedCurve((0.0, 100.0), (12.0, 2.0))))
    red = reduce_model(mech.compile(), steps=37, omega=30.0)
    *_, dxb, _ = closed_form(red.phi, **GEOM)
    np.testing.assert_allclose(red.M_forces, -250.0 * dxb, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(red.M_drive, 12.0 - 10.0 * 30.0 / 100.0)


def test_link_of_reduction_divides_by_its_angular_velocity_analog(table, model):
    rod = reduce_model(model, steps=361, link="rod")
    _, beta, dbeta, *_ = closed_form(table.phi, **GEOM)
    ok = np.abs(dbeta) > 0.05
    np.testing.assert_allclose(rod.ratio, dbeta, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(rod.J_red[ok], table.J_red[ok] / dbeta[ok] ** 2, rtol=1e-11)
    np.testing.assert_allclose(rod.link_angle, beta, atol=1e-12)
    # the rod's rate vanishes at phi = 90, 270 deg: infinite there, reported
    assert rod.status == "singular-position" and "vanishes" in rod.message
    # derivative with respect to the link angle, against differences along the table
    k = np.flatnonzero(ok[1:-1] & ok[:-2] & ok[2:])[10] + 1
    fd = (rod.J_red[k + 1] - rod.J_red[k - 1]) / (rod.link_angle[k + 1] - rod.link_angle[k - 1])
    assert rod.dJ_red_dphi[k] == pytest.approx(fd, rel=2e-3)
    crank = reduce_model(model, steps=361, link="crank")
    np.testing.assert_allclose(crank.J_red, table.J_red, rtol=1e-14)


def test_reduced_mass_at_crank_pin_is_j_over_l_squared(model, table):
    red = reduce_model(model, steps=361, point=("crank", "A"))
    np.testing.assert_allclose(red.m_red * GEOM["r"] ** 2, table.J_red, rtol=1e-13)
    np.testing.assert_allclose(red.v_ratio, GEOM["r"], rtol=1e-13)


def test_table_columns_carry_units(table):
    df = table.to_dataframe()
    for col in ("phi_deg", "J_red_kgm2", "dJ_red_dphi_kgm2", "M_red_Nm", "M_drive_Nm",
                "M_forces_Nm", "J_total_kgm2", "omega_rad_s"):
        assert col in df.columns
    assert df["phi_deg"].iloc[-1] == pytest.approx(360.0)
    with pytest.raises(ValueError):
        table.J_red[0] = 1.0  # records are immutable


def test_reduction_needs_one_degree_of_freedom():
    from mechdyn import examples

    press = examples.load("clutchless_press").compile()
    with pytest.raises(ModelError, match="one degree of freedom.*phi, psi"):
        reduce_model(press)


def test_press_working_mode_is_an_inline_slider_crank():
    """The clutchless press with its rocker locked in line with the ram (working mode) is
    an in-line slider-crank r = 15 mm, l = 40 mm carrying rocker + ram (18 + 100 kg)."""
    from mechdyn import examples

    mech = mode_mechanism(examples.load("clutchless_press"), engage=["rocker_lock"],
                          offsets={"rocker_lock": (0.0, 0.0, 0.0)}, drop=["psi"])
    red = reduce_model(mech.compile(), steps=73)
    g = dict(r=0.015, l=0.040, e=0.0, m1=4.6, J1=0.034 - 4.6 * 0.0075**2, c1=0.0075,
             m2=20.0, J2=0.036, c2=(0.020, 0.0), m3=118.0)
    J, _, dbeta, *_ = closed_form(red.phi, **g)
    # the locked rocker translates with the ram; its centroidal inertia does not count
    np.testing.assert_allclose(red.J_red, J, rtol=1e-12)


# ------------------------------------------------------------------ transmissions
def test_belt_drive_angular_acceleration_equals_lecture_eq_5_16():
    J1, J2, r1, r2, P, T1, T2 = 0.02, 0.05, 0.05, 0.12, 30.0, 4.0, 6.0
    g = 9.81
    belt = ReducedMachine.from_transmission(
        [Member("pulley 1", J1, 1.0), Member("pulley 2", J2, r1 / r2),
         Member("belt", P / g, r1, kind="translation")],
        [MemberLoad("T1", T1, 1.0), MemberLoad("T2", -T2, r1 / r2)])
    eps = (T1 - T2 * r1 / r2) / (J1 + J2 * r1**2 / r2**2 + (P / g) * r1**2)
    for phi, w in ((0.0, 0.0), (1.3, 20.0)):
        assert belt.acceleration(0.0, phi, w) == pytest.approx(eps, rel=1e-15)
    run = run_reduced(belt, 1.0, omega0=0.0, integrator="rk4", steps=10,
                      t_eval=np.linspace(0, 1, 5))
    np.testing.assert_allclose(run.phi, 0.5 * eps * run.t**2, rtol=1e-13, atol=1e-15)


def test_two_stage_gear_train_reduced_inertia_equals_lecture_eq_6_9():
    J1, J2, J3, J4 = 1.2e-4, 8.0e-4, 2.0e-4, 3.1e-3
    i12, i34 = 3.5, 4.2
    i14 = i12 * i34
    train = ReducedMachine.from_transmission(
        [Member("gear 1", J1, 1.0), Member("gear 2", J2, 1 / i12), Member("gear 3", J3, 1 / i12),
         Member("gear 4", J4, 1 / i14)])
    J, dJ = train.inertia(0.7)
    assert J == pytest.approx(J1 + (J2 + J3) / i12**2 + J4 / i14**2, rel=1e-15)
    assert dJ == 0.0


def test_transmission_with_variable_ratio_uses_its_derivative():
    m = Member("cam follower", 2.0, lambda p: 0.01 * np.sin(p), kind="translation")
    mach = ReducedMachine.from_transmission([m])
    J, dJ = mach.inertia(0.4)
    assert J == pytest.approx(2.0 * (0.01 * np.sin(0.4)) ** 2, rel=1e-14)
    assert dJ == pytest.approx(2.0 * 2 * 1e-4 * np.sin(0.4) * np.cos(0.4), rel=1e-8)


def test_member_validation_names_the_field():
    with pytest.raises(ModelError, match="kind must be"):
        Member("x", 1.0, kind="screw")
    with pytest.raises(ModelError, match="inertia must be >= 0"):
        Member("x", -1.0)


# ------------------------------------------------------------------ equation of motion
def test_reduced_run_conserves_energy_and_matches_energy_form(model):
    mach = ReducedMachine.from_model(model)
    run = run_reduced(mach, 0.15, phi0=0.3, omega0=20.0, rtol=1e-11, atol=1e-12,
                      t_eval=np.linspace(0, 0.15, 16))
    E = 0.5 * run.J * run.omega**2
    assert np.ptp(E) <= 1e-9 * E[0]
    w = energy_speed(mach, run.phi, phi0=0.3, omega0=20.0)
    np.testing.assert_allclose(w, run.omega, rtol=1e-9)


def test_energy_form_with_position_dependent_torque():
    # constant inertia, M = a cos(phi): omega^2 = omega0^2 + 2 a sin(phi) / J
    J, a, w0 = 0.3, 2.0, 5.0
    mach = ReducedMachine.constant(J, lambda t, p, w: a * np.cos(p))
    phi = np.linspace(-1.0, 3.0, 9)
    np.testing.assert_allclose(energy_speed(mach, phi, omega0=w0),
                               np.sqrt(w0**2 + 2 * a * np.sin(phi) / J), rtol=1e-10)


def test_reduced_equation_equals_full_lagrange_simulation():
    simulate = pytest.importorskip("mechdyn.simulate").simulate
    mech = slider_crank(**GEOM, gravity=(0.0, -9.81))
    mech.add(Drive("motor", "phi", TorqueSpeedCurve((0.0, 100.0), (5.0, 0.0))))
    model = mech.compile()
    te = np.linspace(0.0, 0.2, 21)
    full = simulate(model, 0.2, q0=[0.3], qdot0=[10.0], t_eval=te, rtol=1e-11, atol=1e-12)
    assert full.status == "success"
    red = run_reduced(ReducedMachine.from_model(model), 0.2, phi0=0.3, omega0=10.0, t_eval=te,
                      rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(red.phi, full.q[:, 0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(red.omega, full.qdot[:, 0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(red.epsilon, full.qddot[:, 0], rtol=0, atol=1e-4)


@pytest.mark.parametrize("integrator, options", [("rk4", {"dt": 2e-4}),
                                                 ("wilson", {"dt": 2e-4})])
def test_reduced_run_with_fixed_step_integrators(integrator, options):
    # a fast table machine; compared with the adaptive reference
    red = reduce_model(slider_crank(**GEOM, gravity=(0.0, -9.81)).compile(), steps=721)
    mach = red.machine()
    te = np.linspace(0.0, 0.1, 11)
    ref = run_reduced(mach, 0.1, phi0=0.0, omega0=20.0, t_eval=te, rtol=1e-12, atol=1e-12)
    run = run_reduced(mach, 0.1, phi0=0.0, omega0=20.0, t_eval=te, integrator=integrator,
                      **options)
    tol = 1e-8 if integrator == "rk4" else 1e-4
    np.testing.assert_allclose(run.omega, ref.omega, rtol=tol)


def test_full_simulation_includes_rotor_inertia_through_the_gear():
    simulate = pytest.importorskip("mechdyn.simulate").simulate
    from mechdyn.modelfile.drives import drive_from_table

    mech = slider_crank(**GEOM)
    mech.add(drive_from_table({"type": "induction_motor", "coordinate": "phi",
                               "catalogue": "4A80B4U3", "gear_ratio": 3.4}, "test"))
    model = mech.compile()
    te = np.linspace(0.0, 0.05, 6)
    full = simulate(model, 0.05, q0=[0.0], qdot0=[40.0], t_eval=te, rtol=1e-10)
    red = run_reduced(ReducedMachine.from_model(model), 0.05, phi0=0.0, omega0=40.0,
                      t_eval=te, rtol=1e-10)
    np.testing.assert_allclose(red.omega, full.qdot[:, 0], rtol=1e-6)
