"""The integrator contract: advance q'' = f(t, q, q') and report each step.

An integrator holds *settings only*.  :meth:`Integrator.integrate` is a
generator: it yields one :class:`Step` per accepted step, each carrying the new
state, the acceleration there and a dense interpolant over the step, and keeps
counters in :attr:`Integrator.stats`.  It knows nothing of bodies; the caller
(``mechdyn.simulate``) re-solves positions, stores samples and stops when it
wants to.

The right-hand side ``f(t, q, qdot)`` returns ``qddot`` (shape (n,)), or, when
the integration carries ``n_w`` extra *quadrature* states ``w`` with
``w' = p(t, q, qdot)`` (e.g. the work of non-conservative forces), the pair
``(qddot, p)``.

How to write a new integrator:

1. subclass :class:`Integrator`, set ``name``, ``order`` and ``adaptive``;
2. validate every setting in ``__init__`` and raise ``ValueError`` naming it;
3. implement ``_steps(rhs, t0, q0, qdot0, w0, t_end)`` yielding :class:`Step`,
   calling ``rhs`` (which counts evaluations) and incrementing
   ``self.stats.steps`` / ``self.stats.rejected``; or, for a fixed-step method,
   subclass :class:`FixedStep` and implement ``_advance`` over one step; for an
   adaptive one, subclass :class:`AdaptiveIntegrator`, which holds and checks the
   tolerances and step bounds (``isinstance(integ, AdaptiveIntegrator)``: "adaptive").
"""

from __future__ import annotations

import copy
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from ..errors import MechdynError

__all__ = ["Integrator", "FixedStep", "AdaptiveIntegrator", "IntegratorStats", "Step",
           "hermite_dense", "check_positive", "IntegratorOptionError", "IntegratorWarning",
           "DEFAULT_RTOL", "first_order_function", "split_state"]


class IntegratorOptionError(MechdynError, ValueError):
    """A bad integrator option (the message names the option and the value)."""


#: default relative tolerance of every adaptive integration of the package
DEFAULT_RTOL = 1e-10


class IntegratorWarning(UserWarning):
    """An option that has no effect where it was given (the message names it)."""


def check_positive(name: str, value, *, integer: bool = False, allow_none: bool = False):
    """Validate a positive (integer) option; raise :class:`IntegratorOptionError` naming it."""
    if value is None and allow_none:
        return None
    kind = "a positive integer" if integer else "a positive number"
    try:
        v = int(value) if integer else float(value)
    except (TypeError, ValueError):
        raise IntegratorOptionError(f"`{name}` must be {kind}, got {value!r}") from None
    if integer and (isinstance(value, bool) or v != value):
        raise IntegratorOptionError(f"`{name}` must be {kind}, got {value!r}")
    if not (math.isfinite(v) and v > 0):
        raise IntegratorOptionError(f"`{name}` must be {kind}, got {value!r}")
    return v


@dataclass
class IntegratorStats:
    """Counters of one integration.

    Attributes
    ----------
    steps : int
        Accepted steps.
    rejected : int
        Rejected steps (adaptive integrators).
    evaluations : int
        Right-hand-side evaluations f(t, q, qdot).
    """

    steps: int = 0
    rejected: int = 0
    evaluations: int = 0


@dataclass
class Step:
    """One accepted step from ``t_old`` to ``t``.

    Attributes
    ----------
    t_old, t : float
        Start and end of the step, s.
    q, qdot, qddot : ndarray, shape (n,)
        State and acceleration at ``t``.
    w : ndarray, shape (n_w,)
        Quadrature states at ``t``.
    dense : callable
        ``dense(s)`` for ``t_old <= s <= t`` returns ``(q, qdot, w)`` at ``s``.
    """

    t_old: float
    t: float
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    w: np.ndarray
    dense: Callable = field(repr=False)


#: the quintic Hermite basis (value, slope and curvature at both ends) and the cubic one
#: (value and slope at both ends), as coefficients of 1, u, ..., u^5
_QUINTIC = np.array([[1, 0, 0, -10, 15, -6], [0, 1, 0, -6, 8, -3],
                     [0, 0, 0.5, -1.5, 1.5, -0.5], [0, 0, 0, 10, -15, 6],
                     [0, 0, 0, -4, 7, -3], [0, 0, 0, 0.5, -1, 0.5]])
