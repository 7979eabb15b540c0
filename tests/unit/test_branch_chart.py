"""Branch charts: none at a dead position, where they apply, and the examples of the new
modules (the branch kept through crossings: tests/physics/test_change_point.py and
test_parallelogram.py)."""

import doctest

import numpy as np
import pytest
from test_sweep import A_, B_, five_bar, four_bar, rocker_limit

from mechdyn.dynamics import lagrange
from mechdyn.dynamics.lagrange import BranchEquations
from mechdyn.kinematics import branch_chart
from mechdyn.kinematics.branch_chart import ChartBook, PathProblem, bridge
from mechdyn.kinematics.sweep import sweep


def test_no_chart_at_a_dead_position():
    # driven from the rocker, a four-bar cannot go beyond the rocker's extreme angle
    model = four_bar(drive="psi").compile()
    psi0 = model.x0[3 * model.body_index("rocker") + 2]
    limit = rocker_limit(B_ - A_)  # crank and coupler folded
    path = PathProblem(model, model.layout(), [0], [psi0], 0)
    assert bridge(path, path.node(psi0, model.x0), limit) is None
    book = ChartBook(path)
    assert book.watch(psi0, model.x0, force_at=limit) is None
    assert book.charts == [] and book.skipped
    sw = sweep(model, values=psi0 + np.linspace(0.0, 1.5, 151))
    assert sw.status == "singular-position" and sw.stats["bifurcations"] == []


def test_charts_only_for_one_coordinate_and_exact_analogs():
    eom = BranchEquations(four_bar().compile(), "analogs", backend="numpy")
    assert eom.book is None
    assert BranchEquations(five_bar().compile(), backend="numpy").book is None  # 2 DOF


@pytest.mark.parametrize("module", [branch_chart, lagrange])
def test_examples_run(module):
    failures, tried = doctest.testmod(module)
    assert tried and not failures
