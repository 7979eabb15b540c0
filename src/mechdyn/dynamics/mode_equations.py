"""The equations of motion of one mode, as the integrators see them.

Lagrange II in the independent coordinates q_I of the mode (a subset of the
declared coordinates, chosen by :class:`~mechdyn.dynamics.modes.ModeSystem`):
A(q) q_I'' = Q - c, with the rows of every active element (joints, engaged
locks, closed stops and contacts, sticking contacts) and the rotor and gear
inertia of the drives reduced to their coordinates.  The right-hand side runs
on the compiled kernel (:mod:`mechdyn.dynamics.compiled`) whenever the mode
allows (numba installed, every load compiled, no sliding friction); otherwise,
and to diagnose a failure, on the NumPy evaluation of the mode
(:meth:`ModeSystem.evaluate`), which also gives every multiplier.  A
fixed-structure run is a run in one mode.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError, SingularPositionError
from ..kinematics.assembly import SINGULAR_RCOND
from ..kinematics.constraints import extend
from .compiled import compile_mode_kernel
from .lagrange import PIVOT_CHECK
from .modes import ModeEval

__all__ = ["ModeEquations", "BACKENDS"]

#: valid values of ``backend``
BACKENDS = ("auto", "numpy", "numba")


class ModeEquations:
    """q_I'' = f(t, q_I, q_I') of one mode, with the power of the non-conservative forces.

    Parameters
    ----------
    sm : SwitchedModel
    ms : ModeSystem
        The mode (rows, independent coordinates, targets of the locks).
    backend : {"auto", "numpy", "numba"}
        ``"auto"`` uses the compiled kernel when it can; ``"numba"`` insists on it.

    Attributes
    ----------
    kernel : CompiledKernel or None
    backend : str
        ``"numba"`` or ``"numpy"``, what this mode runs on.
    note : str
        Why the compiled path is not used, or ``""``.

    Raises
    ------
    ModelError
        An unknown backend, or ``backend="numba"`` where the compiled path cannot run.
    """

    def __init__(self, sm, ms, backend: str = "auto"):
        if backend not in BACKENDS:
            raise ModelError(f"unknown backend {backend!r}; valid: "
                             + ", ".join(repr(b) for b in BACKENDS))
        self.sm, self.ms = sm, ms
        self.kernel, self.note = None, ""
        if backend != "numpy":
            if any(r.slip for r in ms.rows):
                self.note = "sliding friction is evaluated on the NumPy path"
            else:
                self.kernel, self.note = compile_mode_kernel(
                    ms.model, sm.fm, ms.rowset.take(ms.independent_rows), ms.coords)
            if self.kernel is None and backend == "numba":
                raise ModelError(f"the compiled (numba) backend is not available: {self.note}")
        if self.kernel is not None:
            self.kernel.reset(ms.x_ref)
        self.backend = "numba" if self.kernel is not None else "numpy"
        # the kernel's multipliers are those of the independent rows: all of them unless
        # the mode has redundant rows (their share is chosen on the NumPy path)
        self._full = len(ms.independent_rows) == ms.n_rows

    def evaluate(self, t: float, qi, qdi):
        """Everything at a state of the mode (:class:`ModeEval`: poses, rates,
        accelerations of every declared coordinate, every multiplier), from the compiled
        kernel when the mode has no redundant rows, else from the NumPy evaluation."""
        ms = self.ms
        if self.kernel is not None:
            if self._full:
                k = self.kernel.evaluation(t, qi, qdi)
                if k is not None:
                    lam = np.zeros(ms.n_rows)
                    lam[ms.independent_rows] = k["lam"]
                    return ModeEval(k["x"], k["xdot"], k["xddot"], k["q"], k["qdot"],
                                    k["qddot"], lam, k["F"])
            guess = self.kernel.x.copy()
            return ms.evaluate(t, qi, qdi, x_guess=guess)
        return ms.evaluate(t, qi, qdi)

    def numpy_rhs(self, t: float, qi, qdi):
        """(q_I'', array([P_nc])) on the NumPy path; raises the diagnosed error of a
        failure (assembly, lock-up)."""
        ms = self.ms
        ev = self.evaluate(t, qi, qdi)
        Fc = ev.F_conservative
        p = float((ev.F - (self.sm.fm.conservative(ev.x) if Fc is None else Fc)) @ ev.xdot)
        p += friction_power(ms, ev)
        return ev.qddot[ms.coords], np.array([p])

    def rhs(self, t: float, qi, qdi):
        """(q_I'' (n_i,), array([P_nc])) at (t, q_I, q_I')."""
        if self.kernel is not None:
            out = self.kernel.rhs(t, qi, qdi)
            if out is not None:
                return out
        return self.numpy_rhs(t, qi, qdi)

    def check_position(self, t: float, x, q) -> None:
        """Stop at a singular position of the mode (dead, toggle or bifurcation position:
        the mode's coordinates lose control), with t, q and the coordinates named.

        A cheap test first (the pivots of the compiled kernel's last factorization),
        confirmed by the singular values of the scaled position Jacobian.

        Raises
        ------
        SingularPositionError
            sigma_min / sigma_max of [rows_I; g_I] below ``SINGULAR_RCOND``.
        """
        if self.kernel is not None and self.kernel.pivot_ratio >= PIVOT_CHECK:
            return
        rc = self.ms.rcond(x)
        if rc >= SINGULAR_RCOND:
            return
        model = self.ms.model
        names = ", ".join(f"{n} = {v:.9g}" for n, v in zip(model.coordinate_names, q,
                                                               strict=True))
        raise SingularPositionError(
            f"singular position in mode {sorted(self.ms.mode) or '(none)'} at t = {t:.9g} s, "
            f"{names}: sigma_min/sigma_max of the position Jacobian {rc:.2e}; the "
            f"independent coordinates "
            f"{', '.join(model.coordinate_names[k] for k in self.ms.coords)} lose control",
            t=t, q=q)

    def first_order_function(self):
        """``fun(t, y) -> y'`` for y = (q_I, q_I', w) on the compiled kernel, or None."""
        if self.kernel is None:
            return None
        n = self.ms.n_i

        def on_failure(t, y):
            qdd, p = self.numpy_rhs(t, y[:n], y[n:2 * n])
            return np.concatenate([y[n:2 * n], qdd, p])

        return self.kernel.first_order_function(on_failure)


def friction_power(ms, ev) -> float:
    """Power of the sliding friction of the mode's slipping contacts, W (<= 0)."""
    slips = [(k, r) for k, r in enumerate(ms.rows) if r.slip]
    if not slips:
        return 0.0
    X, V = extend(ms.model, ev.x), extend(ms.model, ev.xdot)
    return float(sum(-r.mu * r.slip * ev.lam[ms.n_base + k] * r.tangent.rate(X, V)
                     for k, r in slips))
