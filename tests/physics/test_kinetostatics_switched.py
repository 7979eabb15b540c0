"""Kinetostatics of a switched (variable-structure) trajectory, mode by mode, against the
forward dynamics that produced it and closed forms.

Two coaxial discs: disc 1 is driven by a constant torque T from rest, disc 2 spins freely
at 1 rad/s; a switch locks them together at a crossing.  While locked, the lock carries
the torque that accelerates disc 2: M = J2 alpha = J2 T / (J1 + J2).
"""

import warnings

import numpy as np
import pytest

import mechdyn as md
from mechdyn.dynamics.reactions import KinetostaticsWarning
from mechdyn.mechanism import Drive, Mechanism
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import CoordinateLock, Switch, add_element

J1, J2, T = 0.2, 0.05, 2.0
T_END = 1.5


def _discs(weld: bool) -> Mechanism:
    m = Mechanism("two coaxial discs", gravity=(0.0, 0.0))
    m.add_body("d1", mass=3.0, inertia=J1)
    m.add_body("d2", mass=1.0, inertia=J2)
    m.add_revolute("O1", "ground", "d1")
    m.add_coordinate("th1", kind="angle", body="d1")
    m.add_coordinate("th2", kind="angle", body="d2")
    if weld:  # a weld over a second pin, engaged when th1 rises through 1 rad
        m.add_revolute("O2", "ground", "d2")
        m.add_lock("clutch", "d1", "d2", engaged=False)
        add_element(m, Switch("catch", "engage", "clutch", variable="th1", value=1.0,
                              direction=1))
    else:  # a coordinate lock on the relative angle, engaged when disc 1 catches up
        m.add_revolute("R", "d1", "d2")
        add_element(m, CoordinateLock("clutch", "joint:R"))
        add_element(m, Switch("catch", "engage", "clutch", variable="joint:R", value=0.0,
                              direction=-1))
    m.add(Drive("motor", "th1", T))
    return m


def _run(mech):
    tr = md.simulate(mech, T_END, q0=[0.0, 0.5], qdot0=[0.0, 1.0],
                     t_eval=np.linspace(0.0, T_END, 151), rtol=1e-11)
    assert tr.status == "success", tr.message
    return tr


@pytest.mark.parametrize("weld", [True, False], ids=["weld-lock", "coordinate-lock"])
def test_switched_discs_torques_lock_moment_and_power_per_segment(weld):
    mech = _discs(weld)
    tr = _run(mech)
    vs = tr.stats["variable_structure"]
    assert [sorted(m) for m in vs["modes"]] == [[], ["clutch"]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinetostaticsWarning)  # weld over a pin: redundant
        res = md.kinetostatics(mech, trajectory=tr)
    assert res.switched and res.n == tr.t.size
    np.testing.assert_array_equal(res.mode_index, vs["mode_index"])
    np.testing.assert_array_equal(res.t, tr.t)
    before = res.mode_index == 0
    after = ~before
    assert before.sum() > 10 and after.sum() > 10
    # the switching instant appears twice, in order: before (free) then after (locked)
    t_sw = [e.t for e in tr.events if e.kind == "engage"][0]
    k = np.flatnonzero(res.t == t_sw)
    assert list(k) == [k[0], k[0] + 1] and list(res.mode_index[k]) == [0, 1]
    assert [s["driven"] for s in res.stats["segments"]] == [("th1", "th2"), ("th1",)]

    # forward vs inverse: the drive torque in every segment; the free disc needs none
    np.testing.assert_allclose(res.driving["th1"], T, rtol=0, atol=1e-9 * T)
    np.testing.assert_allclose(res.driving["th2"][before], 0.0, atol=1e-9 * T)
    assert np.all(np.isnan(res.driving["th2"][after]))  # th2 is dependent while locked

    # the lock: NaN while released, J2 alpha while engaged (closed form and measured)
    M = res.moments["clutch"] if weld else res.element_forces["clutch"]
    assert np.all(np.isnan(M[before]))
    np.testing.assert_allclose(M[after], J2 * T / (J1 + J2), rtol=1e-9)
    np.testing.assert_allclose(M[after], J2 * tr.qddot[after, 1], rtol=1e-9)
    if not weld:  # the forward run's own lock torque
        np.testing.assert_allclose(M[after], vs["forces"]["clutch"][after], rtol=1e-9)

    # power balance per segment: drive power = dT/dt = J1 w1 a1 + J2 w2 a2
    for seg in res.stats["segments"]:
        assert seg["power_balance_rel"] < 1e-12
    p_drive = np.nansum([res.power[c] for c in res.driven], axis=0)
    dT = J1 * tr.qdot[:, 0] * tr.qddot[:, 0] + J2 * tr.qdot[:, 1] * tr.qddot[:, 1]
    np.testing.assert_allclose(p_drive, dT, rtol=0, atol=1e-9 * np.max(np.abs(dT)))

    # table and summary
    df = res.to_dataframe()
    assert list(df["mode"].iloc[[0, -1]]) == ["-", "clutch"]
    col = "M_clutch_Nm"
    assert df[col].isna().sum() == before.sum()
    text = res.summary()
    assert "2 segment(s) in 2 mode(s)" in text and "0.4 N m" in text
    p = res.peaks()
    if weld:
        assert p["joints"]["clutch"]["peak_moment"] == pytest.approx(0.4, rel=1e-9)
        assert p["joints"]["clutch"]["peak_moment_t"] >= t_sw
    else:
        assert p["elements"]["clutch"]["peak"] == pytest.approx(0.4, rel=1e-9)


