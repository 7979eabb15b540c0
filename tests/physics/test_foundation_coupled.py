"""The machine on its isolators, coupled in one simulation (mechdyn.foundation.mounting),
against closed forms: a rotating unbalance's transmissibility, the static sag, the
momentum balance, and the one-way linear prediction for a heavy base."""

import numpy as np
import pytest

import mechdyn
from mechdyn import Mechanism
from mechdyn.errors import ModelError
from mechdyn.foundation import (
    Foundation,
    Isolator,
    compare_mounting,
    floor_forces,
    mounted,
    transmissibility,
)
from mechdyn.mechanism import Drive, Force, TorqueSpeedCurve

M_ROTOR, ECC, SPEED = 10.0, 0.01, 30.0  # kg, m, rad/s


def unbalance(gravity=(0.0, 0.0), ecc=ECC, speed=SPEED, drive=True) -> Mechanism:
    """A disc pinned to the frame at the origin, its mass ``ecc`` off the pin, held at
    ``speed`` by a steep speed governor (a drive on its angle)."""
    mech = Mechanism("unbalance", gravity=gravity)
    mech.add_body("rotor", mass=M_ROTOR, inertia=50.0, com=(ecc, 0.0))
    mech.add_revolute("O", "ground", "rotor")
    mech.add_coordinate("phi", kind="angle", body="rotor")
    if drive:
        mech.add(Drive("motor", "phi", TorqueSpeedCurve((speed - 1, speed + 1),
                                                        (2e3, -2e3))))
        mech.extras["initial"] = {"qdot": {"phi": speed}}
    return mech


def base(mass=490.0, k=1e5, c=3000.0, y=0.0) -> Foundation:
    """Two isolators level with the base's centre of mass (the origin): x, y and the
    rotation are uncoupled."""
    return Foundation([Isolator("L", -0.5, y, k, k, c, c), Isolator("R", 0.5, y, k, k, c, c)],
                      mass=mass, inertia=40.0)


def harmonic(t, phase, signal):
    """Amplitude of ``signal`` at the rotor's angle ``phase`` (least squares)."""
    A = np.column_stack([np.cos(phase), np.sin(phase), np.ones_like(phase)])
    coef = np.linalg.lstsq(A, signal, rcond=None)[0]
    return float(np.hypot(*coef[:2]))


@pytest.fixture(scope="module")
def spinning():
    f = base()
    tr = mechdyn.simulate(mounted(unbalance(), f), 2.5, rtol=1e-10, progress=False,
                          t_eval=np.linspace(0.0, 2.5, 5001))
    assert tr.success
    return f, tr


def test_unbalance_transmissibility_closed_form(spinning):
    f, tr = spinning
    late = tr.t > 1.5  # transients decay as exp(-zeta wn t): below 1e-6 by then
    ff = floor_forces(tr, f)
    speed = float(np.mean(tr.rate("phi")[late]))
    force = M_ROTOR * ECC * speed**2
    m_total = f.mass + M_ROTOR  # the unbalanced mass moves with the base
    k, c = 2 * 1e5, 2 * 3000.0
    r = speed / np.sqrt(k / m_total)
    zeta = c / (2 * np.sqrt(k * m_total))
    closed = np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    linear = Foundation(f.supports, mass=m_total, inertia=f.inertia)
    phase = tr.coordinate("phi")[late] + tr.coordinate("base_theta")[late]
    for j, direction in enumerate("xy"):
        amp = harmonic(tr.t[late], phase, ff.floor[late, j]) / force
        assert amp == pytest.approx(closed, rel=1e-3)
        assert amp == pytest.approx(abs(transmissibility(linear, speed, direction)), rel=1e-3)


def test_floor_force_is_the_frame_force_of_the_floor(spinning):
    """The isolators' forces from the base's coordinates against the engine's frame
    loads of the new ground (its reactions and bushing ends): no joint holds the base to
    the floor."""
    f, tr = spinning
    ff = floor_forces(tr, f)
    df = tr.to_dataframe(energy=False, bodies=False, degrees=False)
    scale = np.abs(ff.floor[:, :2]).max()
    for j, col in enumerate(("Fx_frame_N", "Fy_frame_N", "M_frame_Nm")):
        assert np.max(np.abs(df[col].to_numpy() - ff.floor[:, j])) < 1e-12 * scale


