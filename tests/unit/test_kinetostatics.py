"""Unit tests of mechdyn.kinetostatics.inverse and mechdyn.mechanism.process."""

import dataclasses
import doctest
from types import SimpleNamespace

import numpy as np
import pytest

import mechdyn as md
from mechdyn.errors import ModelError, UnitError
from mechdyn.kinetostatics import inverse as ks_module
from mechdyn.kinetostatics.inverse import (
    Kinetostatics,
    applied_forces,
    frame_mass_matrix,
    inertia_forces,
    kinetostatics,
)
from mechdyn.mechanism import Drive, Force, Spring, Table, TorqueSpeedCurve
from mechdyn.mechanism.process import StrokeWindow, position_load, punch_load, time_pulse_load
from mechdyn.model.forces import LoadContext, force_model
from mechdyn.units import registry

G = 9.81


def pendulum(com=(0.3, 0.0), parent_is_ground=True) -> md.Mechanism:
    m = md.Mechanism("pendulum", gravity=(0.0, -G))
    m.add_body("bob", mass=2.0, inertia=0.05, com=com, pose=(0.0, 0.0, -np.pi / 2))
    if parent_is_ground:
        m.add_revolute("O", "ground", "bob")
    else:
        m.add_revolute("O", "bob", "ground")
    m.add_coordinate("theta", "angle", body="bob")
    return m


def slider(com=(0.1, 0.0)) -> md.Mechanism:
    m = md.Mechanism("slider", gravity=(0.0, -G))
    m.add_body("block", mass=3.0, inertia=0.01, com=com, pose=(0.2, 0.0, 0.0))
    m.add_prismatic("guide", "ground", "block", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0))
    m.add_coordinate("s", "travel", joint="guide")
    return m


# ------------------------------------------------------------------ inertia
def test_inertia_forces_are_frame_mass_matrix_times_acceleration_plus_centripetal():
    model = md.Mechanism("x")
    model.add_body("a", mass=2.0, inertia=0.3, com=(0.2, -0.1))
    model.add_body("b", mass=1.5, inertia=0.1, com=(0.0, 0.4))
    model.add_revolute("O", "ground", "a")
    model.add_revolute("P", "a", "b", (0.5, 0.0), (0.0, 0.0))
    model.add_coordinate("p", "angle", body="a")
    model.add_coordinate("q", "angle", body="b")
    mod = model.compile()
    rng = np.random.default_rng(1)
    x, v, a = (rng.normal(size=(4, 6)) for _ in range(3))
    M = frame_mass_matrix(mod, x)
    th = x[:, 2::3]
    arm = np.stack([np.cos(th) * mod.com[:, 0] - np.sin(th) * mod.com[:, 1],
                    np.sin(th) * mod.com[:, 0] + np.cos(th) * mod.com[:, 1]], axis=-1)
    cent = np.zeros((4, 2, 3))
    cent[..., :2] = -(mod.mass[:, None] * arm) * v[:, 2::3, None] ** 2
    expected = np.einsum("nij,nj->ni", M, a) + cent.reshape(4, 6)
    np.testing.assert_allclose(inertia_forces(mod, x, v, a), expected, atol=1e-12)
    # symmetric, positive definite
    np.testing.assert_allclose(M, np.swapaxes(M, -1, -2))
    assert np.all(np.linalg.eigvalsh(M) > 0)


# ------------------------------------------------------------------ signs
def test_reaction_is_force_on_child_from_parent():
    res = kinetostatics(pendulum(), over="theta", speed=0.0, values=[-np.pi / 2])
    # hanging at rest: the pin holds the bob up
    np.testing.assert_allclose(res.reactions["O"][0], [0.0, 2.0 * G], atol=1e-12)
    np.testing.assert_allclose(res.driving["theta"], 0.0, atol=1e-12)
    # the same pin declared with the ground as child: the ground is pulled down
    res2 = kinetostatics(pendulum(parent_is_ground=False), over="theta", speed=0.0,
                         values=[-np.pi / 2])
    np.testing.assert_allclose(res2.reactions["O"][0], [0.0, -2.0 * G], atol=1e-12)
    # what the frame receives is the same either way: the weight
    np.testing.assert_allclose(res.frame_force, [[0.0, -2.0 * G]], atol=1e-12)
    np.testing.assert_allclose(res2.frame_force, [[0.0, -2.0 * G]], atol=1e-12)


