"""Private: fast evaluation of the position problem for :mod:`mechdyn.kinematics.sweep`.

The equations are the model's constraint rows (:mod:`mechdyn.model.rows`): the
residual [Phi; g - q], the Jacobian [Phi_x; g_x] and the acceleration
right-hand side [gamma; gamma_g] = -quad, the same rows that
:mod:`mechdyn.kinematics.constraints` evaluates.  This module knows no joint's
formulas; with numba it evaluates the rows and factors their Jacobians (LU with
partial pivoting, which also gives the sign of the determinant, the branch sign)
by the compiled drivers of :mod:`mechdyn.kernels.rows_sweep`, one position or a
whole batch per call (NumPy's per-call overhead and temporaries would dominate);
without numba by :mod:`mechdyn.kernels.rows_numpy` and dense NumPy solves.

``tests/unit/test_sweep.py`` checks the kernel against central differences of
its residual, its two evaluation paths against each other and its solves and
signs against dense ones.
"""

from __future__ import annotations

import numpy as np

from ..kernels import rows_numpy
from ..model import ConstraintLayout, Model
from ..model.rows import concat
from .assembly import _dense_solve, _scale

__all__ = ["Kernel"]


def _c(a) -> np.ndarray:
    """A C-contiguous float array (one compiled specialization for every caller)."""
    return np.ascontiguousarray(a, dtype=float)


class Kernel:
    """Residual, Jacobian and gamma of the position problem of one model and layout.

    The equations are the rows of the layout (joints, then engaged locks) followed
    by the coordinate rows, F(x) = [Phi(x); g(x) - q], evaluated by the compiled
    drivers of :mod:`mechdyn.kernels.rows_sweep` (or, when numba is not installed
    or ``compiled`` is set to False, by :mod:`mechdyn.kernels.rows_numpy`).
    The methods take a batch (``x`` (N, n_x), ``q`` (N, n_q)) or one position
    (1-D arrays).

    Parameters
    ----------
    model : Model
    layout : ConstraintLayout
        The mode's row layout (``layout.rowset``).
    """

    def __init__(self, model: Model, layout: ConstraintLayout):
        self.model = model
        self.lay = layout
        nb = self.nb = model.n_bodies
        self.n_x = 3 * nb
        self.n_rows = layout.n_rows
        self.n_q = model.n_q
        self.n_eq = layout.n_rows + model.n_q
        self.square = self.n_eq == self.n_x
        self.col_scale = _scale(model)
        #: the rows of F: the layout's constraint rows, then the coordinate rows
        self.rows = concat(nb, layout.rowset, model.coordinate_rows)
        self._ints, self._flts = self.rows.packed()
        from ..kernels import rows_numba, rows_sweep  # numba is imported only here

        self._drivers = rows_sweep
        #: evaluate and factor with the compiled drivers (numba installed), else NumPy
        self.compiled = rows_numba.NUMBA
        if self.compiled:
            with rows_numba.compiling("numba kernels of the kinematic sweep"):
                x = np.random.default_rng(1).normal(size=(1, self.n_x))
                J = self.system(x, np.zeros((1, self.n_q)))[1]
                self.apply(J, self.factor(J), J[..., :1])

    def system(self, x, q):
        """F (N, n_eq) (m or rad) and J (N, n_eq, n_x) at poses x (N, n_x), q (N, n_q)."""
        if x.ndim == 1:
            F, J = self.system(x[None], q[None])
            return F[0], J[0]
        if not self.compiled:
            p = rows_numpy.parts(self.rows, x)
            F = rows_numpy.values(self.rows, x, p)
            F[..., self.n_rows:] -= q
            return F, rows_numpy.jacobian(self.rows, x, p)
        F = np.empty((x.shape[0], self.n_eq))
        J = np.zeros((x.shape[0], self.n_eq, self.n_x))
        self._drivers.system_batch(_c(x), _c(q), self.nb, self._ints, self._flts,
                                   self.n_rows, F, J)
        return F, J

    def gamma(self, x, xdot):
        """[gamma; gamma_g] (N, n_eq): [Phi_x; g_x] xddot = this + [0; qddot]."""
        if x.ndim == 1:
            return self.gamma(x[None], xdot[None])[0]
        if not self.compiled:
            return -rows_numpy.quad(self.rows, x, xdot)
        out = np.empty((x.shape[0], self.n_eq))
        self._drivers.gamma_batch(_c(x), _c(xdot), self.nb, self._ints, self._flts, out)
        return out

    def factor(self, J):
        """Factors of Jacobians J (N, n_eq, n_x) or (n_eq, n_x) for :meth:`apply`, and the
        signs of det [Phi_x; g_x] (the branch sign, as ``assembly.branch_sign``):
        ``(lu, piv, sign)``, ``lu`` None where the solves are dense."""
        one = J.ndim == 2
        Jb = J[None] if one else J
        lu = piv = None
        if not self.square:
            sign = np.ones(Jb.shape[0])
        elif not self.compiled:
            sign = np.sign(np.linalg.det(Jb))
        else:
            lu, piv = np.array(Jb, dtype=float), np.empty(Jb.shape[:2], dtype=np.intp)
            sign = np.empty(Jb.shape[0])
            self._drivers.lu_batch(lu, piv, sign)
        return (lu, piv, float(sign[0]) if one else sign)

    def apply(self, J, fac, rhs):
        """y with J y = rhs, J (N, n_eq, n_x) and rhs (N, n_eq, k) -> (N, n_x, k), or one
        position (J 2-D, rhs 1-D or 2-D), with the factors of :meth:`factor`."""
        if fac is None or fac[0] is None:
            return _dense_solve(J, rhs)
        y = np.array(rhs, dtype=float)
        shape = y.shape
        y = y.reshape((-1,) + shape[-2:] if J.ndim == 3 else (1, self.n_eq, -1))
        self._drivers.lu_solve_batch(fac[0], fac[1], y)
        y = y.reshape(shape)
        return y if np.all(np.isfinite(y)) else _dense_solve(J, rhs)

    def rhs_unit(self, N):
        """[0; I], the right-hand side of the velocity-analog equations, (N, n_eq, n_q)."""
        E = np.zeros((N, self.n_eq, self.n_q))
        E[:, self.n_rows:, :] = np.eye(self.n_q)
        return E