_CUBIC = np.array([[1, 0, -3, 2], [0, 1, -2, 1], [0, 0, 3, -2], [0, 0, -1, 1]])


def hermite_dense(t0, q0, v0, a0, w0, p0, t1, q1, v1, a1, w1, p1):
    """Quintic Hermite interpolant of q (from q, q', q'' at both ends) and cubic of w.

    Returns a callable ``dense(s) -> (q, qdot, w)`` valid on [t0, t1]; local
    error O(h^6) in q, O(h^5) in qdot.
    """
    h = t1 - t0
    q0, v0, a0, q1, v1, a1, w0, p0, w1, p1 = (np.asarray(v, float) for v in (
        q0, v0, a0, q1, v1, a1, w0, p0, w1, p1))
    Y = np.array([q0, h * v0, h * h * a0, q1, h * v1, h * h * a1])  # in the unit step u
    W = np.array([w0, h * p0, w1, h * p1])

    def dense(s):
        if h == 0:
            return q1.copy(), v1.copy(), w1.copy()
        u = (s - t0) / h
        powers = u ** np.arange(6)
        slopes = np.arange(6) * np.concatenate([[0.0], powers[:5]])  # d/du of the powers
        return _QUINTIC @ powers @ Y, _QUINTIC @ slopes @ Y / h, _CUBIC @ powers[:4] @ W

    return dense


class Integrator(ABC):
    """Base class of the integrators of q'' = f(t, q, q').

    Subclasses hold settings only; :meth:`integrate` yields :class:`Step`
    records and fills :attr:`stats`.
    """

    #: short name used by ``simulate(integrator=...)`` and the CLI
    name: str = "?"
    #: global order of accuracy
    order: int = 0
    #: whether the step size is chosen from an error estimate
    adaptive: bool = False

    def __init__(self):
        self.stats = IntegratorStats()

    def settings(self) -> dict:
        """The settings of this integrator (for the run's stats)."""
        return {}

    def integrate(self, f: Callable, t0: float, q0, qdot0, t_end: float, *,
                  w0=None, first_order: Callable | None = None) -> Iterator[Step]:
        """Integrate from ``t0`` to ``t_end``, yielding every accepted step.

        Parameters
        ----------
        f : callable
            ``f(t, q, qdot) -> qddot`` or, with ``w0``, ``-> (qddot, p)``.
        t0, t_end : float
            Start and end times, s (``t_end >= t0``).
        q0, qdot0 : array_like, shape (n,)
            Initial coordinates and rates.
        w0 : array_like, shape (n_w,), optional
            Initial quadrature states (integrated as w' = p).
        first_order : callable, optional
            The same right-hand side as ``fun(t, y) -> y'`` for y = (q, q', w); an
            integrator that works on first-order systems may call it directly
            (it saves the Python glue of unpacking per evaluation).

        Yields
        ------
        Step
        """
        t0 = float(t0)
        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise IntegratorOptionError(f"`t_end` must be a number, got {t_end!r}") from None
        if not math.isfinite(t_end) or t_end < t0:
            raise IntegratorOptionError(
                f"`t_end` must be finite and >= t0 = {t0:g} s, got {t_end!r}")
        q0 = np.array(q0, dtype=float).reshape(-1)
        qdot0 = np.array(qdot0, dtype=float).reshape(-1)
        if qdot0.shape != q0.shape:
            raise IntegratorOptionError(f"`qdot0` must have the shape of `q0` {q0.shape}, "
                                        f"got {qdot0.shape}")
        has_w = w0 is not None
        w0 = np.zeros(0) if w0 is None else np.array(w0, dtype=float).reshape(-1)
        self.stats = IntegratorStats()
        stats = self.stats

        def rhs(t, q, qdot):
            stats.evaluations += 1
            out = f(t, q, qdot)
            if has_w:
                a, p = out
                return np.asarray(a, float), np.asarray(p, float).reshape(-1)
            return np.asarray(out, float), np.zeros(0)

        return self._steps(rhs, t0, q0, qdot0, w0, t_end, first_order)

    @abstractmethod
    def _steps(self, rhs, t0, q0, qdot0, w0, t_end, first_order=None) -> Iterator[Step]:
        """Yield the accepted steps (``rhs`` always returns ``(qddot, p)``)."""

    def __repr__(self) -> str:
        s = ", ".join(f"{k}={v!r}" for k, v in self.settings().items())
        return f"{type(self).__name__}({s})"


