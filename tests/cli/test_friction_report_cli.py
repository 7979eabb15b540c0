"""``mechdyn report`` of the toggle press with friction in every pin and the ram guide
(issue 12 acceptance): the torque, loss and efficiency curves and the cycle-efficiency line
with the energies, checked against the friction-circle law and the energy balance."""

import re

import numpy as np
import pytest

import mechdyn
from mechdyn.cli import main
from mechdyn.results.plot import plot_kinetostatics
from mechdyn.results.report_figures import kinetostatics_figure


@pytest.fixture(scope="module")
def press():
    model = mechdyn.examples.load("toggle_press_friction").compile()
    values = np.linspace(0.5 * np.pi, 2.5 * np.pi, 145)
    return mechdyn.kinetostatics(model, speed=40 * np.pi / 30, values=values)


def _pin_loss(ks, joint) -> np.ndarray:
    """The friction-circle law, written here: mu r |R| |omega_child - omega_parent|, W."""
    mech = ks.model.mechanism
    j = mech.joints[joint]
    names = ks.model.body_names

    def omega(body):
        return 0.0 if body == "ground" else ks.xdot[:, 3 * names.index(body) + 2]

    R = ks.reactions[joint]
    return j.friction * j.pin_radius * np.hypot(R[:, 0], R[:, 1]) * np.abs(
        omega(j.child) - omega(j.parent))


def test_report_figure_has_the_losses_per_pair_and_the_efficiency(press):
    fig = kinetostatics_figure(press)
    titles = [a.title.text for a in (fig.layout.yaxis, fig.layout.yaxis2, fig.layout.yaxis3,
                                     fig.layout.yaxis4)]
    assert titles == ["torque (N m)", "force (kN)", "power lost (W)", "efficiency (%)"]
    assert fig.layout.xaxis4.title.text == "phi (deg)"
    traces = {tr.name: tr for tr in fig.data}
    assert {f"P lost {j}" for j in "ABCDEF"} | {"P lost slide", "η"} <= set(traces)
    x = np.rad2deg(press.values)
    for j in "ABCDEF":  # the curve drawn is the law's power
        tr = traces[f"P lost {j}"]
        np.testing.assert_allclose(tr.x, x, rtol=1e-12)
        np.testing.assert_allclose(tr.y, _pin_loss(press, j), rtol=1e-9,
                                   atol=1e-9 * press.power_loss.max())
    eta = traces["η"].y
    p_in = press.driving_total_power
    ok = p_in > 0
    np.testing.assert_allclose(eta[ok], 100 * press.power_out[ok] / p_in[ok], rtol=1e-12)


def test_matplotlib_plot_has_the_friction_panel(press):
    fig = plot_kinetostatics(press, None)
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert "power lost by friction (W)" in labels and "efficiency (%)" in labels
    assert fig.axes[3].get_xlabel() == "phi (deg)"
    ax = next(ax for ax in fig.axes if ax.get_ylabel() == "power lost by friction (W)")
    assert {f"P lost {j} (W)" for j in "ABCDEF"} <= {ln.get_label() for ln in ax.lines}


def test_report_states_cycle_efficiency_and_energies(tmp_path, capsys):
    html = tmp_path / "press.html"
    rc = main(["report", "toggle_press_friction", "--steps", "145", "--no-animation",
               "-o", str(html)])
    assert rc == 0, capsys.readouterr().err
    text = html.read_text(encoding="utf-8")
    m = re.search(r"cycle efficiency ([0-9.]+) \(([0-9.]+) %\); energy in ([0-9.]+) J, out "
                  r"([0-9.]+) J, lost ([0-9.]+) J", text)
    assert m, "the friction summary line"
    eta, pct, e_in, e_out, e_lost = map(float, m.groups())
    # energy balance over a cycle at constant speed: in = out + lost (kinetic and
    # potential energy come back), to the trapezoidal rule's accuracy
    assert e_in == pytest.approx(e_out + e_lost, rel=2e-3)
    assert eta == pytest.approx(e_out / e_in, rel=2e-3) and pct == pytest.approx(100 * eta,
                                                                                 rel=2e-3)
    rows = text.split("<h3>Friction losses per pair</h3>", 1)[1].split("</table>", 1)[0]
    pairs = re.findall(r"<tr><td>([A-Za-z]+)</td>\s*<td[^>]*>(revolute|prismatic)</td>\s*"
                       r"<td>([0-9.e+-]+)</td>", rows)
    assert [p[0] for p in pairs] == ["A", "B", "C", "D", "E", "F", "slide"]
    assert sum(float(p[2]) for p in pairs) == pytest.approx(e_lost, rel=1e-3)
    joints = text.split("<h3>Joints</h3>", 1)[1].split("</table>", 1)[0]
    assert "<th>friction mu</th>" in joints and "<th>pin radius / guide length (mm)</th>" in joints
    for label in ("power lost (W)", "efficiency (%)", "torque (N m)"):
        assert label in text  # the axes of the interactive figure
