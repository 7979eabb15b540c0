"""Redundant bilateral joints shared by their compliances (issue 12 item 5): a rigid bar
pinned at two points B1, B2 to a crank turning at constant speed, a load between the pins.

Closed form (written here): the pins' resultant on the bar is S = m a_G - m g - P (the bar
turns at constant speed, so its angular acceleration is zero and the pins' moment about G
vanishes).  With e along B1 -> B2 and n normal to it, the normal components follow from
the moments about G: b1 = S_n (L - d) / L, b2 = S_n d / L (statically determinate); the
components along the bar are indeterminate, a1 + a2 = S_e, and the pins of compliance c1,
c2 deflect alike along the rigid bar, c1 a1 = c2 a2 (springs in parallel):
a1 = S_e c2 / (c1 + c2), a2 = S_e c1 / (c1 + c2).
"""

import warnings

import numpy as np
import pytest

import mechdyn
from mechdyn.dynamics.reactions import KinetostaticsWarning
from mechdyn.errors import ModelError
from mechdyn.modelfile import loads

R1, L, D = 0.1, 0.2, 0.08            # crank pin B1 at R1; bar length L; its com at D from B1
M_BAR, G, W = 3.0, 9.81, 12.0        # kg, m/s^2, rad/s
P = np.array([480.0, -640.0])        # the load on the bar at its com, N
C1, C2 = 1e-9, 3e-9                  # m/N
PHI0 = 0.3


def _mm(*v) -> str:
    return "[" + ", ".join(f'"{x * 1e3} mm"' for x in v) + "]"


def _toml(c1: str | None = '"1e-9 m/N"', c2: str | None = '"3 um/kN"') -> str:
    """The model file, in inline tables; the pins' compliances as given (None: none)."""
    comp = [f", compliance = {c}" if c else "" for c in (c1, c2)]
    pose = _mm(R1 * np.cos(PHI0), R1 * np.sin(PHI0))[:-1] + f', "{PHI0} rad"]'
    crank = (f'{{ mass = "2 kg", inertia = "0.02 kg*m^2", com = {_mm(0.05, 0)}, pose = '
             f'["0 mm", "0 mm", "{PHI0} rad"], points = {{ B1 = {_mm(R1, 0)}, '
             f'B2 = {_mm(R1 + L, 0)} }} }}')
    bar = (f'{{ mass = "{M_BAR} kg", inertia = "0.01 kg*m^2", com = {_mm(D, 0)}, pose = '
           f'{pose}, points = {{ B1 = {_mm(0, 0)}, B2 = {_mm(L, 0)} }} }}')
    pin = '{ type = "revolute", parent = "crank", child = "bar", point = '
    return f"""
model = {{ name = "bar pinned twice to a crank", gravity = ["0 m/s^2", "-{G} m/s^2"] }}
[bodies]
crank = {crank}
bar = {bar}
[joints]
O = {{ type = "revolute", parent = "ground", child = "crank" }}
B1 = {pin}"B1"{comp[0]} }}
B2 = {pin}"B2"{comp[1]} }}
[coordinates]
phi = {{ kind = "angle", body = "crank" }}
[[loads]]
type = "force"
body = "bar"
magnitude = "{np.hypot(*P)} N"
direction = [{P[0]}, {P[1]}]
"""


def _run(text):
    model = loads(text, name="bar.toml").compile()
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        ks = mechdyn.kinetostatics(model, over="phi", speed=W,
                                   values=PHI0 + np.linspace(0.0, 2 * np.pi, 73))
    return ks, [str(w.message) for w in rec if issubclass(w.category, KinetostaticsWarning)]


def _closed_form(phi):
    e = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    n = np.stack([-np.sin(phi), np.cos(phi)], axis=-1)
    a_g = -W**2 * (R1 + D) * e                       # centripetal acceleration of G
    S = M_BAR * a_g - M_BAR * np.array([0.0, -G]) - P
    s_e, s_n = np.sum(S * e, -1), np.sum(S * n, -1)
    a1, a2 = s_e * C2 / (C1 + C2), s_e * C1 / (C1 + C2)
    b1, b2 = s_n * (L - D) / L, s_n * D / L
    return a1[:, None] * e + b1[:, None] * n, a2[:, None] * e + b2[:, None] * n


def test_pins_share_the_load_along_the_bar_by_their_compliances():
    ks, msgs = _run(_toml())
    R1_cf, R2_cf = _closed_form(ks.values)
    scale = np.abs(np.concatenate([R1_cf, R2_cf])).max()
    np.testing.assert_allclose(ks.reactions["B1"], R1_cf, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(ks.reactions["B2"], R2_cf, rtol=0, atol=1e-10 * scale)
    assert ks.status == "redundant" and ks.stats["redundant_shared_by"] == "compliance"
    assert any("shared by the joints' compliances" in m and "B1 1e-09 m/N" in m
               and "B2 3e-09 m/N" in m for m in msgs)
    # the minimum norm would have split the axial load evenly: not what is reported
    e = np.stack([np.cos(ks.values), np.sin(ks.values)], axis=-1)
    a1 = np.sum(ks.reactions["B1"] * e, -1)
    a2 = np.sum(ks.reactions["B2"] * e, -1)
    np.testing.assert_allclose(C1 * a1, C2 * a2, rtol=0, atol=1e-10 * scale * C2)


def test_without_every_compliance_the_minimum_norm_stays_and_says_why():
    ks, msgs = _run(_toml(c2=None))
    assert ks.stats["redundant_shared_by"] == "minimum norm"
    assert any("compliance of joint(s) 'B2' is not given" in m for m in msgs)
    e = np.stack([np.cos(ks.values), np.sin(ks.values)], axis=-1)
    a1 = np.sum(ks.reactions["B1"] * e, -1)
    a2 = np.sum(ks.reactions["B2"] * e, -1)
    np.testing.assert_allclose(a1, a2, rtol=1e-9, atol=1e-9)  # minimum norm: halves


def test_bad_compliance_names_the_joint_and_key():
    with pytest.raises(ModelError, match=r"joints.*B1.*compliance"):
        loads(_toml(c1='"2 kg"'), name="bar.toml")
    with pytest.raises(ModelError, match=r"compliance"):
        loads(_toml(c1='"-1e-9 m/N"'), name="bar.toml")
    m = mechdyn.Mechanism("m")
    m.add_body("a")
    m.add_revolute("O", "ground", "a", compliance=-1.0)
    assert any("compliance must be a finite number >= 0" in p for p in m.problems())