def test_driving_torque_is_what_the_drive_applies_and_frame_takes_its_reaction():
    # horizontal: the drive must hold the weight with a CCW torque m g l
    res = kinetostatics(pendulum(), over="theta", speed=0.0, values=[0.0], point=(0.0, 0.0))
    np.testing.assert_allclose(res.driving["theta"], [2.0 * G * 0.3], rtol=1e-12)
    # the motor stator pushes back on the frame
    np.testing.assert_allclose(res.frame_loads["drives"][0], [0.0, 0.0, -2.0 * G * 0.3],
                               atol=1e-12)
    # total frame moment about the pivot: the weight's moment about O (-m g l) ... and
    # the pin passes no moment, so frame moment = stator reaction = -m g l
    np.testing.assert_allclose(res.frame_moment, [-2.0 * G * 0.3], rtol=1e-12)
    # about another point: M_P = M_O - (P - O) x F
    res_p = kinetostatics(pendulum(), over="theta", speed=0.0, values=[0.0], point=(0.5, 0.2))
    F = res.frame_force[0]
    expected = res.frame_moment[0] - (0.5 * F[1] - 0.2 * F[0])
    np.testing.assert_allclose(res_p.frame_moment, [expected], rtol=1e-12)


def test_prismatic_reaction_normal_force_and_moment_and_travel_drive():
    res = kinetostatics(slider(), over="s", speed=0.0, values=[0.2, 0.3])
    # the guide carries the weight (normal +y) and the moment of the offset weight
    np.testing.assert_allclose(res.joint_frame["guide"], [[0.0, 3.0 * G]] * 2, atol=1e-12)
    np.testing.assert_allclose(res.moments["guide"], [0.1 * 3.0 * G] * 2, rtol=1e-12)
    np.testing.assert_allclose(res.driving["s"], 0.0, atol=1e-12)
    df = res.to_dataframe()
    assert {"s_m", "F_drive_s_N", "P_drive_s_W", "Ft_guide_N", "Fn_guide_N",
            "M_guide_Nm"} <= set(df.columns)
    # pushing it at constant acceleration along the guide needs m a
    res2 = kinetostatics(slider(), over="s", t=np.linspace(0, 1, 5),
                         law=lambda t: (0.2 + 0.5 * t**2, 1.0 * t, 1.0))
    np.testing.assert_allclose(res2.driving["s"], 3.0, rtol=1e-12)
    np.testing.assert_allclose(res2.power["s"], 3.0 * np.linspace(0, 1, 5), rtol=1e-12)


# ------------------------------------------------------------------ the record
def rotor(m=1.5, r=0.2, gravity=(0.0, 0.0)):
    mech = md.Mechanism("rotor", gravity=gravity)
    mech.add_body("disc", mass=m, inertia=0.02, com=(r, 0.0))
    mech.add_revolute("O", "ground", "disc")
    mech.add_coordinate("phi", "angle", body="disc")
    return mech


def test_record_fields_dataframe_and_summary():
    res = kinetostatics(rotor(), over="phi", speed=10.0)
    assert isinstance(res, Kinetostatics)
    assert res.n == 361 and res.status == "success" and res.warnings == ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.status = "x"
    df = res.to_dataframe()
    for col in ("t_s", "phi_deg", "M_drive_phi_Nm", "P_drive_phi_W", "Fx_O_N", "Fy_O_N",
                "F_O_N", "angle_F_O_deg", "Fx_frame_N", "Fy_frame_N", "F_frame_N",
                "M_frame_Nm", "Fx_frame_O_N"):
        assert col in df.columns
    assert len(df) == 361
    np.testing.assert_allclose(df["phi_deg"].iloc[-1], 360.0)
    np.testing.assert_allclose(df["t_s"].iloc[-1], 2 * np.pi / 10.0)
    # a rotating unbalance: the bearing force turns with the crank, |F| = m r w^2
    np.testing.assert_allclose(df["F_O_N"], 1.5 * 0.2 * 100.0, rtol=1e-12)
    ang = np.deg2rad(df["angle_F_O_deg"] - df["phi_deg"] + 180.0)  # points to the centre
    np.testing.assert_allclose(np.cos(ang), 1.0, atol=1e-12)
    text = res.summary()
    assert "peak" in text and "RMS" in text and "joint O" in text and "shaking" in text
    p = res.peaks()
    assert p["joints"]["O"]["peak"] == pytest.approx(30.0)
    assert p["driving"]["phi"]["rms"] == pytest.approx(0.0, abs=1e-9)
    assert repr(res).startswith("Kinetostatics(") and "status='success'" in repr(res)


