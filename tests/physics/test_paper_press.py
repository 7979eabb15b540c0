"""The source paper's press as its equations are written (clutchless_press_lumped):
masses lumped at A, B, C, the 4A80B4U3 through 3.4 : 1, no spring on the ram
(docs/paper-press.md, docs/references.md [1]).

The paper's kinetic energy (its eq. 21-24), generalized forces (eq. 27-29) and the
motor's Kloss characteristic are written out here independently of mechdyn."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

import mechdyn
from mechdyn.dynamics.lagrange import equations_of_motion

PAGE = Path(__file__).resolve().parents[2] / "docs" / "paper-press.md"

# the paper's data
L1, L2, L3 = 0.015, 0.040, 0.030
M1, M2, M3, M4 = 4.6, 20.0, 18.0, 100.0
J1, J2, J3 = 0.034, 0.036, 0.0441
G = 9.81                                    # along -x (the ram axis)
PHI0, PSI0, OMEGA0 = math.radians(-64.1), math.radians(-46.34), 43.5
T_END, N = 0.05, 40
# the drive: 4A80B4U3 (1.5 kW, 1500 rpm, slip 5.8 %, M_k/M_n = 2.2), Kloss, i = 3.4
P_N, W0, S_N, LAM, RATIO = 1500.0, 1500 * math.pi / 30, 0.058, 2.2, 3.4


def crank_torque(omega):
    """Kloss's formula M = 2 M_k / (s/s_k + s_k/s) at the motor, times the ratio."""
    m_n = P_N / (W0 * (1 - S_N))
    s_k = S_N * (LAM + math.sqrt(LAM**2 - 1))
    s = (W0 - RATIO * np.asarray(omega)) / W0
    return RATIO * 2 * LAM * m_n * s * s_k / (s**2 + s_k**2)


def points(phi, psi):
    """r_A, r_B, r_C and the rod angle (paper eq. 1-4), the branch x_B > x_A; complex-safe."""
    xa, ya = L1 * np.cos(phi), L1 * np.sin(phi)
    yb = L3 * np.sin(psi)
    xb = xa + np.sqrt(L2**2 - (yb - ya) ** 2)
    xc = xb - L3 * np.cos(psi)
    return (xa, ya), (xb, yb), (xc, 0 * xc), np.arctan((yb - ya) / (xb - xa))


def analogs(phi, psi, h=1e-30):
    """Velocity analogs d/dphi, d/dpsi of A, B, C and of the three link angles, by the
    complex step (exact to round-off): rows A, B, C (2-vectors), omega1..3 (scalars)."""
    out = []
    for dq in ((h, 0), (0, h)):
        a, b, c, th2 = points(phi + 1j * dq[0], psi + 1j * dq[1])
        v = [np.imag(np.array(p)) / h for p in (a, b, c)]
        w = [dq[0] / h, float(np.imag(th2)) / h, dq[1] / h]
        out.append((v, w))
    return out


def paper_mass_matrix(phi, psi):
    """A_ij of T = 1/2 q'^T A q' with T1 = m1/2 v_A^2 + J1/2 w1^2, T2 = m2/2 v_B^2 +
    J2/2 w2^2, T3 = m3/2 v_C^2 + J3/2 w3^2, T4 = m4/2 v_C^2 (paper eq. 21-24)."""
    masses, inertias = (M1, M2, M3 + M4), (J1, J2, J3)
    by_q = analogs(phi, psi)                # [(points' analogs, angles' analogs)] per q
    A = np.zeros((2, 2))
    for i, (v_i, w_i) in enumerate(by_q):
        for j, (v_j, w_j) in enumerate(by_q):
            A[i, j] = (sum(m * v_i[k] @ v_j[k] for k, m in enumerate(masses))
                       + sum(J * w_i[k] * w_j[k] for k, J in enumerate(inertias)))
    return A


def paper_forces(phi, psi, omega):
    """Q_phi, Q_psi of eq. 28-29: the weights at A, B, C and the drive on phi."""
    weights = [np.array([-m * G, 0.0]) for m in (M1, M2, M3 + M4)]
    q = [sum(w @ v[k] for k, w in enumerate(weights)) for v, _ in analogs(phi, psi)]
    return np.array([q[0] + crank_torque(omega), q[1]])


@pytest.fixture(scope="module")
def mech():
    return mechdyn.examples.load("clutchless_press_lumped")


@pytest.fixture(scope="module")
def converged(mech):
    run = mechdyn.simulate(mech, T_END, integrator="dop853", rtol=1e-10, progress=False,
                           t_eval=np.linspace(0, T_END, 401))
    assert run.success, run.message
    return run


