"""Tabulated load values: periodic tables and pulses against the closed form of the
wrapped function, one position and a batch, and the checks of a bad period."""

import math

import numpy as np
import pytest

import mechdyn as md
from mechdyn.mechanism import Force, Table, Torque
from mechdyn.mechanism.load import pulse
from mechdyn.model.forces import LoadContext, evaluate

TWO_PI = 2 * math.pi


def triangle(s):
    """Closed form of the triangle wave 0 -> 1 -> 0 over every [0, 2 pi)."""
    u = np.mod(s, TWO_PI)
    return 1.0 - np.abs(u - math.pi) / math.pi


def gapped(s, outside):
    """Closed form of Table((1, 2, 3), (0, 2, 0), period=5): a hat on [1, 3] of every
    period, ``outside`` on (3, 6)."""
    u = np.mod(np.asarray(s) - 1.0, 5.0)
    return np.where(u <= 2.0, 2.0 - 2.0 * np.abs(u - 1.0), outside)


S = np.concatenate([np.linspace(-20.0, 20.0, 4001), [0.0, TWO_PI, -TWO_PI, 4 * TWO_PI,
                                                     1.0, 3.0, 6.0, -4.0, 3.0 + 5e-13]])


def test_periodic_table_is_the_wrapped_function():
    tri = Table((0.0, math.pi, TWO_PI), (0.0, 1.0, 0.0), "phi", period=TWO_PI)
    np.testing.assert_allclose(tri(S), triangle(S), atol=1e-12)
    for s in S[::97]:  # one value at a time: a float
        v = tri(float(s))
        assert isinstance(v, float) and v == pytest.approx(triangle(s), abs=1e-12)
    hat = Table((1.0, 2.0, 3.0), (0.0, 2.0, 0.0), "t", outside=-1.0, period=5.0)
    np.testing.assert_allclose(hat(S), gapped(S, -1.0), atol=1e-12)
    held = Table((1.0, 2.0, 3.0), (0.5, 2.0, 0.25), "t", period=5.0)  # holds y[-1] on (3, 6)
    assert held(4.5) == 0.25 and held(-0.5) == 0.25 and held(6.0) == 0.5
    assert held(1.5 + 5.0e3) == pytest.approx(1.25, abs=1e-9)
    # not periodic: held or outside beyond the ends, as before
    plain = Table((1.0, 2.0, 3.0), (0.0, 2.0, 0.0), "t", outside=-1.0)
    assert plain.period is None and plain(6.5) == -1.0 and plain(1.5) == 1.0


def test_periodic_pulse_repeats_every_period():
    p = pulse(7.5, math.radians(120.0), math.radians(30.0), "phi", period=TWO_PI)
    assert p.period == TWO_PI
    for k in (-3, 0, 1, 25):
        assert p(math.radians(135.0) + k * TWO_PI) == 7.5
        assert p(math.radians(100.0) + k * TWO_PI) == 0.0
        assert p(math.radians(200.0) + k * TWO_PI) == 0.0
    ramped = pulse(2.0, 1.0, 2.0, "t", ramp=0.5, period=4.0)
    np.testing.assert_allclose(ramped(np.array([0.75, 2.0, 3.25, 4.1, 4.75, 6.0, 7.25])),
                               [1.0, 2.0, 1.0, 0.0, 1.0, 2.0, 1.0], atol=1e-12)
    # a rectangular pulse may fill all but a sliver of its period
    full = pulse(1.0, 0.0, 1.0, "t", period=1.0 + 1e-9)
    assert full(0.5) == 1.0 and full(3.5) == 1.0


@pytest.mark.parametrize("period, match", [
    (0.0, r"table over 'phi': period must be finite and > 0"),
    (-TWO_PI, r"table over 'phi': period must be finite and > 0"),
    (math.inf, r"table over 'phi': period must be finite and > 0"),
    (math.pi, r"table over 'phi': period 3\.14.* shorter than the table's span"),
    ("360 deg", r"table over 'phi': period must be a number"),
])
def test_bad_period_is_a_clear_error(period, match):
    with pytest.raises(ValueError, match=match):
        Table((0.0, math.pi, TWO_PI), (0.0, 1.0, 0.0), "phi", period=period)


def test_bad_pulse_period_is_a_clear_error():
    with pytest.raises(ValueError, match=r"pulse over 'psi': period must be > duration"):
        pulse(1.0, 0.0, 1.0, "psi", period=1.0)
    with pytest.raises(ValueError, match=r"pulse over 't': period must be > duration and "
                                         r">= duration \+ 2 ramp = 2\.0"):
        pulse(1.0, 0.0, 1.0, "t", ramp=0.5, period=1.5)


