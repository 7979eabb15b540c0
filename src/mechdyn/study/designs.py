"""Designs of a study: ranges of parameters with units, sampled on a grid, at random or
by a Latin hypercube (:mod:`scipy.stats.qmc`), seeded."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..units import parse_quantity
from .parameters import BaseModel, Parameter

__all__ = ["Range", "parse_range", "design", "DESIGNS"]

#: the designs :func:`design` knows
DESIGNS = ("grid", "random", "lhs")


@dataclass(frozen=True)
class Range:
    """A parameter and the interval it is varied over.

    Attributes
    ----------
    parameter : Parameter
    low, high : float
        Ends of the interval, SI unit of the parameter's kind (m, kg, rad ...).
    """

    parameter: Parameter
    low: float
    high: float


def parse_range(base: BaseModel, spec: str) -> Range:
    """A range from ``KEY=LOW..HIGH`` text, e.g. ``"bodies.crank.points.A.x=40mm..60mm"``.

    Parameters
    ----------
    base : BaseModel
        The model the key belongs to (tells what the value measures).
    spec : str
        The model-file path, ``=``, and two values with units joined by ``..``.

    Returns
    -------
    Range
        Its ends in SI units.

    Raises
    ------
    ModelError
        Malformed text, an unknown key (the valid keys at that level are listed), a
        unit of the wrong dimension, or ends that are not finite.

    Examples
    --------
    >>> base = BaseModel("slider_crank")
    >>> r = parse_range(base, "bodies.crank.points.A.x=40mm..60mm")
    >>> r.parameter.kind, round(r.low, 6), round(r.high, 6)
    ('length', 0.04, 0.06)
    """
    key, sep, rng = str(spec).partition("=")
    low, dots, high = rng.partition("..")
    if not sep or not dots or not key.strip() or not low.strip() or not high.strip():
        raise ModelError(f"--vary {spec!r}: write KEY=LOW..HIGH, e.g. "
                         f"bodies.crank.points.A.x=40mm..60mm")
    p = base.parameter(key.strip(), low.strip())
    lo = parse_quantity(low.strip(), p.kind, where=f"--vary {key.strip()}")
    hi = parse_quantity(high.strip(), p.kind, where=f"--vary {key.strip()}")
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise ModelError(f"--vary {spec!r}: the ends must be finite")
    return Range(p, lo, hi)


def design(ranges: list[Range], samples: int, kind: str = "lhs", seed: int | None = None):
    """The variants of a study: one row per variant, one column per parameter (SI).

    Parameters
    ----------
    ranges : list of Range
    samples : int
        Number of variants; for ``"grid"`` the points per parameter are
        ``round(samples ** (1 / len(ranges)))`` (at least 2), so the grid has about
        ``samples`` variants.
    kind : {"grid", "random", "lhs"}
        Full-factorial grid (ends included), uniform random, or Latin hypercube
        (:class:`scipy.stats.qmc.LatinHypercube`).
    seed : int, optional
        Seed of the random and Latin-hypercube designs.

    Returns
    -------
    pandas.DataFrame, shape (n_variants, len(ranges))
        Columns: the parameters' :attr:`~mechdyn.study.parameters.Parameter.path`, in SI;
        ``df.attrs["parameters"]`` holds the :class:`Parameter` objects in column order.

    Raises
    ------
    ModelError
        An unknown design, no ranges, a parameter given twice, fewer than 1 sample.

    Examples
    --------
    >>> base = BaseModel("slider_crank")
    >>> r = parse_range(base, "bodies.rod.mass=1kg..2kg")
    >>> design([r], 3, "grid")["bodies.rod.mass"].tolist()
    [1.0, 1.5, 2.0]
    >>> len(design([r], 5, "lhs", seed=1))
    5
    """
    import pandas as pd

    if kind not in DESIGNS:
        raise ModelError(f"unknown design {kind!r}; use one of {', '.join(DESIGNS)}")
    if not ranges:
        raise ModelError("a study needs at least one varied parameter")
    paths = [r.parameter.path for r in ranges]
    if len(set(paths)) != len(paths):
        raise ModelError(f"a parameter is varied twice: {', '.join(paths)}")
    if int(samples) < 1:
        raise ModelError(f"samples must be at least 1, got {samples}")
    d = len(ranges)
    if kind == "grid":
        per = max(2, int(round(samples ** (1.0 / d)))) if samples > 1 else 1
        axes = np.meshgrid(*[np.linspace(0.0, 1.0, per)] * d, indexing="ij")
        unit = np.stack([a.ravel() for a in axes], axis=1)
    elif kind == "random":
        unit = np.random.default_rng(seed).random((int(samples), d))
    else:
        from scipy.stats import qmc

        unit = qmc.LatinHypercube(d=d, seed=seed).random(int(samples))
    lo = np.array([r.low for r in ranges])
    hi = np.array([r.high for r in ranges])
    values = lo + unit * (hi - lo)
    df = pd.DataFrame(values, columns=paths)
    df.attrs["parameters"] = [r.parameter for r in ranges]
    return df
