"""The exception tree of mechdyn.

Every error names the element, the field and the value concerned.  Errors raised
during an analysis carry the time ``t`` and the generalized coordinates ``q`` at
which they happened, so that a caller can report where a run stopped.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

__all__ = [
    "MechdynError",
    "ModelError",
    "UnitError",
    "AssemblyError",
    "SingularPositionError",
    "BranchJumpError",
    "LockupError",
    "IntegrationError",
    "did_you_mean",
]


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
        if isinstance(problems, str):
            problems = [problems]
        self.problems = list(problems)
        if len(self.problems) == 1:
            text = self.problems[0]
        else:
            text = f"{len(self.problems)} problems in the model:\n" + "\n".join(
                f"  - {p}" for p in self.problems
            )
        super().__init__(text)


class UnitError(ModelError):
    """A quantity has a unit of the wrong dimension, or cannot be parsed."""


def _fmt_q(q) -> str:
    if q is None:
        return "?"
    q = np.atleast_1d(np.asarray(q, dtype=float))
    return "[" + ", ".join(f"{v:.6g}" for v in q) + "]"


class _WhereError(MechdynError):
    """An error that happened at a time ``t`` and coordinates ``q``."""

    def __init__(self, message: str, *, t: float | None = None, q=None):
        self.t = t
        self.q = None if q is None else np.array(q, dtype=float, copy=True)
        where = []
        if t is not None:
            where.append(f"t = {t:.9g} s")
        if q is not None:
            where.append(f"q = {_fmt_q(q)}")
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
