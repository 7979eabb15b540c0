"""One engine: a switched run is fixed-structure runs joined at its events.

A disc driven by the 4A80B4U3 induction motor through a 3.4:1 gear (rotor and
gear inertia reduced to the disc's coordinate) carries a second disc on a pin;
a clutch (a coordinate lock of the pin) engages at 0.1 s and releases at 0.2 s.
Between the events the motion must equal that of fixed-structure models run
on their own: before the clutch engages, the driven disc alone (the second disc
spins freely on a frictionless pin, so it does not act on the first); while it
is engaged, the two discs welded into one body.  The same model with a switch
that never fires must give the fixed-structure run of the model without it.
Earlier, the variable-structure path dropped the motor rotor and gear inertia
(45.9 rad/s instead of 7.76 rad/s after 10 ms from rest).
"""

import numpy as np
import pytest

from mechdyn.mechanism import Mechanism
from mechdyn.mechanism.switch import CoordinateLock, Switch, add_element
from mechdyn.modelfile.drives import drive_from_table
from mechdyn.simulate.run import simulate

J1, J2 = 0.02, 0.01  # kg m^2, both discs centred on the axis
RTOL = 1e-12
MOTOR = {"type": "induction_motor", "coordinate": "th1", "catalogue": "4A80B4U3",
         "gear_ratio": 3.4}


def _motor():
    return drive_from_table(dict(MOTOR), "test")


def _two_discs(switch_times=(0.1, 0.2)):
    m = Mechanism("disc, clutch and driven disc", gravity=(0.0, 0.0))
    m.add_body("d1", mass=2.0, inertia=J1)
    m.add_body("d2", mass=1.0, inertia=J2)
    m.add_revolute("O", "ground", "d1")
    m.add_revolute("R", "d1", "d2")
    m.add_coordinate("th1", kind="angle", body="d1")
    m.add_coordinate("th2", kind="angle", body="d2")
    m.add(_motor())
    if switch_times is not None:
        on, off = switch_times
        add_element(m, CoordinateLock("clutch", "joint:R"))
        add_element(m, Switch("on", "engage", "clutch", times=(on,)))
        add_element(m, Switch("off", "release", "clutch", times=(off,)))
    return m


def _one_disc(welded: bool):
    m = Mechanism("driven disc" + (" with the second welded on" if welded else ""),
                  gravity=(0.0, 0.0))
    m.add_body("d1", mass=2.0, inertia=J1)
    m.add_revolute("O", "ground", "d1")
    m.add_coordinate("th1", kind="angle", body="d1")
    if welded:
        m.add_body("d2", mass=1.0, inertia=J2)
        m.add_lock("weld", "d1", "d2", engaged=True, offset=(0.0, 0.0, 0.0))
    m.add(_motor())
    return m


def test_between_events_the_switched_run_equals_fixed_structure_runs():
    w1, w2 = 40.0, -10.0
    te = np.linspace(0.0, 0.3, 61)
    tr = simulate(_two_discs(), 0.3, q0=[0.0, 0.0], qdot0=[w1, w2], t_eval=te, rtol=RTOL,
                  progress=False)
    assert tr.status == "success", tr.message
    kinds = [(e.kind, round(e.t, 12)) for e in tr.events if e.kind in ("engage", "release")]
    assert kinds == [("engage", 0.1), ("release", 0.2)]
    # before the clutch engages: the driven disc alone, rotor and gear inertia included
    before = te[te < 0.1]
    ref = simulate(_one_disc(False), float(before[-1]), q0=[0.0], qdot0=[w1], t_eval=before,
                   rtol=RTOL, progress=False)
    sel = np.isin(tr.t, before)
    np.testing.assert_allclose(tr.qdot[sel, 0], ref.qdot[:, 0], rtol=1e-9)
    np.testing.assert_allclose(tr.q[sel, 0], ref.q[:, 0], rtol=1e-9, atol=1e-12)
    # engaged: both discs as one body, started from the state just after the impact
    eng = [e for e in tr.events if e.kind == "engage"][0]
    during = te[(te > 0.1) & (te < 0.2)]
    ref2 = simulate(_one_disc(True), float(during[-1]), t0=0.1, q0=[eng.q_after[0]],
                    qdot0=[eng.qdot_after[0]], t_eval=during, rtol=RTOL, progress=False)
    sel2 = np.isin(tr.t, during) & (tr.t > 0.1)
    got = tr.qdot[sel2]
    np.testing.assert_allclose(got[:, 0], ref2.qdot[:, 0], rtol=1e-9)
    np.testing.assert_allclose(got[:, 1], ref2.qdot[:, 0], rtol=1e-9)  # they turn as one
    # the motor's rotor inertia shows: the plastic engagement conserves the momentum of
    # d1 with the rotor (reduced to th1) and d2
    from mechdyn.model.inertia import drive_inertia

    Jr = float(drive_inertia(_one_disc(False).compile())[0])
    assert Jr > 0
    h_before = (J1 + Jr) * eng.qdot_before[0] + J2 * eng.qdot_before[1]
    h_after = (J1 + Jr + J2) * eng.qdot_after[0]
    assert h_after == pytest.approx(h_before, rel=1e-10)


def test_a_switch_that_never_fires_gives_the_fixed_structure_run():
    te = np.linspace(0.0, 0.05, 11)
    kw = dict(q0=[0.0, 0.0], qdot0=[0.0, 5.0], t_eval=te, rtol=RTOL, progress=False)
    switched = simulate(_two_discs(switch_times=(1.0, 2.0)), 0.05, **kw)
    fixed = simulate(_two_discs(switch_times=None), 0.05, **kw)
    assert switched.events == [] and switched.status == fixed.status == "success"
    np.testing.assert_allclose(switched.q, fixed.q, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(switched.qdot, fixed.qdot, rtol=1e-9, atol=1e-12)
    # from rest, the motor through its gear (rotor inertia included) reaches the
    # speed of the fixed-structure run, far below the 45.9 rad/s without the rotor
    assert switched.qdot[2, 0] == pytest.approx(fixed.qdot[2, 0], rel=1e-9)
