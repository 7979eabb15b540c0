"""The presses of the source documents, kinetostatically.

* Triangular-toggle six-bar press (Wang & Wei, J. Vibration and Shock 2019 no. 11;
  METHOD.md section 3), bundled ``toggle_press.toml`` (dimensions stated there:
  crank 60 mm, stroke 123.4 mm, BDC at phi = 139.3 deg): with the gravity of every
  link and a pulse working load while the punch is within 3 mm of BDC, the
  driving torque and the forces in B, C and F jump while the punch acts -- the
  phenomenon the paper reports (its dimensions are unknown, so not its numbers).
* Clutchless press (METHOD.md section 1) in its working structure: the rocker
  locked onto the slider makes a slider-crank.
"""

import warnings

import numpy as np
import pytest

from mechdyn import examples
from mechdyn.kinetostatics.inverse import KinetostaticsWarning, dead_centres, kinetostatics
from mechdyn.mechanism import Body, Lock, Mechanism
from mechdyn.mechanism.process import punch_load
from mechdyn.model.constraints import point_position, point_velocity

OMEGA = 40 * 2 * np.pi / 60  # 40 strokes per minute
PUNCH = 7500.0  # N, the working load of toggle_press.toml


def _press(with_load: bool) -> Mechanism:
    mech = examples.load("toggle_press")
    if not with_load:
        mech.loads = [ld for ld in mech.loads if ld.name != "working_load"]
    return mech


@pytest.fixture(scope="module")
def press_runs():
    values = np.deg2rad(np.linspace(0.0, 360.0, 1441))  # 0.25 deg
    loaded = kinetostatics(_press(True), over="phi", speed=OMEGA, values=values)
    idle = kinetostatics(_press(False), over="phi", speed=OMEGA, values=values)
    return values, loaded, idle


def test_toggle_press_bottom_dead_centre_is_where_the_model_file_says():
    dc = dead_centres(_press(False).compile(), "slider", (0.0, 0.0))
    assert np.rad2deg(dc["min"][0]) == pytest.approx(139.3, abs=0.05)
    assert dc["min"][1] == pytest.approx(-0.2371, abs=1e-4)
    assert dc["max"][1] - dc["min"][1] == pytest.approx(0.1234, abs=1e-4)


def test_punch_makes_driving_torque_and_pin_forces_jump(press_runs):
    values, loaded, idle = press_runs
    deg = np.rad2deg(values)
    acting = (deg >= 122.0) & (deg <= 139.3)
    before = np.flatnonzero(deg < 122.0)[-1]
    first = np.flatnonzero(acting)[0]
    # outside the pulse the two runs are identical
    np.testing.assert_allclose(loaded.driving["phi"][~acting], idle.driving["phi"][~acting],
                               atol=1e-9)
    # jump of the driving torque at the pulse's onset: the punch's virtual work,
    # delta tau = -F dy_F/dphi (the load points up, +y)
    model = loaded.model
    vy = point_velocity(model, loaded.x, loaded.xdot, "slider", (0.0, 0.0))[:, 1] / OMEGA
    jump = loaded.driving["phi"] - idle.driving["phi"]
    np.testing.assert_allclose(jump[acting], -PUNCH * vy[acting], rtol=1e-9, atol=1e-9)
    assert loaded.driving["phi"][first] - loaded.driving["phi"][before] > 100.0  # N m
    # the resultant forces in B, C and F jump several-fold while the punch acts
    for j in ("B", "C", "F"):
        f_on = loaded.force_magnitude(j)[first]
        f_off = idle.force_magnitude(j)[first]
        assert f_on > 5 * f_off, j
        assert f_on > 4000.0, j
    # the largest pin force of the cycle is in C, during the pulse
    peaks = loaded.peaks()["joints"]
    assert max(peaks, key=lambda j: peaks[j]["peak"]) in ("C", "D")
    assert 122.0 <= np.rad2deg(peaks["C"]["peak_at"]) <= 139.3
    # near BDC the toggle carries the load with almost no crank torque
    k_bdc = np.argmin(np.abs(deg - 139.0))
    assert abs(jump[k_bdc]) < 0.02 * abs(jump[first])


def test_position_window_punch_acts_on_the_same_crank_angles(press_runs):
    """mechanism.process.punch_load: 3 mm before BDC, only on the way down."""
    values, loaded, idle = press_runs
    model = idle.model
    dc = dead_centres(model, "slider", (0.0, 0.0))
    mech = _press(False)
    mech.add(punch_load("punch", "slider", (0.0, 0.0), PUNCH, end=dc["min"][1], travel=0.003))
    res = kinetostatics(mech, over="phi", speed=OMEGA, values=values)
    acting = np.abs(res.driving["phi"] - idle.driving["phi"]) > 1e-9
    deg = np.rad2deg(values[acting])
    assert deg[0] == pytest.approx(122.0, abs=0.25)
    assert deg[-1] == pytest.approx(139.3, abs=0.25)
    y = point_position(model, res.x, "slider", (0.0, 0.0))[:, 1]
    assert np.all(y[acting] <= dc["min"][1] + 0.003 + 1e-12)


