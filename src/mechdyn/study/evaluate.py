"""One batch of variants, evaluated in order (in this process or on a worker): each
variant built from the model file, analysed, and turned into one table row; a variant
that fails is a row with its status and message."""

from __future__ import annotations

import functools
import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import AssemblyError, MechdynError, SingularPositionError, Status
from .batch import batch_reason, batched, kinetostatic_batch
from .batch_numbers import affine_variants
from .parameters import BaseModel, Parameter, to_shown

__all__ = ["Task", "evaluate_batch", "evaluate_variant", "order_variants", "failure", "head",
           "compiled", "analyse", "attempt"]


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
    """Rows of a batch of variants: as one batch (:mod:`.batch`) when the analysis and
    the variants allow it, else one by one in order, each started from the last
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
        angles in deg), the analysis' figures, ``status``, ``message``,
        ``evaluated`` ("batch" or "loop": how the variant was analysed) and
        ``seconds`` (wall time of the variant; of a batched variant, its share of the
        batch's).

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
    if len(batch) > 1 and batched(task.analysis):
        return _as_batch(task, batch, warm)
    rows = []
    for vid, values in batch:
        row, warm = evaluate_variant(task, vid, values, warm)
        rows.append(row)
    return rows


def _as_batch(task: Task, batch, warm=None) -> list[dict]:
    """:func:`evaluate_batch` through :func:`~.batch.kinetostatic_batch`: the variants'
    numbers from a few compiled probes (:func:`~.batch_numbers.affine_variants`), or
    else every variant compiled; analysed as one batch if :func:`~.batch.batch_reason`
    allows it.  The variants the batch leaves (and every variant otherwise) are
    compiled and analysed one by one."""
    t0 = time.perf_counter()
    rows = [head(task, vid, values) for vid, values in batch]
    values = np.array([v for _, v in batch], dtype=float)
    models: list = [None] * len(batch)
    outcomes: list = [None] * len(batch)
    variants = affine_variants(task, values, functools.partial(attempt, task))
    if variants is None:
        for k, v in enumerate(values):
            models[k] = attempt(task, v)
            if isinstance(models[k], tuple):
                rows[k]["status"], rows[k]["message"] = models[k]
                rows[k]["evaluated"] = "batch"
        good = [k for k, m in enumerate(models) if not isinstance(m, tuple)]
        if good and batch_reason(task.analysis, [models[k] for k in good]) is None:
            for k, o in zip(good, kinetostatic_batch([models[k] for k in good],
                                                     task.analysis), strict=True):
                outcomes[k] = o
    else:
        outcomes = kinetostatic_batch(variants, task.analysis)
    shared = (time.perf_counter() - t0) / len(batch)
    for k, outcome in enumerate(outcomes):
        row, t1 = rows[k], time.perf_counter()
        if outcome is not None:
            row.update(outcome.figures)
            row["status"], row["message"] = outcome.status, outcome.message
            row["evaluated"] = "batch"
        elif "status" not in row:  # on its own: its status and message, or its figures
            model = attempt(task, values[k]) if models[k] is None else models[k]
            if isinstance(model, tuple):
                row["status"], row["message"] = model
                row["evaluated"] = "loop"
            else:
                warm = analyse(task, row, model, warm)
        row["seconds"] = shared + time.perf_counter() - t1
    return rows


def attempt(task: Task, values):
    """The compiled model of a variant, or the (status, message) of its failure."""
    try:
        return compiled(task, tuple(float(v) for v in values))
    except Exception as exc:  # noqa: BLE001 - a failed variant is a row, not the end
        return failure(exc)


def head(task: Task, vid: int, values: tuple[float, ...]) -> dict:
    """The start of a variant's row: its id and its parameters (shown units)."""
    row: dict = {"variant": int(vid)}
    for p, v in zip(task.parameters, values, strict=True):
        row[p.column] = to_shown(v, p.kind)
    return row


def compiled(task: Task, values: tuple[float, ...]):
    """The compiled model of a variant (warnings silenced: the row's status says it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return task.base.compile(dict(zip(task.parameters, values, strict=True)))


def analyse(task: Task, row: dict, model, warm=None):
    """Fill ``row`` with the analysis of a compiled variant (its figures, status and
    message, ``evaluated`` = "loop"); returns the warm state for the next variant
    (``warm`` unchanged when the variant fails)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the record's status and message say it
            outcome = task.analysis(model, warm)
        row.update(outcome.figures)
        row["status"], row["message"] = outcome.status, outcome.message
        if outcome.warm is not None:
            warm = outcome.warm
    except Exception as exc:  # noqa: BLE001 - a failed variant is a row, not the end
        row["status"], row["message"] = failure(exc)
    row["evaluated"] = "loop"
    return warm


def evaluate_variant(task: Task, vid: int, values: tuple[float, ...], warm=None):
    """(row, warm) of one variant (see :func:`evaluate_batch`); ``warm`` is passed on
    unchanged when the variant fails."""
    t0 = time.perf_counter()
    row = head(task, vid, values)
    try:
        model = compiled(task, values)
    except Exception as exc:  # noqa: BLE001 - a failed variant is a row, not the end
        row["status"], row["message"] = failure(exc)
        row["evaluated"] = "loop"
    else:
        warm = analyse(task, row, model, warm)
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
