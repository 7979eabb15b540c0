"""One batch of variants, evaluated in order (in this process or on a worker): each
variant built from the model file, analysed, and turned into one table row; a variant
that fails is a row with its status and message."""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import AssemblyError, MechdynError, SingularPositionError, Status
from .parameters import BaseModel, Parameter, to_shown

__all__ = ["Task", "evaluate_batch", "evaluate_variant", "order_variants", "failure"]


@dataclass(frozen=True)
class Task:
    """What every batch of a study shares: the model file, the varied parameters (in
    the order of the variants' values) and the analysis."""

    base: BaseModel
    parameters: tuple[Parameter, ...]
    analysis: object


def failure(exc: BaseException) -> tuple[str, str]:
    """(status, message) of an exception that ended a variant.

    Examples
    --------
    >>> failure(AssemblyError("the loop through joints 'A', 'B' does not close"))[0]
    'assembly-failed'
    """
    if isinstance(exc, AssemblyError) or "cannot be assembled" in str(exc):
        return Status.ASSEMBLY_FAILED.value, str(exc)
    if isinstance(exc, SingularPositionError):
        return Status.SINGULAR_POSITION.value, str(exc)
    if isinstance(exc, MechdynError):
        return Status.FAILED.value, str(exc)
    return Status.FAILED.value, f"{type(exc).__name__}: {exc}"


def evaluate_batch(task: Task, batch: list[tuple[int, tuple[float, ...]]],
                   warm=None) -> list[dict]:
    """Rows of a batch of variants, evaluated in order, each started from the last
    successful one's ``warm`` state.

    Parameters
    ----------
    task : Task
    batch : list of (int, tuple of float)
        Variant id and its parameter values (SI, in the order of ``task.parameters``).
    warm : object, optional
        Start state of the first variant (see :class:`~.analyses.Outcome`).

    Returns
    -------
    list of dict
        One row per variant: ``variant``, the parameters (columns with their units,
        angles in deg), the analysis' figures, ``status``, ``message`` and
        ``seconds`` (wall time of the variant).

    Examples
    --------
    >>> from mechdyn.study.analyses import KinetostaticExtremes
    >>> base = BaseModel("slider_crank")
    >>> task = Task(base, (base.parameter("bodies.rod.points.B.x"),),
    ...             KinetostaticExtremes("1000 rpm", steps=24))
    >>> rows = evaluate_batch(task, [(0, (0.16,)), (1, (0.01,))])
    >>> [r["status"] for r in rows]
    ['success', 'assembly-failed']
    """
    rows = []
    for vid, values in batch:
        row, warm = evaluate_variant(task, vid, values, warm)
        rows.append(row)
    return rows


def evaluate_variant(task: Task, vid: int, values: tuple[float, ...], warm=None):
    """(row, warm) of one variant (see :func:`evaluate_batch`); ``warm`` is passed on
    unchanged when the variant fails."""
    t0 = time.perf_counter()
    row: dict = {"variant": int(vid)}
    for p, v in zip(task.parameters, values, strict=True):
        row[p.column] = to_shown(v, p.kind)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the record's status and message say it
            model = task.base.compile(dict(zip(task.parameters, values, strict=True)))
            outcome = task.analysis(model, warm)
        row.update(outcome.figures)
        row["status"], row["message"] = outcome.status, outcome.message
        if outcome.warm is not None:
            warm = outcome.warm
    except Exception as exc:  # noqa: BLE001 - a failed variant is a row, not the end
        row["status"], row["message"] = failure(exc)
    row["seconds"] = time.perf_counter() - t0
    return row, warm


def order_variants(values: np.ndarray) -> np.ndarray:
    """An order of the variants in which each is near the one before (greedy nearest
    neighbour in the parameters scaled to their ranges), so that warm starts are short.

    Parameters
    ----------
    values : ndarray, shape (n, d)

    Returns
    -------
    ndarray of int, shape (n,)
        A permutation of ``range(n)`` starting at 0.

    Examples
    --------
    >>> order_variants(np.array([[0.0], [1.0], [0.1], [0.9]])).tolist()
    [0, 2, 3, 1]
    """
    v = np.asarray(values, float)
    n = len(v)
    if n == 0:
        return np.zeros(0, int)
    span = np.ptp(v, axis=0)
    u = (v - v.min(axis=0)) / np.where(span > 0, span, 1.0)
    left = np.ones(n, bool)
    order = np.empty(n, int)
    i = 0
    for k in range(n):
        order[k] = i
        left[i] = False
        if k + 1 < n:
            d = np.sum((u - u[i]) ** 2, axis=1)
            d[~left] = np.inf
            i = int(np.argmin(d))
    return order
