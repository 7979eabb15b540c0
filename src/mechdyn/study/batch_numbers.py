"""The numbers of a batch of variants without compiling each one: the constraint rows,
sketch poses, masses, inertias and centres of mass of a compiled model are affine
functions of the model-file values a study varies (a point, a mass, a pose), so a few
compiled probes give every variant's.

The fit is checked, never assumed: compiled at a reference variant, at one step along
each parameter and at one more point inside the batch's box, the probes' numbers must
lie on one affine function (to :data:`_FIT_RTOL`); and each corner of the box is
compiled, so that the loader's value checks (a mass >= 0 ...), which hold on a box when
they hold at its corners, hold for every variant.  A variant whose sketch does not
assemble, or whose turn meets a dead position, leaves the batch at its first step
(:func:`~mechdyn.study.batch.kinetostatic_batch`) and is then compiled and analysed on
its own, which gives its status and message.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import Status
from .batch import Variants, batch_reason

__all__ = ["affine_variants"]

#: relative tolerance of the affine fit (of each array's largest entry)
_FIT_RTOL = 1e-12
#: the box's corners are compiled for up to this many varied parameters (beyond: no fit)
_MAX_CORNER_PARAMETERS = 4


def _numbers(model) -> dict:
    """The arrays of a compiled variant that the batch reads (see :class:`Variants`)."""
    return {"rows": model.layout().rowset.packed()[1],
            "coords": model.coordinate_rows.packed()[1], "x_start": model.x_sketch,
            "mass": model.mass, "inertia": model.inertia, "com": model.com}


def affine_variants(task, values, attempt) -> Variants | None:
    """The :class:`~mechdyn.study.batch.Variants` of parameter values (V, d) (SI, in
    the order of ``task.parameters``) from compiled probes, or None when they do not
    fit one affine function, a corner of the box fails a value check, the model has
    loads besides gravity, a body without a sketch pose or assembly modes, or the
    reference variant (the one nearest the middle of the box) does not compile.

    Parameters
    ----------
    task : Task
        The study's task (:class:`~mechdyn.study.evaluate.Task`): its parameters and
        analysis.
    values : array_like, shape (V, d)
        The parameter values of the V variants, SI (m, kg, kg m^2, rad ...).
    attempt : callable
        ``attempt(values)`` compiles one variant (values shape (d,)): its Model, or the
        (status, message) of its failure (:func:`~mechdyn.study.evaluate.attempt`).

    Returns
    -------
    Variants or None
        The stacked numbers of the V variants, from 2 + d' probes (d' the parameters
        that vary, at most 4) plus the corners of the box,
        not one compilation per variant; ``length_scale`` the smallest of the probes'.

    Examples
    --------
    >>> from mechdyn.study.analyses import KinetostaticExtremes
    >>> from mechdyn.study.evaluate import Task, attempt
    >>> from functools import partial
    >>> from mechdyn.study.parameters import BaseModel
    >>> base = BaseModel("slider_crank")
    >>> task = Task(base, (base.parameter("bodies.crank.points.A.x"),),
    ...             KinetostaticExtremes("1000 rpm"))
    >>> vs = affine_variants(task, np.array([[0.04], [0.05], [0.06]]), partial(attempt, task))
    >>> k = vs.base.layout().rowset.labels.index("A.x")   # a row of joint A
    >>> vs.rows[:, k, :2].round(12).tolist()   # its parent point: the crank's point A
    [[0.04, 0.0], [0.05, 0.0], [0.06, 0.0]]
    """
    values = np.asarray(values, float)
    lo, hi = values.min(axis=0), values.max(axis=0)
    # the reference: the variant nearest the middle of the box (likely to assemble)
    mid = np.abs((values - 0.5 * (lo + hi)) / np.where(hi > lo, hi - lo, 1.0)).max(axis=1)
    p0 = values[int(np.argmin(mid))]
    ref = attempt(p0)
    if isinstance(ref, tuple) or batch_reason(task.analysis, [ref]) is not None:
        return None
    if ref.mechanism.loads or not ref.pose_given.all() or ref.assembly_modes:
        return None
    var = np.flatnonzero(hi > lo)
    if var.size > _MAX_CORNER_PARAMETERS:
        return None
    for corner in itertools.product(*[(lo[i], hi[i]) for i in var]):
        p = p0.copy()
        p[var] = corner
        got = attempt(p)
        if isinstance(got, tuple) and got[0] != Status.ASSEMBLY_FAILED.value:
            return None  # a value check fails in the box: each variant says its own
    # probes near the reference (they assemble where it does), a quarter of the box away
    step = np.where(p0 - lo > hi - p0, lo - p0, hi - p0) / 4
    points = [p0 + np.eye(values.shape[1])[i] * step[i] for i in var]
    rng = np.random.default_rng(len(values))
    check = p0.copy()
    check[var] += step[var] * rng.uniform(0.2, 0.8, var.size)
    models = [ref]
    for p in [*points, check]:
        m = attempt(p)
        if isinstance(m, tuple) or np.any(m.gravity != ref.gravity):
            return None
        models.append(m)
    nums = [_numbers(m) for m in models]
    A = np.column_stack([np.ones(len(models)),
                         np.array([p0, *points, check])[:, var] - p0[var]])
    fit = {}
    for key in nums[0]:
        Y = np.stack([n[key].ravel() for n in nums])
        coef = np.linalg.lstsq(A[:-1], Y[:-1], rcond=None)[0]  # exact: square (1 + d)
        scale = max(float(np.abs(Y).max()), 1e-300)
        if np.abs(A[-1] @ coef - Y[-1]).max() > _FIT_RTOL * scale:
            return None  # not affine (a normalised axis, a derived offset ...)
        dv = values[:, var] - p0[var]
        fit[key] = (coef[0] + dv @ coef[1:]).reshape((len(values),) + nums[0][key].shape)
    L = min(m.length_scale for m in models)  # the Newton tolerance's scale
    return Variants(ref, fit["rows"], fit["coords"], fit["x_start"], fit["mass"],
                    fit["inertia"], fit["com"], np.full(len(values), L), None)