class FixedStep(Integrator):
    """Base class of the fixed-step integrators: ``steps`` equal steps over [t0, t_end]
    (default 100 when ``dt`` is not given), or steps of ``dt`` (s; the last one shortened
    to land on ``t_end``); ``compiled=False`` keeps the Python stepper where the compiled
    loop could run (see :attr:`compiled`; None: the class's choice).  A subclass
    implements :meth:`_advance`; the dense output over each step is
    :func:`hermite_dense`."""

    adaptive = False
    #: segments on a compiled kernel run in the compiled fixed-step loop
    #: (:mod:`mechdyn.kernels.fixed_step_numba`): True for the methods it has (RK4,
    #: Wilson's); False on an instance: the Python stepper everywhere (for cross-checks)
    compiled = False

    def __init__(self, steps: int | None = None, dt: float | None = None, *,
                 compiled: bool | None = None):
        super().__init__()
        if compiled is not None:
            self.compiled = bool(compiled)
        self.steps = check_positive("steps", steps, integer=True, allow_none=True)
        self.dt = check_positive("dt", dt, allow_none=True)
        if self.steps is not None and self.dt is not None:
            raise IntegratorOptionError("give either `steps` or `dt`, not both")

    def settings(self) -> dict:
        return {"steps": self.steps, "dt": self.dt}

    @abstractmethod
    def _advance(self, rhs, t, t1, q, v, w, a, p):
        """``(q, q', w, q'', p)`` at ``t1`` from the state and ``(a, p) = rhs(t, q, v)``
        at ``t``."""

    def grid(self, t0: float, t_end: float) -> np.ndarray:
        """The step ends over [t0, t_end], ``t0`` first: ``steps`` equal steps, or steps
        of ``dt`` with the last one shortened to land on ``t_end`` (s).

        Parameters
        ----------
        t0, t_end : float
            The interval, s (``t_end`` >= ``t0``; equal: the grid is ``[t0]``).

        Returns
        -------
        ndarray, shape (n + 1,)
            The step ends, s: ``t0`` first, ``t_end`` last (exactly).

        Examples
        --------
        >>> from mechdyn.integrate import RungeKutta4
        >>> RungeKutta4(dt=0.4).grid(0.0, 1.0).tolist()
        [0.0, 0.4, 0.8, 1.0]
        >>> RungeKutta4(steps=2).grid(0.0, 1.0).tolist()
        [0.0, 0.5, 1.0]
        """
        if t_end == t0:
            return np.array([t0])
        if self.dt is not None:
            n = max(1, int(math.ceil((t_end - t0) / self.dt - 1e-9)))
            grid = t0 + self.dt * np.arange(n + 1)
            grid[-1] = t_end
            return grid
        return np.linspace(t0, t_end, (100 if self.steps is None else self.steps) + 1)

    def _steps(self, rhs, t0, q0, qdot0, w0, t_end, first_order=None) -> Iterator[Step]:
        grid = self.grid(t0, t_end)
        q, v, w = q0, qdot0, w0
        a, p = rhs(t0, q, v)
        t = t0
        for t1 in grid[1:]:
            q1, v1, w1, a1, p1 = self._advance(rhs, t, t1, q, v, w, a, p)
            dense = hermite_dense(t, q, v, a, w, p, t1, q1, v1, a1, w1, p1)
            self.stats.steps += 1
            yield Step(t, float(t1), q1, v1, a1, w1, dense)
            t, q, v, w, a, p = float(t1), q1, v1, w1, a1, p1