def test_harmonics_of_a_rotating_unbalance():
    m, r, w = 1.5, 0.2, 10.0
    res = kinetostatics(rotor(m, r), over="phi", speed=w,
                        values=np.linspace(0.0, 2 * np.pi, 73), point=(0.1, 0.0))
    h = res.harmonics()
    assert list(h["order"][:3]) == [0, 1, 2] and len(h) == 37
    np.testing.assert_allclose(h["f_Hz"][1], w / (2 * np.pi))
    amp = m * r * w**2
    np.testing.assert_allclose(h["Fx_frame_N"][1], amp, rtol=1e-12)
    np.testing.assert_allclose(h["Fy_frame_N"][1], amp, rtol=1e-12)
    assert np.all(np.abs(h["Fx_frame_N"][2:]) < 1e-9 * amp)
    # Fx = m r w^2 cos(phi): phase 0; Fy = m r w^2 sin(phi): phase -90 deg
    np.testing.assert_allclose(h["Fx_frame_N_phase_deg"][1], 0.0, atol=1e-9)
    np.testing.assert_allclose(h["Fy_frame_N_phase_deg"][1], -90.0, atol=1e-9)
    # moment about (0.1, 0): -(P x F) with the pin at the origin: 0.1 * Fy ... first order
    np.testing.assert_allclose(h["M_frame_Nm"][1], 0.1 * amp, rtol=1e-12)
    assert len(res.harmonics(3)) == 4
    # not one uniform turn: refused with an explanation
    half = kinetostatics(rotor(), over="phi", speed=w, values=np.linspace(0, np.pi, 40))
    with pytest.raises(ValueError, match="one full turn"):
        half.harmonics()


# ------------------------------------------------------------------ motion specs
def test_motion_specs_and_errors():
    mech = rotor(gravity=(0.0, -G))
    with pytest.raises(ModelError, match="valid coordinate names"):
        kinetostatics(mech, over="psi", speed=1.0)
    with pytest.raises(ValueError, match="give the motion"):
        kinetostatics(mech, over="phi")
    with pytest.raises(ValueError, match="needs the times"):
        kinetostatics(mech, over="phi", law=lambda t: t)
    traj = SimpleNamespace(t=[0.0, 1.0], q=[[0.0], [1.0]], qdot=[[1.0], [1.0]],
                           qddot=[[0.0], [0.0]])
    with pytest.raises(ValueError, match="not both"):
        kinetostatics(mech, trajectory=traj, speed=1.0)
    with pytest.raises(ModelError, match="load"):
        kinetostatics(mech, over="phi", speed=1.0, reacting_loads=["nothing"])
    with pytest.raises(ValueError, match="model_drives"):
        kinetostatics(mech, over="phi", speed=1.0, model_drives="keep")
    # negative speed: default values go backwards and time still advances
    res = kinetostatics(mech, over="phi", speed=-2.0)
    assert res.values[-1] == pytest.approx(-2 * np.pi)
    assert np.all(np.diff(res.t) > 0)
    # the trajectory route, default over = first coordinate
    res = kinetostatics(mech, trajectory=traj)
    assert res.over == "phi" and res.driven == ("phi",)


