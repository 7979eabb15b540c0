"""Choosing an integrator by name, and a small driver for plain ODEs.

``make_integrator("wilson", steps=40)`` builds an integrator from its name and
options (unknown names and misplaced options give errors naming them);
:func:`segment_integrators` the integrator of every segment of a run;
:func:`solve` runs one over [t0, t_end] with output times and events, the
integrate-level analogue of ``scipy.integrate.solve_ivp`` for q'' = f(t, q, q').
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from ..fieldmap import FieldMapping
from .base import (
    DEFAULT_RTOL,
    AdaptiveIntegrator,
    Integrator,
    IntegratorOptionError,
    IntegratorStats,
)
from .compiled_dop853 import DOP853
from .events import as_events
from .runge_kutta import RungeKutta4
from .scipy_ivp import SCIPY_METHODS, ScipyIntegrator
from .segment import arm, run_segment, user_event_functions, user_event_records
from .wilson import Wilson

__all__ = ["INTEGRATORS", "make_integrator", "segment_integrators", "solve", "Solution",
           "SolveStats", "sample_times"]

#: valid integrator names: "dop853" runs in the compiled loop where it can
#: (:mod:`mechdyn.integrate.compiled_dop853`), "scipy-dop853" is SciPy's everywhere
INTEGRATORS = ("wilson", "rk4", *SCIPY_METHODS, "scipy-dop853")
_WILSON_OPTIONS = ("iterations", "tol", "theta")
_ADAPTIVE_OPTIONS = ("first_step", "max_step")


def make_integrator(name: str | Integrator = "dop853", *, steps: int | None = None,
                    dt: float | None = None, rtol: float = DEFAULT_RTOL, atol=None,
                    **options) -> Integrator:
    """An integrator from its name and options.

    Parameters
    ----------
    name : str or Integrator
        One of :data:`INTEGRATORS` (case-insensitive), or an integrator instance
        (returned as is; then no other option may be given).
    steps, dt
        Number of steps or step size (s) of the fixed-step integrators ``wilson``, ``rk4``.
    rtol, atol
        Tolerances of the adaptive integrators; ignored by fixed-step ones.
    **options
        ``iterations``, ``tol``, ``theta`` for ``wilson``; ``first_step``, ``max_step``
        for the adaptive ones.

    Raises
    ------
    IntegratorOptionError
        Unknown name (the valid ones are listed), an option the integrator does not
        take, or a bad value.
    """
    if isinstance(name, Integrator):
        extra = [k for k, v in {"steps": steps, "dt": dt, **options}.items() if v is not None]
        if extra:
            raise IntegratorOptionError(
                f"options {', '.join(extra)} cannot be combined with an integrator instance "
                f"({name!r}); set them on the instance")
        return name
    if not isinstance(name, str) or name.lower() not in INTEGRATORS:
        raise IntegratorOptionError(
            f"unknown integrator {name!r}; valid integrator names: {', '.join(INTEGRATORS)}")
    key = name.lower()
    options = {k: v for k, v in options.items() if v is not None}
    if key in ("wilson", "rk4"):
        allowed = _WILSON_OPTIONS if key == "wilson" else ()
        bad = [k for k in options if k not in allowed]
        if bad:
            raise IntegratorOptionError(
                f"integrator {key!r} does not take option(s) {', '.join(bad)}; its options: "
                + ", ".join(("steps", "dt", *allowed)))
        return Wilson(steps, dt, **options) if key == "wilson" else RungeKutta4(steps, dt)
    given = [k for k, v in (("steps", steps), ("dt", dt)) if v is not None]
    bad = given + [k for k in options if k not in _ADAPTIVE_OPTIONS]
    if bad:
        raise IntegratorOptionError(
            f"integrator {key!r} is adaptive and does not take option(s) {', '.join(bad)}; "
            f"its options: rtol, atol, {', '.join(_ADAPTIVE_OPTIONS)} (fixed-step "
            f"integrators taking steps/dt: wilson, rk4)")
    if key == "dop853":
        return DOP853(rtol, atol, **options)
    integ = ScipyIntegrator(key.removeprefix("scipy-"), rtol, atol, **options)
    integ.name = key
    return integ


@dataclass(frozen=True)
class SolveStats(FieldMapping):
    """The counters of a :func:`solve` (also read as a mapping: ``stats["steps"]``).

    Attributes
    ----------
    integrator : str
        The integrator's name.
    steps : int
        Accepted steps.
    rejected : int
        Rejected steps (adaptive integrators).
    evaluations : int
        Right-hand-side evaluations f(t, q, qdot).

    Examples
    --------
    >>> s = SolveStats("rk4", steps=10, evaluations=41)
    >>> s.steps, s["evaluations"], list(s)
    (10, 41, ['integrator', 'steps', 'rejected', 'evaluations'])
    """

    integrator: str
    steps: int = 0
    rejected: int = 0
    evaluations: int = 0


@dataclass
class Solution:
    """Result of :func:`solve`: samples (time-major), events, counters
    (:class:`SolveStats`), status."""

    t: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    w: np.ndarray
    events: list = field(default_factory=list)
    stats: SolveStats = field(default_factory=lambda: SolveStats(""))
    status: str = "success"


def segment_integrators(method, t0: float, t_end: float, *, rtol, atol, dt, steps, iterations,
                         tol, theta, first_step, max_step):
    """``(factory, name)``: ``factory(scale, first) -> Integrator`` for a segment of a run.

    Every integrator of the package is allowed (:data:`mechdyn.integrate.INTEGRATORS` or an
    instance).  The fixed-step ones (``wilson``, ``rk4``) step on a grid of one ``dt``
    from the start of every segment, the last step shortened to the event; the
    adaptive ones get absolute tolerances per state, ``atol * scale`` for the
    coordinates (``scale``: 1 for angles, the length scale for travels), ten times that
    for their rates and ``1e3 atol`` for the work, and, after an event, a small first
    step ``first``.

    Raises
    ------
    IntegratorOptionError
        An unknown integrator or options that do not belong to it.
    """
    fixed = dict(dt=dt, steps=steps, iterations=iterations, tol=tol, theta=theta)
    compiled = True
    name = method.lower() if isinstance(method, str) else method  # make_integrator checks it
    if isinstance(method, Integrator):
        make_integrator(method, **fixed)  # refuses options beside an instance
        name = method.name
        if isinstance(method, AdaptiveIntegrator):
            rtol, atol = method.rtol, method.atol
            first_step = method.first_step if first_step is None else first_step
            max_step = method.max_step if max_step is None else max_step
        else:
            fixed.update(dt=method.dt, steps=method.steps,
                         **{k: getattr(method, k, None) for k in ("iterations", "tol", "theta")})
            compiled = getattr(method, "compiled", True)
    if name in ("wilson", "rk4"):
        # the same validation as a fixed-structure run (first_step, max_step are refused)
        make_integrator(name, first_step=first_step, max_step=max_step, **fixed)
        h = fixed["dt"] if fixed["dt"] is not None else (t_end - t0) / (fixed["steps"] or 100)
        opts = {k: fixed[k] for k in ("iterations", "tol", "theta") if name == "wilson"}

        def factory(scale, first):
            integ = make_integrator(name, dt=h, **opts)
            integ.compiled = compiled  # an instance's choice of the Python stepper is kept
            return integ

        return factory, f"{name} (dt={h:.6g} s)"
    make_integrator(name, rtol=rtol, atol=atol, first_step=first_step, max_step=max_step,
                    **fixed)  # validates the options (steps/dt are refused here)

    def factory(scale, first):
        sc = np.asarray(scale, float)
        return make_integrator(name, rtol=rtol,
                               atol=np.concatenate([atol * sc, atol * sc * 10, [atol * 1e3]]),
                               first_step=first_step if first_step is not None else first,
                               max_step=max_step)

    return factory, name


def sample_times(t0: float, t_end: float, t_eval) -> np.ndarray | None:
    """Validate output times: sorted, within [t0, t_end]."""
    if t_eval is None:
        return None
    te = np.asarray(t_eval, dtype=float).reshape(-1)
    if np.any(np.diff(te) < 0):
        raise IntegratorOptionError("`t_eval` must be sorted increasingly")
    if te.size and (te[0] < t0 - 1e-12 * max(1.0, abs(t0)) or te[-1] > t_end * (1 + 1e-12)
                    + 1e-15):
        raise IntegratorOptionError(f"`t_eval` must lie within [{t0:g}, {t_end:g}] s")
    return te


def solve(integrator: Integrator | str, f: Callable, t0: float, q0, qdot0, t_end: float, *,
          t_eval=None, events=None, w0=None, **options) -> Solution:
    """Integrate q'' = f(t, q, q') and collect samples (every step, or at ``t_eval``).

    Parameters
    ----------
    integrator : Integrator or str
    f : callable
        ``f(t, q, qdot) -> qddot`` (or ``(qddot, p)`` with ``w0``).
    t_eval : array_like, optional
        Output times (interpolated with the dense output); default every step.
    events : callable or list, optional
        Event functions ``g(t, q, qdot)`` (see :mod:`mechdyn.integrate.events`).
    **options
        Passed to :func:`make_integrator` when ``integrator`` is a name.
    """
    integ = make_integrator(integrator, **options)
    efns = user_event_functions(as_events(events))
    te = sample_times(t0, t_end, t_eval)
    q0 = np.asarray(q0, float).reshape(-1)
    v0 = np.asarray(qdot0, float).reshape(-1)
    n = q0.size
    wz = np.zeros(0) if w0 is None else np.asarray(w0, float).reshape(-1)
    out_t, out_y, out_a = [], [], []  # samples: t, y = (q, q', w), q''

    def rhs(t, q, v):
        r = f(t, q, v)
        if w0 is None:
            return np.asarray(r, float), np.zeros(0)
        return np.asarray(r[0], float), np.asarray(r[1], float).reshape(-1)

    def push(t, y, a=None):
        out_t.append(t)
        out_y.append(np.array(y, float))
        out_a.append(rhs(t, y[:n], y[n:2 * n])[0] if a is None else np.array(a))

    eqs = SimpleNamespace(rhs=rhs, first_order_function=lambda: None)
    y = np.concatenate([q0, v0, wz])
    if te is None:
        push(t0, y)
    else:
        for _ in range(int(np.sum(te <= t0))):
            push(t0, y)
        te = te[te > t0]
    counts = IntegratorStats()
    t, fresh, next_out, records, status = t0, set(), 0, [], "success"

    def coordinates(t_, y_):  # what the caller's event functions read
        return SimpleNamespace(q=y_[:n], qdot=y_[n:2 * n])

    while True:  # segments, restarted at each of the caller's events
        arm(efns, t, coordinates(t, y), fresh)
        hit, next_out = run_segment(
            integ, eqs, t, y, t_end, efns, evaluate=coordinates,
            after_step=lambda step, y_: None,
            sample=lambda ts, y_, step, ev: push(ts, y_, step.qddot if ts == step.t else None),
            t_eval=np.zeros(0) if te is None else te, next_out=next_out,
            every_step=te is None, stats=counts, n=n)
        if hit is None:
            break
        t, fired, dense = hit
        y = dense(t)
        records.extend(user_event_records(fired, t, y, n))
        fresh = {(e.kind, e.key) for e in fired}
        terminal = any(e.data.terminal for e in fired)
        if terminal or t >= t_end:
            status = "event" if terminal else "success"
            if te is None:
                push(t, y)
            break
    Y = np.array(out_y).reshape(len(out_t), -1)
    return Solution(np.array(out_t), Y[:, :n], Y[:, n:2 * n], np.array(out_a).reshape(-1, n),
                    Y[:, 2 * n:], records, SolveStats(integ.name, counts.steps, counts.rejected,
                                          counts.evaluations), status)