def test_press_bed_carries_the_punch_reaction(press_runs):
    values, loaded, idle = press_runs
    bed = kinetostatics(_press(True), over="phi", speed=OMEGA, values=values,
                        reacting_loads=["working_load"])
    # with the workpiece on the bed, the frame sees the same shaking force as idle
    np.testing.assert_allclose(bed.frame_force, idle.frame_force, atol=1e-8)
    # without, the punch force shows up in the foundation load
    assert np.max(loaded.frame_force[:, 1]) > np.max(idle.frame_force[:, 1]) + 0.9 * PUNCH


# ------------------------------------------------------------------ clutchless press
def _clutchless_working() -> Mechanism:
    """The bundled clutchless press with the rocker locked in line with the ram (psi = 0)."""
    mech = examples.load("clutchless_press")
    lk = mech.joints["rocker_lock"]
    mech.joints["rocker_lock"] = Lock(lk.name, lk.parent, lk.child, engaged=False,
                                      offset=(0.0, 0.0, 0.0))
    return mech


def _slider_crank_equivalent(mech: Mechanism) -> Mechanism:
    """The same machine with the locked rocker merged into the ram (one body)."""
    ro, sl = mech.bodies["rocker"], mech.bodies["slider"]
    m = ro.mass + sl.mass
    com = ((ro.mass * np.asarray(ro.com) + sl.mass * np.asarray(sl.com)) / m)
    inertia = (ro.inertia + ro.mass * np.sum((np.asarray(ro.com) - com) ** 2)
               + sl.inertia + sl.mass * np.sum((np.asarray(sl.com) - com) ** 2))
    out = Mechanism("merged", gravity=mech.gravity)
    out.add_ground(dict(mech.ground.points))
    out.add(mech.bodies["crank"])
    out.add(mech.bodies["rod"])
    out.add(Body("ram", mass=m, inertia=inertia, com=tuple(com),
                 points={"B": ro.points["B"]}, pose=(sl.pose[0], 0.0, 0.0)))
    out.add_revolute("O", "ground", "crank", "O", "O")
    out.add_revolute("A", "crank", "rod", "A", (0.0, 0.0))
    out.add_revolute("B", "rod", "ram", "B", "B")
    out.add_prismatic("guide", "ground", "ram", "O", (1.0, 0.0), (0.0, 0.0))
    out.add_coordinate("phi", "angle", body="crank")
    return out


def test_clutchless_press_working_mode_is_a_slider_crank():
    mech = _clutchless_working()
    values = np.deg2rad(np.linspace(0.0, 360.0, 361))
    with pytest.warns(KinetostaticsWarning, match="not unique"):
        res = kinetostatics(mech, over="phi", speed=43.5, values=values,
                            mode={"rocker_lock"})
    # phi driven, psi follows the lock (rocker in line with the ram)
    assert res.driven == ("phi",)
    np.testing.assert_allclose(res.q[:, 1], 0.0, atol=1e-12)
    # the pin C and the lock join the same two bodies: redundant, force split not unique
    assert res.status == "redundant"
    assert set(res.redundant_joints) == {"C", "rocker_lock"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinetostaticsWarning)
        ref = kinetostatics(_slider_crank_equivalent(mech), over="phi", speed=43.5,
                            values=values)
    scale = np.max(np.abs(ref.driving["phi"]))
    np.testing.assert_allclose(res.driving["phi"], ref.driving["phi"], atol=1e-9 * scale)
    fscale = np.max(np.abs(ref.reactions["B"]))
    for j in ("O", "A", "guide"):
        np.testing.assert_allclose(res.reactions[j], ref.reactions[j], atol=1e-9 * fscale)
    np.testing.assert_allclose(res.moments["guide"], ref.moments["guide"], atol=1e-9 * fscale)
    np.testing.assert_allclose(res.frame_force, ref.frame_force, atol=1e-9 * fscale)


def test_clutchless_press_idle_mode_holds_the_rocker():
    """Two DOF: driving phi alone holds psi at its initial value with a holding torque."""
    mech = examples.load("clutchless_press")
    values = np.deg2rad(np.linspace(-64.1, -64.1 + 90.0, 31))
    res = kinetostatics(mech, over="phi", speed=43.5, values=values)
    assert res.driven == ("phi", "psi")
    assert any("held fixed" in w for w in res.warnings)
    np.testing.assert_allclose(res.q[:, 1], np.deg2rad(-46.34), atol=1e-12)
    np.testing.assert_allclose(res.qdot[:, 1], 0.0, atol=1e-12)
    assert np.all(np.isfinite(res.driving["psi"]))
    assert res.stats["power_balance_rel"] < 1e-9