def test_speed_takes_units_of_its_coordinate():
    """A speed in units (text, pint quantity, one per coordinate) is its SI number: the
    same times and torques; a unit of the wrong dimension names speed and coordinate."""
    rot = rotor(gravity=(0.0, -G)).compile()
    phi = np.linspace(0.0, np.pi, 7)
    ref = kinetostatics(rot, over="phi", speed=2 * np.pi, values=phi)
    for speed in ("60 rpm", "1 turn/s", registry().Quantity(360.0, "deg/s"), ["60rpm"],
                  (np.float64(2 * np.pi),)):
        res = kinetostatics(rot, over="phi", speed=speed, values=phi)
        np.testing.assert_allclose(res.t, ref.t, rtol=1e-14, atol=0.0)
        np.testing.assert_allclose(res.driving["phi"], ref.driving["phi"], rtol=1e-12)
    sl = slider().compile()
    s = np.linspace(0.2, 0.3, 5)
    ref = kinetostatics(sl, over="s", speed=0.5, values=s)
    for speed in ("500 mm/s", registry().Quantity(1.8, "km/h")):
        res = kinetostatics(sl, over="s", speed=speed, values=s)
        np.testing.assert_allclose(res.t, ref.t, rtol=1e-14, atol=0.0)
    with pytest.raises(UnitError, match=r"speed of 'phi' \(an angle coordinate\): '0.5 m/s'"
                       r".*velocity unit.*expected an angular velocity"):
        kinetostatics(rot, over="phi", speed="0.5 m/s", values=phi)
    with pytest.raises(UnitError, match=r"speed of 'phi'.*no angle unit"):
        kinetostatics(rot, over="phi", speed="1 Hz", values=phi)
    with pytest.raises(UnitError, match=r"speed of 's' \(a length coordinate\).*expected a "
                                        r"velocity"):
        kinetostatics(sl, over="s", speed=registry().Quantity(60.0, "rpm"), values=s)
    with pytest.raises(ValueError, match="expected 1 value"):
        kinetostatics(rot, over="phi", speed=["60 rpm", "30 rpm"], values=phi)


def test_model_drives_replace_or_load():
    mech = rotor(gravity=(0.0, -G))
    mech.add(Drive("motor", "phi", TorqueSpeedCurve((0.0, 20.0), (5.0, 0.0))))
    vals = np.linspace(0, 2 * np.pi, 37)
    rep = kinetostatics(mech, over="phi", speed=10.0, values=vals)
    load = kinetostatics(mech, over="phi", speed=10.0, values=vals, model_drives="load")
    np.testing.assert_allclose(rep.driving["phi"] - load.driving["phi"], 2.5, rtol=1e-12)
    assert "replaced" in rep.message
    # the stator takes the whole motor torque either way
    np.testing.assert_allclose(rep.frame_loads["drives"], load.frame_loads["drives"],
                               atol=1e-12)


