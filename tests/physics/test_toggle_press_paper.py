"""The identified toggle press (``toggle_press_paper.toml``) against the paper's figures.

Wang Zhongshuang, Wei Jing, J. Vibration and Shock 2019 no. 11 (METHOD.md section 3): idle
driving torque max 51.9302 N m at 284 deg, min -59.7138 N m at 60 deg, turning points at
about 1, 60, 284 and 341 deg; under the pulse at 139 deg the torque falls by 45.5442 % to
9.2786 N m and |F_B|, |F_C|, |F_F| rise to 1045.7381, 8022.6847, 7866.6739 N (+352.7272,
+1023.4243, +4753.0297 %).  The tolerances are the residuals stated in the model file's
header; the numbers compared are the paper's, not this code's.
"""

import numpy as np
import pytest

import mechdyn as md
from mechdyn import examples
from mechdyn.kinematics import solve_position
from mechdyn.modelfile import loads

STEP = 0.5  # deg; 139 deg is a sample
PHI = np.deg2rad(np.arange(0.0, 360.0, STEP))
K139 = int(round(139.0 / STEP))


def _speed(mech):
    return float(mech.extras["initial"]["qdot"]["phi"])


@pytest.fixture(scope="module")
def runs():
    text = examples.path("toggle_press_paper").read_text(encoding="utf-8")
    loaded = examples.load("toggle_press_paper")
    idle = loads(text.split("[[loads]]")[0], name="toggle_press_paper (idle)")
    w = _speed(loaded)
    return {name: md.kinetostatics(m, over="phi", speed=w, values=PHI).to_dataframe()
            for name, m in (("idle", idle), ("load", loaded))}


def _extremum(tau, k):
    """Value and angle (deg) of the parabola through samples k-1, k, k+1 (periodic)."""
    n = len(tau)
    y0, y1, y2 = tau[(k - 1) % n], tau[k], tau[(k + 1) % n]
    h = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    return y1 - 0.25 * (y0 - y2) * h, ((k + h) * STEP) % 360.0


def _turning_points(tau):
    d = np.diff(np.append(tau, tau[0]))
    return [_extremum(tau, (k + 1) % len(tau))
            for k in range(len(d)) if np.sign(d[k]) != np.sign(d[(k + 1) % len(d)])]


def _angle_error(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


# The residuals stated in the model file's header (identified / paper - 1, in %, and the
# angle differences in deg), as upper bounds.  The idle curve is fitted (extremes within
# 1 %, four turning points); the figures at 139 deg are not (docs/toggle-press-paper.md).
STATED = {"M_max": 1.0, "M_max_deg": 2.5, "M_min": 1.0, "M_min_deg": 7.0,
          "turn_1_deg": 11.5, "turn_4_deg": 2.0, "fall_Nm": 0.01,
          "F_B": 57.0, "F_C": 52.0, "F_F": 72.0}


def test_idle_torque_extremes_and_their_angles_within_the_stated_residuals(runs):
    tau = runs["idle"]["M_drive_phi_Nm"].to_numpy()
    top, at_top = _extremum(tau, int(np.argmax(tau)))
    low, at_low = _extremum(tau, int(np.argmin(tau)))
    assert abs(top / 51.9302 - 1.0) * 100 <= STATED["M_max"]
    assert abs(low / -59.7138 - 1.0) * 100 <= STATED["M_min"]
    assert _angle_error(at_top, 284.0) <= STATED["M_max_deg"]
    assert _angle_error(at_low, 60.0) <= STATED["M_min_deg"]
    assert top > 0 > low


def test_idle_torque_turning_points_near_the_papers_within_the_stated_residuals(runs):
    tau = runs["idle"]["M_drive_phi_Nm"].to_numpy()
    tps = _turning_points(tau)
    assert len(tps) == 4  # the paper's four
    assert min(_angle_error(a, 1.0) for _, a in tps) <= STATED["turn_1_deg"]
    assert min(_angle_error(a, 341.0) for _, a in tps) <= STATED["turn_4_deg"]


def test_pulse_at_139_deg_makes_the_torque_fall_by_the_papers_amount(runs):
    """The paper: 9.2786 N m after a fall of 45.5442 %, i.e. by 7.7602 N m.  The fall is
    matched; the level is not (the idle torque at 139 deg is -12.98 N m, not 17.04)."""
    idle = runs["idle"].iloc[K139]
    load = runs["load"].iloc[K139]
    fall = idle["M_drive_phi_Nm"] - load["M_drive_phi_Nm"]
    assert fall == pytest.approx(9.2786 / (1 - 0.455442) - 9.2786, abs=STATED["fall_Nm"])
    # outside the pulse the two runs are the same machine
    far = np.abs(np.rad2deg(PHI) - 139.0) > 2.0
    assert np.allclose(runs["idle"]["M_drive_phi_Nm"][far], runs["load"]["M_drive_phi_Nm"][far],
                       rtol=0, atol=1e-9)


def test_pulse_pin_forces_rise_within_the_stated_residuals(runs):
    idle = runs["idle"].iloc[K139]
    load = runs["load"].iloc[K139]
    for joint, paper in (("B", 1045.7381), ("C", 8022.6847), ("F", 7866.6739)):
        assert abs(load[f"F_{joint}_N"] / paper - 1.0) * 100 <= STATED[f"F_{joint}"], joint
        assert load[f"F_{joint}_N"] > idle[f"F_{joint}_N"], joint


def test_pulse_torque_fall_is_the_virtual_work_of_the_load(runs):
    """Second formulation: the fall is F_r times the slide's rate dy_F/dphi (virtual work),
    from the slide's positions by central differences, not from the multipliers."""
    mech = examples.load("toggle_press_paper")
    text = examples.path("toggle_press_paper").read_text(encoding="utf-8")
    F_r = float(text.split('pulse = "')[1].split(" N")[0])
    model = mech.compile()
    k = model.body_index("slider")
    ys = []
    x = model.x0
    for deg in (139.0 - 0.01, 139.0 + 0.01):
        x = solve_position(model, [np.deg2rad(deg)], x)
        ys.append(x[3 * k + 1])
    rate = (ys[1] - ys[0]) / np.deg2rad(0.02)
    fall = runs["idle"].iloc[K139]["M_drive_phi_Nm"] - runs["load"].iloc[K139]["M_drive_phi_Nm"]
    assert rate < 0  # the punch moves down: before bottom dead centre
    assert fall == pytest.approx(-F_r * rate, rel=1e-4)


def test_idle_torque_is_the_power_balance_of_gravity_and_kinetic_energy(runs):
    """Independent check of the sweep: over a turn at constant speed the drive's work is
    zero (the machine returns to the same potential and kinetic energy)."""
    tau = runs["idle"]["M_drive_phi_Nm"].to_numpy()
    assert abs(np.mean(tau)) < 1e-6 * np.max(np.abs(tau))
