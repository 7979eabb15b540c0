"""The exception tree of mechdyn, and the one status vocabulary of its records.

Every error names the element, the field and the value concerned.  Errors raised
during an analysis carry the time ``t`` and the generalized coordinates ``q`` at
which they happened, so that a caller can report where a run stopped.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from enum import StrEnum

import numpy as np

__all__ = ["Status", "MechdynError", "ModelError", "UnitError", "AssemblyError",
           "SingularPositionError", "BranchJumpError", "LockupError", "IntegrationError",
           "did_you_mean"]


class Status(StrEnum):
    """How an analysis ended: the one status vocabulary of every record.

    A ``Status`` is a ``str`` (``Status.SUCCESS == "success"``), so records print and
    compare as plain text.  Everything but ``SUCCESS`` and ``REDUNDANT`` means the
    analysis did not cover all that was asked, and the record's ``message`` says where
    (time, coordinates, elements).

    Examples
    --------
    >>> Status("singular-position") is Status.SINGULAR_POSITION
    True
    >>> Status.SUCCESS == "success"
    True
    """

    #: completed
    SUCCESS = "success"
    #: completed; reactions of redundant joints are not unique (minimum-norm ones given)
    REDUNDANT = "redundant"
    #: a terminal event of the caller ended the run
    EVENT = "event"
    #: a dead, toggle or bifurcation position: the coordinates lose control there
    SINGULAR_POSITION = "singular-position"
    #: positions where friction locks the mechanism: no finite driving torque moves it
    SELF_LOCKING = "self-locking"
    #: the mechanism cannot be assembled at the coordinates reached
    ASSEMBLY_FAILED = "assembly-failed"
    #: the generalized mass matrix is singular (a coordinate without inertia)
    SINGULAR_MASS_MATRIX = "singular-mass-matrix"
    #: non-finite values appeared
    NON_FINITE = "non-finite"
    #: no consistent set of contact forces (complementarity has no solution)
    NO_CONTACT_SOLUTION = "no-contact-solution"
    #: a mode leaves no freedom the declared coordinates describe
    LOCKUP = "lockup"
    #: switching does not settle (too many events)
    TOO_MANY_EVENTS = "too-many-events"
    #: the wall-time limit was reached
    TIMEOUT = "timeout"
    #: the step size fell below the smallest allowed (the motion is too fast for the
    #: requested tolerance)
    STEP_TOO_SMALL = "step-too-small"
    #: the step budget of the run was used up
    BUDGET = "budget-exhausted"
    #: stopped by the user (Ctrl-C); the data so far is kept
    INTERRUPTED = "interrupted"
    #: a transient did not reach its steady state in the time given
    NOT_SETTLED = "not-settled"
    #: some segments could not be analysed (their rows are NaN)
    PARTIAL = "partial"
    #: anything else (the integrator failed ...)
    FAILED = "failed"

    def __repr__(self) -> str:
        return repr(self.value)


class MechdynError(Exception):
    """Base class of every error raised by mechdyn."""


class ModelError(MechdynError, ValueError):
    """A mechanism description or model file is wrong.

    Parameters
    ----------
    problems : str or sequence of str
        One message per problem.  A model is validated whole, so all problems
        found are reported at once.
    """

    def __init__(self, problems: str | Sequence[str]):
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        if len(self.problems) == 1:
            super().__init__(self.problems[0])
        else:
            super().__init__(f"{len(self.problems)} problems in the model:\n"
                             + "\n".join(f"  - {p}" for p in self.problems))


class UnitError(ModelError):
    """A quantity has a unit of the wrong dimension, or cannot be parsed."""


class _WhereError(MechdynError):
    """An error that happened at a time ``t`` and coordinates ``q``."""

    def __init__(self, message: str, *, t: float | None = None, q=None):
        self.t = t
        self.q = None if q is None else np.array(q, dtype=float, copy=True)
        where = []
        if t is not None:
            where.append(f"t = {t:.9g} s")
        if q is not None:
            where.append("q = [" + ", ".join(f"{v:.6g}" for v in np.atleast_1d(self.q)) + "]")
        self.message = message
        super().__init__(message + (f" (at {', '.join(where)})" if where else ""))


class AssemblyError(_WhereError):
    """The constraint equations cannot be satisfied at the requested coordinates.

    Attributes
    ----------
    residuals : dict[str, float]
        Norm of the residual of each joint whose equations stay violated, in m
        (or rad for angular equations), largest first.
    """

    def __init__(self, message: str, *, t=None, q=None, residuals: dict | None = None):
        self.residuals = dict(residuals or {})
        super().__init__(message, t=t, q=q)


class SingularPositionError(_WhereError):
    """A dead or toggle position: the constraint Jacobian loses rank.

    Attributes
    ----------
    sigma_min : float
        Smallest singular value of the scaled constraint Jacobian.
    coordinates : list[str]
        Generalized coordinates that lose control of the mechanism there.
    joints : list[str]
        Joints whose equations become dependent there.
    """

    def __init__(self, message, *, t=None, q=None, sigma_min=np.nan, coordinates=(),
                 joints=()):
        self.sigma_min = float(sigma_min)
        self.coordinates = list(coordinates)
        self.joints = list(joints)
        super().__init__(message, t=t, q=q)


class BranchJumpError(_WhereError):
    """The position solve would have moved the mechanism to another assembly branch."""


class LockupError(_WhereError):
    """A mechanism cannot move on: no motion is consistent with the active constraints."""


class ContactError(MechdynError):
    """No contact force distribution satisfies the complementarity conditions."""

    def __init__(self, message, *, t=None):
        self.t = t
        super().__init__(message + (f" (at t = {t:.9g} s)" if t is not None else ""))


class IntegrationError(_WhereError):
    """Numerical integration failed (non-finite state, singular mass matrix, ...)."""


def did_you_mean(name: str, valid: Iterable[str], what: str) -> str:
    """Message for an unknown name, listing the valid ones.

    Parameters
    ----------
    name : str
        The name that was not found.
    valid : iterable of str
        The names that exist.
    what : str
        What kind of thing the name should denote ("body", "joint", ...).
    """
    valid = sorted(valid)
    listing = ", ".join(repr(v) for v in valid) if valid else "(none defined)"
    return f"unknown {what} {name!r}; valid {what} names: {listing}"