def test_closed_stop_carries_the_drive_torque_less_the_weight_moment():
    """A pendulum disc driven into an upper stop (plastic): once closed there is no
    freedom left; the stop's torque (a row of dynamics/modes.py) balances the drive
    and the weight, and agrees with the forward run's stop force."""
    m = Mechanism("disc against a stop", gravity=(0.0, -9.81))
    m.add_body("d1", mass=3.0, inertia=0.2, com=(0.05, 0.0))
    m.add_revolute("O1", "ground", "d1")
    m.add_coordinate("th1", kind="angle", body="d1")
    m.add(Drive("motor", "th1", 4.0))
    add_element(m, Stop("stop", "th1", upper=1.0, restitution=0.0))
    tr = md.simulate(m, 1.0, q0=[0.0], qdot0=[0.0], t_eval=np.linspace(0.0, 1.0, 101),
                     rtol=1e-11)
    assert tr.status == "success", tr.message
    res = md.kinetostatics(m, trajectory=tr)
    closed = res.mode_index == 1
    assert closed.sum() > 10 and res.status == "success"
    assert res.stats["segments"][1]["driven"] == ()
    np.testing.assert_allclose(res.driving["th1"][~closed], 4.0, atol=1e-9)
    assert np.all(np.isnan(res.driving["th1"][closed]))
    stop = res.element_forces["stop"]
    assert np.all(np.isnan(stop[~closed]))
    np.testing.assert_allclose(stop[closed], 4.0 - 3.0 * 9.81 * 0.05 * np.cos(1.0), rtol=1e-12)
    np.testing.assert_allclose(stop[closed], tr.stats["variable_structure"]["forces"]["stop"]
                               [closed], rtol=1e-12)
    # what the frame receives equals the forward run's record
    np.testing.assert_allclose(res.frame_force, tr.stats["variable_structure"]["frame_force"],
                               atol=1e-9)
    assert "F_stop_N" not in res.to_dataframe() and "M_stop_Nm" in res.to_dataframe()


def test_mode_cannot_be_forced_on_a_switched_trajectory():
    mech = _discs(True)
    tr = _run(mech)
    with pytest.raises(ValueError, match="variable-structure"):
        md.kinetostatics(mech, trajectory=tr, mode={"clutch"})


def test_forward_run_and_kinetostatics_report_the_same_joint_reactions():
    """One reaction reporter: the force AND moment on the child from the parent, at the
    joint point, ground frame.  The clutchless press run to just past its first lock
    (stops, an impact-closed contact, the rocker lock) and analysed again by
    kinetostatics from its own samples: every joint's force and moment agree to
    round-off (a revolute's moment at its pin is zero; the rocker's pin B used to be
    reported about the rocker's frame origin, 400 N m).  The weld of the two discs
    reports the same moment about its point (the child frame origin) both ways."""
    from mechdyn.examples import press_cycle

    mech = press_cycle.build()
    tr = md.simulate(mech, 0.2, rtol=1e-9, t_eval=np.linspace(0.0, 0.2, 101))
    assert tr.status == "success", tr.message
    assert [e.kind for e in tr.events].count("engage") == 1
    res = md.kinetostatics(mech, trajectory=tr)
    forces = tr.stats["variable_structure"]["forces"]
    scale = max(np.max(np.abs(res.reactions[j])) for j in res.reactions)
    assert scale > 1e4  # N: the stroke's linkage forces
    for j, kind in res.joint_kinds.items():
        f = np.asarray(forces[j])
        assert f.shape == (tr.t.size, 2 if kind == "revolute" else 3)
        np.testing.assert_allclose(f[:, :2], res.reactions[j], rtol=0, atol=1e-8 * scale)
        moment = f[:, 2] if f.shape[1] == 3 else np.zeros(tr.t.size)
        np.testing.assert_allclose(moment, res.moments[j], rtol=0, atol=1e-8 * scale)
    assert "M_B_Nm" not in tr.to_dataframe() and "M_guide_Nm" in tr.to_dataframe()
    # the loads on the frame (joint reactions, spring ends, stops, the motor's stator):
    # force and moment about the ground origin, forward run against inverse dynamics
    vs = tr.stats["variable_structure"]
    fscale = np.max(np.abs(res.frame_force))
    np.testing.assert_allclose(vs.frame_force, res.frame_force, rtol=0, atol=1e-9 * fscale)
    np.testing.assert_allclose(vs.frame_moment, res.frame_moment, rtol=0,
                               atol=1e-9 * np.max(np.abs(res.frame_moment)))
    assert "M_frame_Nm" in tr.to_dataframe()
    P = (0.05, -0.12)  # about another point, as kinetostatics takes it
    trp = md.simulate(mech, 0.2, rtol=1e-9, t_eval=np.linspace(0.0, 0.2, 101), point=P)
    resp = md.kinetostatics(mech, trajectory=trp, point=P)
    np.testing.assert_allclose(trp.stats["variable_structure"].frame_moment, resp.frame_moment,
                               rtol=0, atol=1e-9 * np.max(np.abs(resp.frame_moment)))

    discs = _discs(True)
    tr = _run(discs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinetostaticsWarning)  # weld over a pin
        res = md.kinetostatics(discs, trajectory=tr)
    locked = res.mode_index == 1
    clutch = tr.stats["variable_structure"]["forces"]["clutch"]
    np.testing.assert_allclose(clutch[locked, 2], res.moments["clutch"][locked], rtol=1e-12)