def wilson(mech, steps, **kw):
    run = mechdyn.simulate(mech, T_END, integrator="wilson", steps=steps, progress=False, **kw)
    assert run.success, run.message
    return run


def test_the_lumped_variant_loads_with_the_paper_data(mech):
    init = mech.extras["initial"]
    assert np.isclose(init["q"]["phi"], PHI0) and np.isclose(init["q"]["psi"], PSI0)
    assert init["qdot"] == {"phi": OMEGA0, "psi": 0.0}
    assert [mech.bodies[b].mass for b in ("crank", "rod", "rocker", "slider")] == [M1, M2, M3, M4]
    assert not mech.loads                   # no spring on the ram: the paper's Q has none
    gear = mech.drives[0].torque
    assert gear.ratio == RATIO and gear.efficiency == 1.0
    assert gear.extra_inertia() == 0.0      # eq. 21 has no rotor term


def test_mass_matrix_and_forces_are_the_papers_lumped_ones(mech):
    eqs = equations_of_motion(mech)
    for phi, psi in ((PHI0, PSI0), (0.3, -1.0), (0.9, -1.15)):
        terms = eqs.terms(0.0, [phi, psi], [OMEGA0, 0.0])
        A = paper_mass_matrix(phi, psi)
        np.testing.assert_allclose(terms.A, A, rtol=0, atol=1e-10 * np.abs(A).max())
        np.testing.assert_allclose(terms.Q, paper_forces(phi, psi, OMEGA0), rtol=1e-10)
    # the kinetic energy at the initial state
    qd = np.array([OMEGA0, 0.0])
    T_paper = 0.5 * qd @ paper_mass_matrix(PHI0, PSI0) @ qd
    assert abs(eqs.energy(0.0, [PHI0, PSI0], qd)["kinetic"] - T_paper) < 1e-10 * T_paper
    assert abs(crank_torque(OMEGA0) - 34.6989) < 1e-4   # 34.5 N m of the paper variant, nearly


def test_wilson_40_steps_agrees_with_the_converged_run(mech, converged):
    runs = {n: wilson(mech, n) for n in (40, 80)}
    err = {n: r.q[-1] - converged.q[-1] for n, r in runs.items()}
    # N = 40: phi within 4e-4 rad (0.022 deg), psi within 8e-4 rad, omega1 within 0.07 rad/s
    assert abs(err[40][0]) < 4e-4 and abs(err[40][1]) < 8e-4
    assert abs(runs[40].qdot[-1, 0] - converged.qdot[-1, 0]) < 0.07
    assert 3.5 < err[40][0] / err[80][0] < 4.5                 # second order
    # the paper's own formulation (finite-difference analogs, d = 0.1 deg) changes
    # the 40-step result by less than 1e-5 rad
    paper = wilson(mech, N, formulation="analogs")
    assert np.max(np.abs(paper.q[-1] - runs[40].q[-1])) < 1e-5


def test_converged_run_is_converged(mech, converged):
    rk = mechdyn.simulate(mech, T_END, integrator="rk4", steps=320, progress=False)
    assert np.max(np.abs(rk.q[-1] - converged.q[-1])) < 1e-9


def test_rk4_error_falls_sixteenfold_per_halving(mech, converged):
    errs = [mechdyn.simulate(mech, T_END, integrator="rk4", steps=n, progress=False).q[-1, 0]
            - converged.q[-1, 0] for n in (40, 80, 160)]
    ratios = [errs[0] / errs[1], errs[1] / errs[2]]
    assert all(14 < r < 18 for r in ratios), ratios


def test_energy_balance_with_the_motor_power(converged):
    """T + U - T0 - U0 = integral of the motor's power, T and U from the lumped points
    of the table, the power from Kloss's formula written above."""
    df = converged.to_dataframe(points=True)
    t, omega = df["t_s"].to_numpy(), df["phi_dot_rad_s"].to_numpy()
    v2 = {p: df[f"vx_{p}_m_s"] ** 2 + df[f"vy_{p}_m_s"] ** 2
          for p in ("crank_A", "rod_B", "slider_com")}
    T = 0.5 * (M1 * v2["crank_A"] + M2 * v2["rod_B"] + (M3 + M4) * v2["slider_com"]
               + J1 * omega**2 + J2 * df["omega_rod_rad_s"] ** 2
               + J3 * df["psi_dot_rad_s"] ** 2)
    U = G * (M1 * df["x_crank_A_m"] + M2 * df["x_rod_B_m"] + (M3 + M4) * df["x_slider_m"])
    from scipy.integrate import cumulative_simpson
    work = cumulative_simpson(crank_torque(omega) * omega, x=t, initial=0.0)
    np.testing.assert_allclose(T, df["T_J"], rtol=1e-10)
    np.testing.assert_allclose(U - U.iloc[0], df["U_J"] - df["U_J"].iloc[0], atol=1e-10)
    np.testing.assert_allclose((T + U) - (T + U).iloc[0], work, atol=1e-6)
    assert np.ptp(df["E_balance_J"]) < 1e-6


