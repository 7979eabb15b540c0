"""Impacts of a mechanism whose pairs have friction (issue 12, item 4): the impulse
problem takes the pairs as frictionless, and says so once per event, naming the pairs
that carry an impulse."""

import warnings

import numpy as np
from dynamics_models import pendulum

import mechdyn
from mechdyn.friction.ignored import FrictionIgnoredWarning
from mechdyn.mechanism.contact import Stop
from mechdyn.mechanism.switch import add_element

G = 9.81


def test_pendulum_with_pin_friction_stopped_by_a_plastic_stop():
    """A pendulum with pin friction released horizontal, stopped by a plastic stop on its
    angle: after the impact it is at rest (theta' = 0: the stop's row takes the whole
    momentum, the pin friction is not in the impulse problem), the energy lost in the
    impact is its kinetic energy just before, and the warning names pin 'O' and the stop
    once (the pendulum then stays on the stop, held by it: no further impact)."""
    m, a, Jc = 2.0, 0.5, 0.05
    mech = pendulum(90.0, m=m, a=a, Jc=Jc, g=G)
    pin = mech.joints["O"]
    mech.joints["O"] = type(pin)(**{**pin.__dict__, "friction": 0.2, "pin_radius": 0.02})
    add_element(mech, Stop("rest", "theta", lower=-1.0, restitution=0.0))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tr = mechdyn.simulate(mech, 0.8, q0=[0.0], qdot0=[0.0], progress=False)
    assert tr.status == "success", tr.message
    hits = [e for e in tr.events if e.kind == "impact"]
    assert len(hits) == 1
    ev = hits[0]
    assert abs(ev.q_before[0] + 1.0) < 1e-9 and ev.qdot_before[0] < -1.0
    assert ev.qdot_after[0] == 0.0 or abs(ev.qdot_after[0]) < 1e-12
    J_O = Jc + m * a * a
    np.testing.assert_allclose(ev.energy_lost, 0.5 * J_O * ev.qdot_before[0] ** 2, rtol=1e-12)
    notes = [str(w.message) for w in caught if issubclass(w.category, FrictionIgnoredWarning)]
    assert len(notes) == 1
    assert "'O'" in notes[0] and "'rest@lower' closing" in notes[0] and "frictionless" in notes[0]


def test_every_run_of_one_compiled_model_gives_its_own_warning():
    """The 'once' of the warning is once per run: a second run of the same compiled model
    (whose switchable elements are compiled once and kept with it) warns again."""
    mech = pendulum(90.0, m=2.0, a=0.5, Jc=0.05, g=G)
    pin = mech.joints["O"]
    mech.joints["O"] = type(pin)(**{**pin.__dict__, "friction": 0.2, "pin_radius": 0.02})
    add_element(mech, Stop("rest", "theta", lower=-1.0, restitution=0.0))
    model = mech.compile()
    for _ in range(2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            tr = mechdyn.simulate(model, 0.8, q0=[0.0], qdot0=[0.0], progress=False)
        assert tr.status == "success", tr.message
        assert sum(issubclass(w.category, FrictionIgnoredWarning) for w in caught) == 1


def test_no_warning_for_an_impact_of_frictionless_pairs():
    mech = pendulum(90.0)
    add_element(mech, Stop("rest", "theta", lower=-1.0, restitution=0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionIgnoredWarning)
        tr = mechdyn.simulate(mech, 0.8, q0=[0.0], qdot0=[0.0], progress=False)
    assert [e.element for e in tr.events] == ["rest@lower"]