class AdaptiveIntegrator(Integrator):
    """Base class of the adaptive integrators (the package's DOP853, SciPy's solvers):
    the step size follows an error estimate against ``atol_i + rtol |y_i|`` over the
    first-order state y = (q, q', w).

    Parameters
    ----------
    rtol : float
        Relative tolerance (> 0), default ``DEFAULT_RTOL`` (1e-10).
    atol : float or array_like, optional
        Absolute tolerance, SI units of each state component (> 0); a scalar, or an
        array of length 2 n + n_w over (q, q', w), checked against the state by
        :meth:`start_vector`.  Default ``1e-3 rtol``.
    first_step, max_step : float, optional
        Initial and largest step sizes, s (> 0; default: the method's starting step,
        no bound).

    Raises
    ------
    IntegratorOptionError
        A tolerance or step bound that is not a positive finite number (the message
        names it).

    Examples
    --------
    >>> from mechdyn.integrate import AdaptiveIntegrator, make_integrator
    >>> integ = make_integrator("dop853", rtol=1e-6, max_step=0.01)
    >>> isinstance(integ, AdaptiveIntegrator), integ.atol, integ.max_step
    (True, 1e-09, 0.01)
    >>> make_integrator("dop853", atol=-1.0)
    Traceback (most recent call last):
    ...
    mechdyn.integrate.base.IntegratorOptionError: `atol` must be positive, got -1.0
    """

    adaptive = True
    #: whether a segment on a compiled kernel may run in a compiled loop (True for the
    #: package's DOP853, :class:`mechdyn.integrate.compiled_dop853.DOP853`)
    compiled = False

    def __init__(self, rtol: float = DEFAULT_RTOL, atol=None, *,
                 first_step: float | None = None, max_step: float | None = None):
        super().__init__()
        self.rtol = check_positive("rtol", rtol)
        if atol is None:
            atol = 1e-3 * self.rtol
        at = np.asarray(atol, dtype=float)
        if not np.all(np.isfinite(at)) or np.any(at <= 0):
            raise IntegratorOptionError(f"`atol` must be positive, got {atol!r}")
        self.atol = float(at) if at.ndim == 0 else at
        self.first_step = check_positive("first_step", first_step, allow_none=True)
        self.max_step = check_positive("max_step", max_step, allow_none=True)

    def start_vector(self, q0, qdot0, w0) -> np.ndarray:
        """The first-order start (q, q', w), its size checked against ``atol``.

        Raises
        ------
        IntegratorOptionError
            ``atol`` is an array whose length is not that of the state.
        """
        y0 = np.concatenate([q0, qdot0, w0])
        if np.ndim(self.atol) and np.size(self.atol) != y0.size:
            raise IntegratorOptionError(
                f"`atol` has {np.size(self.atol)} components but the state (q, q', w) has "
                f"{y0.size}")
        return y0

    def settings(self) -> dict:
        return {"rtol": self.rtol, "atol": self.atol, "first_step": self.first_step,
                "max_step": self.max_step}

    def going_on(self, h: float | None) -> AdaptiveIntegrator:
        """This integrator with its first step ``h`` (s), counters of its own: the method
        going on from the middle of a segment with the step it had (a compiled loop
        handing a segment over), rather than starting again with a guessed step; ``self``
        where ``h`` is None or not positive.

        Examples
        --------
        >>> from mechdyn.integrate import make_integrator
        >>> make_integrator("dop853").going_on(1e-3).first_step
        0.001
        """
        if h is None or not h > 0.0 or not np.isfinite(h):
            return self
        other = copy.copy(self)
        other.stats = type(self.stats)()
        other.first_step = float(h)
        return other


def first_order_function(rhs, n: int):
    """y' = f(t, y) of the first-order state y = (q, q', w) (n coordinates) from the
    second-order ``rhs(t, q, qdot) -> (qddot, P_nc)``.

    Examples
    --------
    >>> f = first_order_function(lambda t, q, qd: (-q, np.zeros(1)), 1)
    >>> f(0.0, np.array([2.0, 3.0, 0.0])).tolist()
    [3.0, -2.0, 0.0]
    """
    def fun(t, y):
        return np.concatenate([y[n:2 * n], *rhs(t, y[:n], y[n:2 * n])])

    return fun


def split_state(y, n: int) -> tuple:
    """``(q, q', w)`` of a first-order state y of n coordinates (views of y).

    Examples
    --------
    >>> [a.tolist() for a in split_state(np.arange(5.0), 2)]
    [[0.0, 1.0], [2.0, 3.0], [4.0]]
    """
    return y[:n], y[n:2 * n], y[2 * n:]