def test_without_a_spring_the_ram_falls_into_a_singular_position(mech):
    run = mechdyn.simulate(mech, 0.06, integrator="dop853", rtol=1e-8, progress=False)
    assert run.status == "singular-position"
    assert abs(run.t[-1] - 0.05682) < 2e-5
    phi, psi = np.rad2deg(run.q[-1])
    assert abs(phi - 54.98) < 0.01 and abs(psi + 67.50) < 0.01
    assert abs(run.qdot[-1, 0] - 7.13) < 0.01
    x_c = run.to_dataframe()["x_slider_m"].iloc[-1]
    assert abs(x_c + 2.87e-3) < 1e-5
    a, b, _, _ = points(*run.q[-1])
    assert abs(b[0] - a[0]) < 1e-5           # the rod A-B normal to the ram axis


def _rows(n_cells):
    """Rows of n_cells cells of the tables of docs/paper-press.md whose third cell is a
    number (the results table has 6 cells, the one-change-at-a-time table 7)."""
    for line in PAGE.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == n_cells and re.fullmatch(r"-?\d+\.\d+", cells[3]):
            yield cells


def _table():
    """The results table: (variant, run) -> phi, psi (deg), omega1, omega3 (rad/s)."""
    return {(c[0].strip("`"), c[1]): [float(v) for v in c[2:]] for c in _rows(6)}


RUNS = {"Wilson, N = 40": dict(integrator="wilson", steps=N),
        "RK4, N = 40": dict(integrator="rk4", steps=N),
        "DOP853, rtol 1e-10": dict(integrator="dop853", rtol=1e-10)}


def test_the_numbers_of_the_page_are_the_code_s():
    rows = _table()
    assert len(rows) == 6
    for name in ("clutchless_press_lumped", "clutchless_press_paper"):
        mech = mechdyn.examples.load(name)
        for label, options in RUNS.items():
            run = mechdyn.simulate(mech, T_END, progress=False, **options)
            got = [*np.rad2deg(run.q[-1]), *run.qdot[-1]]
            np.testing.assert_allclose(got, rows[name, label], rtol=0, atol=6e-5)


def _variant(masses, drive, ram):
    """clutchless_press with the lumped or mid-length bodies, the motor of the lumped
    file or 34.5 N m, the ram free or on the 1e7 N/m spring of clutchless_press_paper."""
    from mechdyn.examples.paper_case import press_idle
    lumped = mechdyn.examples.load("clutchless_press_lumped")
    mech = mechdyn.examples.load("clutchless_press")
    if masses == "lumped":
        mech.bodies.update(lumped.bodies)
    press_idle(mech, support_stiffness=1e7 if ram == "spring" else None)
    if drive == "motor":
        mech.drives[:] = lumped.drives
    return mech


def test_one_change_at_a_time():
    rows = list(_rows(7))
    assert len(rows) == 8
    for masses, drive, ram, *numbers, end in rows:
        run = mechdyn.simulate(_variant(masses, drive, ram), T_END, integrator="dop853",
                               rtol=1e-10, progress=False)
        got = [*np.rad2deg(run.q[-1]), run.qdot[-1, 0]]
        np.testing.assert_allclose(got, [float(v) for v in numbers], rtol=0, atol=6e-3)
        if end == "0.05 s":
            assert run.success, run.message
        else:
            assert run.status == "singular-position"
            assert abs(run.t[-1] - float(end.split()[2])) < 6e-5


def test_the_prose_numbers(converged):
    assert abs(crank_torque(OMEGA0) / RATIO - 10.21) < 0.005
    assert abs(crank_torque(np.linspace(0, OMEGA0, 4351)).max() - 75.8) < 0.05
    assert abs(crank_torque(43.0) - crank_torque(44.0) - 11.4) < 0.05
    df = converged.to_dataframe()
    assert abs(df["x_slider_m"].iloc[-1] - 6.6e-3) < 5e-5
    assert abs(df["phi_dot_rad_s"].max() - 47.0) < 0.05
    assert abs(2 * math.pi * math.sqrt(M4 / 1e7) - 0.020) < 5e-4