def rotor():
    mech = md.Mechanism("rotor", gravity=(0.0, 0.0))
    mech.add_body("disc", mass=1.5, inertia=0.02, com=(0.2, 0.0), points={"P": (0.3, 0.0)})
    mech.add_revolute("O", "ground", "disc")
    mech.add_coordinate("phi", "angle", body="disc")
    return mech


@pytest.mark.parametrize("variable, closed", [
    ("phi", lambda t, q, qd, x: q[..., 0]),
    ("phi_dot", lambda t, q, qd, x: qd[..., 0]),
    ("t", lambda t, q, qd, x: t),
    ("disc.P.x", lambda t, q, qd, x: 0.3 * np.cos(x[..., 2])),
])
def test_periodic_tables_through_the_load_evaluator_batched_and_pointwise(variable, closed):
    model = rotor().compile()
    rng = np.random.default_rng(3)
    n = 200
    t = rng.uniform(-30.0, 30.0, n)
    q = rng.uniform(-40.0, 40.0, (n, 1))
    qd = rng.uniform(-50.0, 50.0, (n, 1))
    x = np.zeros((n, 3))
    x[:, 2] = q[:, 0]
    xd = np.zeros((n, 3))
    xd[:, 2] = qd[:, 0]
    ctx = LoadContext(model, t, q, qd, x, xd)
    s = closed(t, q, qd, x)
    if variable == "disc.P.x":  # a length: a 0.1 m period over [-0.3, 0.3]
        tab = Table((-0.3, -0.275, -0.25), (0.0, 1.0, 0.0), variable, outside=0.5, period=0.1)
        u = np.mod(s + 0.3, 0.1)
        want = np.where(u <= 0.05, 1.0 - np.abs(u - 0.025) / 0.025, 0.5)
    else:
        tab = Table((0.0, math.pi, TWO_PI), (0.0, 1.0, 0.0), variable, period=TWO_PI)
        want = triangle(s)
    batched = evaluate(tab, ctx)
    assert batched.shape == (n,)
    np.testing.assert_allclose(batched, want, atol=1e-9)
    pointwise = np.array([evaluate(tab, ctx.at((k,))) for k in range(n)])
    np.testing.assert_array_equal(pointwise, batched)


def test_periodic_table_in_a_simulation_matches_the_compiled_kernel():
    from mechdyn.dynamics.lagrange import EquationsOfMotion

    mech = rotor()
    mech.add(Torque("cam", "disc", Table((0.5, 2.0, 3.0), (0.0, -4.0, 1.0), "phi",
                                         outside=0.25, period=TWO_PI)))
    mech.add(Force("tick", "disc", "P", pulse(3.0, 0.01, 0.02, "t", ramp=0.005, period=0.1),
                   direction=(0.0, 1.0), frame="body"))
    model = mech.compile()
    fast = EquationsOfMotion(model)
    if fast.backend != "numba":
        pytest.skip(f"compiled backend not available: {fast.backend_note}")
    slow = EquationsOfMotion(model, backend="numpy")
    J = 0.02 + 1.5 * 0.2**2
    for t, phi in ((0.0, 1.0), (0.125, 1.0 + 7 * TWO_PI), (0.37, -2.0), (-0.2, 5.9),
                   (1.0, -3 * TWO_PI + 2.5)):
        q, qd = np.array([phi]), np.array([3.0])
        a1, _ = fast.rhs(t, q, qd)
        a2, _ = slow.rhs(t, q, qd)
        np.testing.assert_allclose(a1, a2, rtol=1e-12, atol=1e-12)
        u = (phi - 0.5) % TWO_PI + 0.5
        cam = (np.interp(u, (0.5, 2.0, 3.0), (0.0, -4.0, 1.0)) if u <= 3.0 else 0.25)
        w = (t - 0.005) % 0.1 + 0.005
        tick = 3.0 * np.clip(min((w - 0.005) / 0.005, (0.035 - w) / 0.005), 0.0, 1.0)
        assert a2[0] == pytest.approx((cam + 0.3 * tick) / J, abs=1e-9)


def test_every_column_of_a_reduction_table_has_its_unit():
    import mechdyn
    from mechdyn.reduction.reduce import reduce_model
    from mechdyn.results.table import unit_of_column

    red = reduce_model(mechdyn.examples.load("slider_crank").compile(), steps=5)
    units = {c: unit_of_column(c) for c in red.to_dataframe().columns}
    assert units["J_red_kgm2"] == units["dJ_red_dphi_kgm2"] == "kg*m^2"
    assert all(units.values()), units