def test_batched_loads_match_scalar_evaluator_for_every_kind():
    mech = rotor(gravity=(0.0, -G))
    mech.add_ground({"S": (0.5, 0.5)})
    mech.add(Spring("s", "ground", "S", "disc", (0.2, 0.0), stiffness=100.0,
                    free_length=0.3, damping=2.0, preload=4.0))
    mech.add(Force("f1", "disc", (0.1, 0.0), Table((0.0, 1.0), (0.0, 10.0), "t"), (1.0, 1.0)))
    mech.add(Force("f2", "disc", (0.1, 0.0), lambda ctx: 3.0 * ctx.rate("phi"), (0.0, 1.0),
                   "body"))
    mech.add(Force("f3", "disc", (0.2, 0.0),
                   Table((-0.2, 0.2), (5.0, -5.0), "disc.com.y", outside=0.0), (1.0, 0.0)))
    mech.add(Drive("motor", "phi", Table((0.0, 7.0), (1.0, 2.0), "phi")))
    model = mech.compile()
    res = kinetostatics(model, over="phi", t=np.linspace(0, 1, 21),
                        law=lambda t: (1.3 * t + 0.5 * t**2, 1.3 + t, 1.0), model_drives="load")
    F, ground, Qd = applied_forces(model, res.t, res.x, res.xdot, res.q, res.qdot)
    fm = force_model(model)
    for k in range(res.n):
        Fk, Qk = fm.applied(res.t[k], res.x[k], res.xdot[k], res.q[k], res.qdot[k])
        G_ = np.array([[0.0, 0.0, 1.0]])
        np.testing.assert_allclose(F[k], Fk + Qk @ G_, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(Qd[k], Qk, rtol=1e-12)
    # the spring's ground end: its force on the frame is opposite to that on the disc
    assert np.all(np.isfinite(ground)) and np.any(ground)
    assert "loads" in res.frame_loads


# ------------------------------------------------------------------ process loads
def test_stroke_window_acts_only_near_the_end_and_on_the_way_there():
    w = StrokeWindow(100.0, "slide", "F", end=-0.2, travel=0.003)
    y = np.array([-0.19, -0.1985, -0.2025, -0.2, -0.2, -0.1985])
    v = np.array([-1.0, -1.0, -1.0, -1.0, 1.0, 1.0])
    np.testing.assert_allclose(w.factor(y, v), [0, 1, 0, 1, 0, 0])
    w2 = StrokeWindow(100.0, "slide", "F", end=-0.2, travel=0.003, approaching_only=False,
                      ramp=0.002)
    np.testing.assert_allclose(w2.factor(y, v), [0, 0.75, 0, 1, 1, 0.75])
    with pytest.raises(ValueError, match="travel"):
        StrokeWindow(1.0, "slide", "F", end=0.0, travel=0.0)
    with pytest.raises(ValueError, match="towards"):
        StrokeWindow(1.0, "slide", "F", end=0.0, travel=0.1, towards=0)


def test_punch_load_is_an_ordinary_force_for_scalar_and_batched_contexts():
    m = md.Mechanism("ram", gravity=(0.0, 0.0))
    m.add_body("ram", mass=1.0, points={"F": (0.0, 0.0)}, pose=(0.0, -0.1, 0.0))
    m.add_prismatic("guide", "ground", "ram", (0.0, 0.0), (0.0, 1.0), "F")
    m.add_coordinate("y", "travel", joint="guide")
    f = punch_load("punch", "ram", "F", 500.0, end=-0.2, travel=0.003)
    assert f.direction == (0.0, 1.0) and isinstance(f.magnitude, StrokeWindow)
    m.add(f)
    model = m.compile()
    t = np.linspace(0.0, 1.0, 201)
    # ram goes down from -0.1 to -0.2 and back (y = -0.15 - 0.05 cos(2 pi t))
    res = kinetostatics(model, over="y", t=t,
                        law=lambda s: (-0.15 - 0.05 * np.cos(2 * np.pi * s),
                                       0.1 * np.pi * np.sin(2 * np.pi * s),
                                       0.2 * np.pi**2 * np.cos(2 * np.pi * s)))
    acting = np.abs(res.driving["y"] - 1.0 * res.qddot[:, 0]) > 1e-9
    y = res.q[acting, 0]
    assert acting.any() and np.all(y <= -0.197 + 1e-12) and np.all(res.qdot[acting, 0] < 0)
    # the punch pushes up (+y) while the ram moves down: the drive pushes 500 N harder down
    np.testing.assert_allclose(res.driving["y"][acting] - res.qddot[acting, 0], -500.0)
    # scalar context (forward dynamics) gives the same
    k = int(np.flatnonzero(acting)[0])
    ctx = LoadContext(model, t[k], res.q[k], res.qdot[k], res.x[k], res.xdot[k])
    assert f.magnitude(ctx) == 500.0


def test_position_and_time_pulse_helpers_build_tables():
    f = position_load("cushion", "slider", "F", [-0.3, -0.2], [1000.0, 0.0])
    assert f.magnitude.variable == "slider.F.y" and f.magnitude.outside == 0.0
    with pytest.raises(ValueError, match="named point"):
        position_load("c", "slider", (0.0, 0.0), [0, 1], [0, 1])
    p = time_pulse_load("kick", "slider", "F", 200.0, start=0.1, duration=0.01)
    assert p.magnitude(0.105) == 200.0 and p.magnitude(0.2) == 0.0


def test_module_docstring_examples_run():
    failures, _ = doctest.testmod(ks_module, optionflags=doctest.ELLIPSIS)
    assert failures == 0
    from mechdyn.mechanism import process

    failures, _ = doctest.testmod(process)
    assert failures == 0
