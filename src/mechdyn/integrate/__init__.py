"""Integrators of q'' = f(t, q, q'); they know nothing of bodies."""

from .base import AdaptiveIntegrator, Integrator, IntegratorOptionError, IntegratorStats, Step
from .driver import INTEGRATORS, Solution, SolveStats, make_integrator, solve
from .events import Event, EventRecord
from .runge_kutta import RungeKutta4
from .scipy_ivp import ScipyIntegrator
from .wilson import Wilson

__all__ = ["AdaptiveIntegrator", "Integrator", "IntegratorOptionError", "IntegratorStats",
           "Step", "INTEGRATORS", "Solution", "SolveStats", "make_integrator", "solve", "Event",
           "EventRecord", "RungeKutta4", "ScipyIntegrator", "Wilson"]