def test_momentum_balance(spinning):
    """d/dt of the momentum of base and rotor = minus the force on the floor (no gravity)."""
    f, tr = spinning
    mech = tr.model.mechanism
    dp = np.zeros((tr.t.size, 2))
    xdd = tr.xddot()
    for i, name in enumerate(tr.body_names):
        b = mech.bodies[name]
        th, w, al = tr.x[:, 3 * i + 2], tr.xdot[:, 3 * i + 2], xdd[:, 3 * i + 2]
        cx = np.cos(th) * b.com[0] - np.sin(th) * b.com[1]
        cy = np.sin(th) * b.com[0] + np.cos(th) * b.com[1]
        ax = xdd[:, 3 * i] - al * cy - w**2 * cx
        ay = xdd[:, 3 * i + 1] + al * cx - w**2 * cy
        dp += b.mass * np.column_stack([ax, ay])
    ff = floor_forces(tr, f)
    assert np.max(np.abs(dp + ff.floor[:, :2])) < 1e-6 * M_ROTOR * ECC * SPEED**2


def test_static_sag_is_weight_over_stiffness():
    f = base(mass=490.0, k=1e5, c=3000.0)
    mech = unbalance(gravity=(0.0, -9.81), ecc=0.0, drive=False)
    mm = mounted(mech, f)
    sag = -(f.mass + M_ROTOR) * 9.81 / (2 * 1e5)
    q = mm.extras["initial"]["q"]
    # the isolators are linear in the base's displacement: no geometric error
    assert q["base_y"] == pytest.approx(sag, rel=1e-12)
    assert abs(q["base_x"]) < 1e-15 and abs(q["base_theta"]) < 1e-15
    tr = mechdyn.simulate(mm, 0.2, rtol=1e-10, progress=False)
    assert np.max(np.abs(tr.coordinate("base_y") / sag - 1)) < 1e-6  # it stays there


def test_heavy_base_agrees_with_the_one_way_prediction():
    """On a heavy base (50 t) the base hardly moves and the machine runs as on a rigid
    frame: the coupled floor force is the one-way linear prediction."""
    f = base(mass=5e4, k=1e7, c=1e5)
    c = compare_mounting(unbalance(), f, 1.0, samples=2001, rtol=1e-10, progress=False)
    dyn = c.one_way.floor[:, :2] - c.one_way.floor[0, :2]
    diff = c.coupled.floor[:, :2] - c.one_way.floor[:, :2]
    assert np.max(np.abs(diff)) < 2e-3 * np.max(np.abs(dyn))
    s = c.statistics()
    assert s["coupled"]["peak_N"] == pytest.approx(s["one_way"]["peak_N"], rel=1e-3)
    assert "coupled" in c.summary() and "Fy_floor_N_coupled" in c.to_dataframe()


def test_a_force_whose_reaction_the_frame_carries():
    """A ram held up on its guide by a force from the frame (a spring pack): with its
    reaction on the base the floor carries the weights alone and the base stays at rest;
    the rigid frame's loads get the same reaction (rigid = weights)."""
    mech = Mechanism("held ram", gravity=(0.0, -9.81))
    mech.add_body("ram", mass=10.0, pose=(0.0, 0.2, 0.0))
    mech.add_prismatic("guide", "ground", "ram", (0.0, 0.0), axis=(0.0, 1.0))
    mech.add_coordinate("s", kind="travel", joint="guide")
    mech.add(Force("pack", "ram", "com", 10.0 * 9.81, (0.0, 1.0)))
    f = base(mass=490.0, k=1e5, c=3000.0)
    weight = 500.0 * 9.81
    mm = mounted(mech, f, reacting=("pack",))
    tr = mechdyn.simulate(mm, 0.2, rtol=1e-10, progress=False)
    assert np.max(np.abs(tr.coordinate("base_y") / (-weight / 2e5) - 1)) < 1e-6
    c = compare_mounting(mech, f, 0.2, samples=21, reacting=("pack",), rtol=1e-10,
                         progress=False)
    np.testing.assert_allclose(c.rigid[:, 1], -weight, rtol=1e-9)
    np.testing.assert_allclose(c.coupled.floor[:, 1], -weight, rtol=1e-6)
    with pytest.raises(ModelError, match="unknown force load 'pak'"):
        mounted(mech, f, reacting=("pak",))
