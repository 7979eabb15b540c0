"""Optimisation over continuous parameters: minimise one figure of a study analysis
subject to bounds on others (a fixed stroke, a transmission angle of at least 40 deg)
and to assemblability, with :func:`scipy.optimize.minimize` or
:func:`scipy.optimize.differential_evolution`; every evaluation is a row of the same
table a study gives."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..brief import brief, number
from ..errors import ModelError, Status
from .analyses import check_figures
from .designs import Range
from .evaluate import Task, evaluate_variant
from .output import StudyOutput, order_columns
from .parameters import BaseModel

__all__ = ["Constraint", "Optimum", "optimise", "parse_constraint"]

_OK = (Status.SUCCESS.value, Status.REDUNDANT.value)


@dataclass(frozen=True)
class Constraint:
    """Bounds on a figure of the table, in the column's unit: ``low <= value <= high``
    (``low == high``: fixed).

    Examples
    --------
    >>> Constraint("stroke_cylinder_m", 0.1, 0.1).fixed
    True
    """

    column: str
    low: float | None = None
    high: float | None = None

    @property
    def fixed(self) -> bool:
        """True when the figure is held at one value."""
        return self.low is not None and self.low == self.high


def parse_constraint(text: str) -> Constraint:
    """A constraint from ``COLUMN>=VALUE``, ``COLUMN<=VALUE`` or ``COLUMN=VALUE`` (the
    value in the column's unit).

    Raises
    ------
    ModelError
        Other text.

    Examples
    --------
    >>> parse_constraint("mu_min_rod_rocker_deg>=40")
    Constraint(column='mu_min_rod_rocker_deg', low=40.0, high=None)
    """
    m = re.fullmatch(r"\s*([\w.]+)\s*(>=|<=|==|=)\s*([-+\d.eE]+)\s*", str(text))
    if m is None:
        raise ModelError(f"constraint {text!r}: write COLUMN>=VALUE, COLUMN<=VALUE or "
                         f"COLUMN=VALUE, e.g. stroke_cylinder_m=0.1")
    col, op, v = m.group(1), m.group(2), float(m.group(3))
    return Constraint(col, v if op != "<=" else None, v if op != ">=" else None)


@dataclass(repr=False)
class Optimum:
    """The result of :func:`optimise`.

    Attributes
    ----------
    values : dict of str to float
        The best feasible parameters by model-file path, SI.
    objective : float
        The objective there (its column's unit).
    row : dict
        The table row of the best evaluation.
    table : pandas.DataFrame
        Every evaluation, one row each (``variant`` = evaluation number), with
        ``objective`` and ``feasible``.
    success : bool
    message : str
        The optimiser's.
    """

    values: dict
    objective: float
    row: dict
    table: object
    success: bool
    message: str
    evaluations: int = field(default=0)

    def __repr__(self) -> str:
        at = ", ".join(f"{k} = {number(v)}" for k, v in list(self.values.items())[:3])
        return brief(self, f"objective {number(self.objective)}", at,
                     f"{self.evaluations} evaluations",
                     "converged" if self.success else "not converged")


class _Problem:
    """Parameters scaled to [0, 1] by their ranges; one evaluation per distinct point
    (the objective and the constraints share it), each started from the last poses."""

    def __init__(self, base, ranges, analysis, objective, constraints, output, ctol):
        self.task = Task(base, tuple(r.parameter for r in ranges), analysis)
        self.lo = np.array([r.low for r in ranges])
        self.span = np.array([r.high - r.low for r in ranges])
        self.objective, self.constraints = objective, list(constraints)
        self.rows: list[dict] = []
        self.points: list[np.ndarray] = []  # SI parameters of each evaluation
        self.cache: dict[tuple, dict] = {}
        self.warm = None
        self.out = output
        self.ctol = ctol

    def row(self, u) -> dict:
        key = tuple(np.round(np.asarray(u, float), 15))
        if key not in self.cache:
            x = self.lo + np.clip(key, 0.0, 1.0) * self.span
            r, self.warm = evaluate_variant(self.task, len(self.rows), tuple(x), self.warm)
            self.points.append(x)
            ok = r["status"] in _OK and np.isfinite(r.get(self.objective, np.nan))
            if ok and self.objective not in r:
                raise ModelError(f"the analysis gives no figure {self.objective!r}")
            r["objective"] = r.get(self.objective, np.nan)
            r["feasible"] = bool(ok and all(v >= -self.ctol for v in self.margins(r)))
            self.rows.append(r)
            self.cache[key] = r
            if self.out is not None:
                self.out.append([r])
        return self.cache[key]

    def margins(self, r) -> list[float]:
        """Each bound as ``>= 0`` when met, scaled by the bound (or 1)."""
        out = []
        for c in self.constraints:
            v = r.get(c.column, np.nan)
            if c.column not in r and r["status"] in _OK:
                raise ModelError(f"constraint on {c.column!r}: the analysis gives no such "
                                 f"figure; it gives {', '.join(sorted(r))}")
            for bound, sign in ((c.low, 1.0), (c.high, -1.0)):
                if bound is not None:
                    m = sign * (v - bound) / max(abs(bound), 1e-12)
                    out.append(float(m) if np.isfinite(m) else -1.0)
        return out

    def f(self, u) -> float:
        r = self.row(u)
        return float(r["objective"]) if r["status"] in _OK else 1e300

    def g(self, u) -> np.ndarray:
        r = self.row(u)
        return np.array(self.margins(r) if r["status"] in _OK else
                        [-1.0] * max(1, len(self.margins(r))))


def optimise(model, ranges: list[Range], analysis, objective: str, *,
             constraints: list[Constraint] = (), method: str = "cobyqa", start=None,
             seed: int | None = None, maxiter: int = 200, tol: float = 1e-6,
             popsize: int = 8, ctol: float = 1e-6,
             output: str | Path | None = None) -> Optimum:
    """Minimise a figure of an analysis over continuous parameters.

    Parameters
    ----------
    model : str, Path or BaseModel
    ranges : list of Range
        The parameters and their bounds (:func:`~mechdyn.study.designs.parse_range`).
    analysis : callable
        A study analysis (:mod:`mechdyn.study.analyses`).
    objective : str
        The column to minimise, e.g. ``"M_drive_phi_peak_Nm"``.
    constraints : list of Constraint
        Bounds on other columns; a variant that cannot be assembled (or stops at a dead
        position) is infeasible.
    method : str
        A method of :func:`scipy.optimize.minimize` that takes constraints and bounds
        (default ``"cobyqa"``, derivative-free; ``"cobyla"``, ``"slsqp"``), or
        ``"differential_evolution"`` (global; seeded by ``seed``).
    start : mapping or sequence of float, optional
        First point of a local method, SI (default the middle of the ranges).
    seed : int, optional
    maxiter : int
        Iterations (local: evaluations for the derivative-free methods; global:
        generations).
    tol : float
        Tolerance on the scaled parameters (local) or the relative spread of the
        population (global).
    popsize : int
        Population per parameter of differential evolution.
    ctol : float
        A constraint counts as met within this fraction of its bound (differential
        evolution meets a fixed figure only within a tolerance: give e.g. 1e-3).
    output : str or Path, optional
        Write every evaluation to this ``.csv``/``.parquet`` as it is made.

    Returns
    -------
    Optimum

    Raises
    ------
    ModelError
        No feasible evaluation, or an objective or constraint the analysis does not give.

    Examples
    --------
    >>> from mechdyn.study.analyses import KinetostaticExtremes
    >>> from mechdyn.study.designs import parse_range
    >>> base = BaseModel("slider_crank")
    >>> r = [parse_range(base, "bodies.crank.com.x=-40mm..20mm")]
    >>> best = optimise(base, r, KinetostaticExtremes("1000 rpm", steps=36),
    ...                 "M_drive_phi_peak_Nm", maxiter=30)
    >>> -0.03 < best.values["bodies.crank.com.x"] < 0.0
    True
    """
    from scipy import optimize

    base = model if isinstance(model, BaseModel) else BaseModel(model)
    names = {"objective": objective, **{f"constraints[{k}]": c.column
                                        for k, c in enumerate(constraints)}}
    check_figures(analysis, base.compile({}), names,  # before the first evaluation
                  [r.parameter.column for r in ranges])
    out = None if output is None else StudyOutput(output)
    if out is not None:
        out.clear()
    prob = _Problem(base, ranges, analysis, objective, constraints, out, ctol)
    d = len(ranges)
    bounds = optimize.Bounds(np.zeros(d), np.ones(d))
    try:
        if method == "differential_evolution":
            cons = optimize.NonlinearConstraint(prob.g, -ctol, np.inf) if constraints else ()
            res = optimize.differential_evolution(
                prob.f, bounds, constraints=cons, seed=seed, maxiter=maxiter, tol=tol,
                popsize=popsize, polish=False, init="latinhypercube")
        else:
            if start is None:
                u0 = np.full(d, 0.5)
            else:
                x0 = np.array([start[r.parameter.path] for r in ranges] if isinstance(
                    start, dict) else start, float)
                u0 = (x0 - prob.lo) / np.where(prob.span != 0, prob.span, 1.0)
            cons = [{"type": "ineq", "fun": prob.g}] if constraints else []
            opts = {"maxiter": maxiter} if method.lower() not in ("cobyqa", "cobyla") \
                else {"maxfev" if method.lower() == "cobyqa" else "maxiter": maxiter}
            res = optimize.minimize(prob.f, u0, method=method, bounds=bounds,
                                    constraints=cons, tol=tol, options=opts)
    finally:
        table = out.finish() if out is not None else None
    import pandas as pd

    if table is None:
        table = order_columns(pd.DataFrame(prob.rows))
    feasible = [r for r in prob.rows if r["feasible"]]
    if not feasible:
        raise ModelError(f"no feasible variant among {len(prob.rows)} evaluations "
                         f"(statuses: {', '.join(sorted({r['status'] for r in prob.rows}))})")
    best = min(feasible, key=lambda r: r["objective"])
    values = {p.path: float(x) for p, x in zip(prob.task.parameters,
                                               prob.points[best["variant"]], strict=True)}
    return Optimum(values, float(best["objective"]), best, table, bool(res.success),
                   str(res.message), len(prob.rows))
