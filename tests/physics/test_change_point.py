"""A change-point four-bar (a + b = c + d) driven by its crank through the position where
all bars are in line: its two assembly branches cross there.  The sweep keeps the
branch that continues smoothly (from one side of the line B-D to the other), not the
one that keeps the sign of det [Phi_x; g_x]; the chart of the crossing matches direct
solves where those are well conditioned.  Oracle: Freudenstein's closed form
(tests/physics/test_four_bar.py), whose two roots swap at the crossing."""

import numpy as np
import pytest
from test_four_bar import four_bar, freudenstein, wrap

from mechdyn.kinematics.branch_chart import ChartBook, PathProblem
from mechdyn.kinematics.sweep import sweep

LENGTHS = {"a": 0.02, "b": 0.05, "c": 0.03, "d": 0.04}  # 0.02 + 0.05 = 0.03 + 0.04


@pytest.mark.parametrize("crossed", [False, True], ids=["open", "crossed"])
def test_the_sweep_keeps_the_smooth_branch_through_the_crossing(crossed):
    values = np.linspace(1.0, -1.0, 401)  # phi = 0, the crossing, is a sample
    sw = sweep(four_bar(**LENGTHS, crossed=crossed), values=values)
    assert sw.status == "success" and len(sw) == 401
    assert [b["kind"] for b in sw.stats["bifurcations"]] == ["bifurcation"]
    psi = sw.angular("rocker")[0]
    with np.errstate(invalid="ignore"):  # at the crossing the discriminant is 0 +- eps
        plus, minus = freudenstein(values, **LENGTHS)
    known = np.isfinite(plus)
    assert np.sum(~known) <= 1
    on_plus = np.abs(wrap(psi - plus)) < 1e-9
    on_minus = np.abs(wrap(psi - minus)) < 1e-9
    assert np.all((on_plus | on_minus)[known])  # a closed-form root everywhere ...
    before, after = values > 0.05, values < -0.05
    # ... and the other root after the crossing: the smooth continuation
    assert on_plus[before].all() and on_minus[after].all() or \
        on_minus[before].all() and on_plus[after].all()
    # no kink at the crossing: second differences as small as elsewhere
    d2 = np.abs(np.diff(psi, 2))
    k = int(np.argmin(np.abs(values)))
    assert np.max(d2[k - 5:k + 5]) < 2 * np.max(d2[:k - 20])


def test_the_chart_matches_direct_solves_outside_its_zone():
    model = four_bar(**LENGTHS).compile()
    path = PathProblem(model, model.layout(), [0], [1.0], 0)
    book = ChartBook(path)
    chart, x = None, model.x0
    for s in np.linspace(1.0, 0.2, 9):
        x = path.solve(s, x).x
        chart = chart or book.watch(s, x)
    assert chart is not None and chart.kind == "bifurcation"
    assert chart.signs[0] != chart.signs[1] and abs(chart.centre) < 0.03
    L = model.length_scale
    for s in (chart.centre + 0.2, chart.centre - 0.2):
        xc, xs, xss = chart.evaluate(s)
        direct = path.solve(s, xc)
        assert np.max(np.abs((direct.x - xc) * path.scale)) < 1e-12 * L
        assert np.max(np.abs((direct.xs - xs) * path.scale)) < 1e-10 * L
        assert np.max(np.abs((direct.xss - xss) * path.scale)) < 1e-8 * L
    X, XS, XSS = chart.evaluate(np.array([-0.1, 0.0, 0.1]))
    assert X.shape == XS.shape == XSS.shape == (3, model.n_x)
