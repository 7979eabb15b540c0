"""Compiled (numba) evaluation of the exact equations of motion.

One call of the kernel does, for a state (t, q, q'): the Newton position solve
from the last pose (with the linear predictor x + B (q - q_last)), the velocity
analogs B, the acceleration bias b, the centre-of-mass analogs, the mass matrix
A = B_c^T M B_c, c = B_c^T M b_c, the applied forces and Q = B^T F + Q_drive,
the Cholesky solve for q'' and the power of the non-conservative forces.  It
is the same mathematics as :mod:`mechdyn.dynamics.lagrange` (which stays the
reference; a test checks both agree to 1e-12), written as loops over small
dense arrays so that the per-evaluation cost is a few microseconds instead of
the ~1 us per NumPy call of the batched reference path.

The model is packed into one integer and one float array (see ``_Packer``).
Supported: revolute, prismatic and lock joints; angle, relative-angle and
travel coordinates; gravity; springs and dampers; rotary springs; forces and
torques of constant magnitude or tabulated (periodic or not) in time or in a
coordinate (rate);
drives constant, tabulated or given by a torque-speed curve.  A load given by a
Python callable (or anything else) makes :func:`compile_kernel` return None
with the reason, and the NumPy path is used.

numba is optional (``pip install mechdyn[fast]``); without it the NumPy path
is used.  Compiled code is cached on disk (``cache=True``): the first run pays
the compilation (reported as ``compile_time``), later runs load it.
"""

from __future__ import annotations

import time

import numpy as np

from ..mechanism.drive import TorqueSpeedCurve
from ..mechanism.load import Force, RotarySpring, Spring, Table, Torque
from ..model import COORD_ANGLE, COORD_RELATIVE, COORD_TRAVEL

__all__ = ["compile_kernel", "CompiledKernel", "numba_available"]

try:  # pragma: no cover - depends on the environment
    import numba

    _NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    _NUMBA = False


def numba_available() -> bool:
    """Whether the compiled backend can be used."""
    return _NUMBA


def _njit(fn):
    if _NUMBA:
        return numba.njit(cache=True, fastmath=False, nogil=True)(fn)
    return fn


# ----------------------------------------------------------------------------- layout
# header of the int array: counts, then section offsets
H_NB, H_NQ, H_NREV, H_NPRI, H_NLOCK, H_NSPR, H_NROT, H_NFOR, H_NTOR, H_NDRV, H_NROWS = range(11)
H_IOFF = 16  # int offsets of sections start here
H_FOFF = 32  # float offsets of sections start here
HEADER = 48
# sections (same index in the int and the float offset tables)
S_BODY, S_REV, S_PRI, S_LOCK, S_COORD, S_SPR, S_ROT, S_FOR, S_TOR, S_DRV, S_TAB = range(11)
# strides
IR_REV, FR_REV = 2, 4
IR_PRI, FR_PRI = 2, 7
IR_LOCK, FR_LOCK = 2, 3
IR_COORD, FR_COORD = 4, 1
IR_SPR, FR_SPR = 2, 8
IR_ROT, FR_ROT = 2, 4
# value records (forces, torques, drives): mode, tab_off, tab_len, var_kind, var_index,
# table flags (T_OUTSIDE | T_PERIODIC), then a target part; a table is stored in the
# table section as xs (tab_len), ys (tab_len) and, if periodic, its period
IR_VAL = 6
IR_FOR, FR_FOR = IR_VAL + 2, 5 + 1  # body, frame | sx, sy, dx, dy, value, outside
IR_TOR, FR_TOR = IR_VAL + 2, 2  # body, reaction | value, outside
IR_DRV, FR_DRV = IR_VAL + 1, 3  # coordinate | value, outside, extra inertia
FR_BODY = 4  # m, J, cx, cy
F_GLOBAL = 4  # gx, gy, length_scale, tol (at the start of the float array)
# value modes and table variables
V_CONST, V_TABLE = 0, 1
T_OUTSIDE, T_PERIODIC = 1, 2  # table flags
VAR_T, VAR_Q, VAR_QDOT = 0, 1, 2
# work array layout: x (nx) | q_last (nq) | B_last (nx nq) | xdot (nx) | x_good (nx) | flags
W_VALID = 0  # flags: B_last valid
W_PIVOT = 1  # pivot ratio of the last factorisation
W_ITER = 2  # Newton iterations of the last solve
W_ERR = 3  # last Newton residual
W_COUNT = 4  # evaluations of the equations
N_FLAGS = 5


class _Unsupported(Exception):
    pass


class _Packer:
    """Pack a model into (ip, fp)."""

    def __init__(self, model, layout):
        self.model, self.layout = model, layout
        self.tab_x: list[float] = []
        self.tabs: list[float] = []
        self.ints: dict[int, list[int]] = {s: [] for s in range(11)}
        self.flts: dict[int, list[float]] = {s: [] for s in range(11)}

    def value(self, v, where):
        """(int record, value, outside) of a load magnitude."""
        m = self.model
        if isinstance(v, bool):
            raise _Unsupported(f"{where}: boolean value")
        if isinstance(v, int | float | np.floating | np.integer):
            return [V_CONST, 0, 0, VAR_T, 0, 0], float(v), 0.0
        if isinstance(v, TorqueSpeedCurve):
            return self.table(v.omega, v.torque, VAR_QDOT, -1, None)
        if isinstance(v, Table):
            var = v.variable
            if var == "t":
                kind, idx = VAR_T, 0
            elif var in m.coordinate_names:
                kind, idx = VAR_Q, m.coordinate_index(var)
            elif var.endswith("_dot") and var[:-4] in m.coordinate_names:
                kind, idx = VAR_QDOT, m.coordinate_index(var[:-4])
            else:
                raise _Unsupported(f"{where}: table over {var!r} (only t, coordinates and "
                                   f"their rates are compiled)")
            return self.table(v.x, v.y, kind, idx, v.outside, v.period)
        raise _Unsupported(f"{where}: value {type(v).__name__} is not compiled "
                           f"(a Python callable is evaluated on the NumPy path)")

    def table(self, xs, ys, kind, idx, outside, period=None):
        """Append a table (xs, ys, then the period if any) to the table section."""
        off = len(self.tabs)
        self.tabs.extend(float(a) for a in xs)
        self.tabs.extend(float(b) for b in ys)
        flags = 0 if outside is None else T_OUTSIDE
        if period is not None:
            self.tabs.append(float(period))
            flags |= T_PERIODIC
        return ([V_TABLE, off, len(xs), kind, idx, flags], 0.0,
                0.0 if outside is None else float(outside))

    def pack(self):
        m, lay = self.model, self.layout
        fm = m._force_model if hasattr(m, "_force_model") else None
        from .forces import force_model

        fm = fm or force_model(m)
        nb = m.n_bodies
        for k in range(nb):
            self.flts[S_BODY] += [m.mass[k], m.inertia[k], m.com[k, 0], m.com[k, 1]]
        rv = m.rev
        for k in range(len(rv.names)):
            self.ints[S_REV] += [int(rv.i[k]), int(rv.j[k])]
            self.flts[S_REV] += [*rv.si[k], *rv.sj[k]]
        pr = m.pri
        for k in range(len(pr.names)):
            self.ints[S_PRI] += [int(pr.i[k]), int(pr.j[k])]
            self.flts[S_PRI] += [*pr.si[k], *pr.ui[k], *pr.sj[k], float(pr.angle[k])]
        lk = m.lock
        nlock = 0
        for k in range(len(lk.names)):
            if lay.lock_active[k]:
                nlock += 1
                self.ints[S_LOCK] += [int(lk.i[k]), int(lk.j[k])]
                self.flts[S_LOCK] += [*lk.c[k], float(lk.angle[k])]
        for c in range(m.n_q):
            kind = int(m.coord_kind[c])
            if kind == COORD_ANGLE:
                rec = [kind, int(m.coord_body[c]), 0, 0]
            elif kind == COORD_RELATIVE:
                jj = int(m.coord_joint[c])
                rec = [kind, int(rv.i[jj]), int(rv.j[jj]), 0]
            elif kind == COORD_TRAVEL:
                rec = [kind, 0, 0, int(m.coord_joint[c])]
            else:  # pragma: no cover
                raise _Unsupported(f"coordinate kind {kind}")
            self.ints[S_COORD] += rec
            self.flts[S_COORD] += [float(m.coord_offset[c])]
        for (_, i, si, j, sj, k, L0, c, pre) in fm.springs:
            self.ints[S_SPR] += [int(i), int(j)]
            self.flts[S_SPR] += [*si, *sj, k, L0, c, pre]
        for (_, i, j, k, a0, c, pre) in fm.rotary:
            self.ints[S_ROT] += [int(i), int(j)]
            self.flts[S_ROT] += [k, a0, c, pre]
        for (ld, b, s) in fm.forces:
            rec, val, out = self.value(ld.magnitude, f"force {ld.name!r}")
            self.ints[S_FOR] += rec + [int(b), 1 if ld.frame == "body" else 0]
            self.flts[S_FOR] += [float(s[0]), float(s[1]), *map(float, ld.direction), val, out]
        for (ld, b, r) in fm.torques:
            rec, val, out = self.value(ld.magnitude, f"torque {ld.name!r}")
            self.ints[S_TOR] += rec + [int(b), nb if r is None else int(r)]
            self.flts[S_TOR] += [val, out]
        for (dr, k) in fm.drives:
            tq = dr.torque
            if hasattr(tq, "torque_at") and not isinstance(tq, TorqueSpeedCurve):
                table = getattr(tq, "as_table", None)
                if table is None:
                    raise _Unsupported(f"drive {dr.name!r}: characteristic "
                                       f"{type(tq).__name__} is evaluated on the NumPy path")
                om, tv = table()
                rec, val, out = self.table(om, tv, VAR_QDOT, k, None)
            else:
                rec, val, out = self.value(tq, f"drive {dr.name!r}")
            if rec[3] == VAR_QDOT and rec[4] == -1:
                rec[4] = k  # a torque-speed curve reads its own coordinate's rate
            self.ints[S_DRV] += rec + [int(k)]
            j_extra = getattr(tq, "extra_inertia", None)
            self.flts[S_DRV] += [val, out, float(j_extra()) if j_extra is not None else 0.0]
        extra = [ld for ld in m.mechanism.loads
                 if not isinstance(ld, Spring | RotarySpring | Force | Torque)]
        if extra:
            raise _Unsupported(f"load {getattr(extra[0], 'name', '?')!r} "
                               f"({type(extra[0]).__name__}) is evaluated on the NumPy path")
        self.flts[S_TAB] = self.tabs

        head = np.zeros(HEADER, dtype=np.int64)
        head[H_NB], head[H_NQ] = nb, m.n_q
        head[H_NREV], head[H_NPRI], head[H_NLOCK] = len(rv.names), len(pr.names), nlock
        head[H_NSPR], head[H_NROT] = len(fm.springs), len(fm.rotary)
        head[H_NFOR], head[H_NTOR], head[H_NDRV] = len(fm.forces), len(fm.torques), len(fm.drives)
        head[H_NROWS] = lay.n_rows
        ip_parts, fp_parts = [head], [np.array([*m.gravity, m.length_scale,
                                                1e-13 * max(m.length_scale, 1e-3)])]
        ioff, foff = HEADER, F_GLOBAL
        for s in range(11):
            head[H_IOFF + s] = ioff
            head[H_FOFF + s] = foff
            a = np.array(self.ints[s], dtype=np.int64)
            f = np.array(self.flts[s], dtype=np.float64)
            ip_parts.append(a)
            fp_parts.append(f)
            ioff += a.size
            foff += f.size
        return np.concatenate(ip_parts).astype(np.int64), np.concatenate(fp_parts)


# ----------------------------------------------------------------------------- kernels
@_njit
def _lu(a, piv, n):
    """In-place LU with partial pivoting; returns min|u_ii| / max|u_ii| (0 if singular)."""
    umin = np.inf
    umax = 0.0
    for k in range(n):
        p = k
        best = abs(a[k, k])
        for r in range(k + 1, n):
            v = abs(a[r, k])
            if v > best:
                best = v
                p = r
        piv[k] = p
        if p != k:
            for c in range(n):
                tmp = a[k, c]
                a[k, c] = a[p, c]
                a[p, c] = tmp
        d = a[k, k]
        if best < umin:
            umin = best
        if best > umax:
            umax = best
        if d == 0.0:
            return 0.0
        inv = 1.0 / d
        for r in range(k + 1, n):
            f = a[r, k] * inv
            a[r, k] = f
            if f != 0.0:
                for c in range(k + 1, n):
                    a[r, c] -= f * a[k, c]
    if umax == 0.0:
        return 0.0
    return umin / umax


@_njit
def _lu_solve(a, piv, b, n):
    """Solve with the factors of ``_lu`` (b overwritten)."""
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for r in range(1, n):
        s = b[r]
        for c in range(r):
            s -= a[r, c] * b[c]
        b[r] = s
    for r in range(n - 1, -1, -1):
        s = b[r]
        for c in range(r + 1, n):
            s -= a[r, c] * b[c]
        b[r] = s / a[r, r]


@_njit
def _pri_pose(x, nb, i, j, fp, f0):
    """Geometry of prismatic joint rows: body angles, rotated points A_i s_i, axis u,
    A_j s_j and the separation d = r_j + A_j s_j - r_i - A_i s_i."""
    xi = yi = ti = 0.0
    if i < nb:
        xi, yi, ti = x[3 * i], x[3 * i + 1], x[3 * i + 2]
    xj = yj = tj = 0.0
    if j < nb:
        xj, yj, tj = x[3 * j], x[3 * j + 1], x[3 * j + 2]
    ci, si = np.cos(ti), np.sin(ti)
    cj, sj = np.cos(tj), np.sin(tj)
    aix, aiy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
    ux, uy = ci * fp[f0 + 2] - si * fp[f0 + 3], si * fp[f0 + 2] + ci * fp[f0 + 3]
    ajx, ajy = cj * fp[f0 + 4] - sj * fp[f0 + 5], sj * fp[f0 + 4] + cj * fp[f0 + 5]
    return ti, tj, aix, aiy, ux, uy, ajx, ajy, xj + ajx - xi - aix, yj + ajy - yi - aiy


@_njit
def _pri_rates(v, nb, i, j, aix, aiy, ajx, ajy):
    """Angular rates of the two bodies and the rate of the separation d."""
    vxi = vyi = wi = 0.0
    if i < nb:
        vxi, vyi, wi = v[3 * i], v[3 * i + 1], v[3 * i + 2]
    vxj = vyj = wj = 0.0
    if j < nb:
        vxj, vyj, wj = v[3 * j], v[3 * j + 1], v[3 * j + 2]
    return wi, wj, vxj - wj * ajy - vxi + wi * aiy, vyj + wj * ajx - vyi - wi * aix


@_njit
def _system(x, q, ip, fp, F, J, want_jac):
    """Residual [Phi; g - q] (F) and Jacobian (J, columns scaled by the length scale for
    rotations when used through ``_solve_scaled``) at pose x."""
    nb = ip[H_NB]
    nx = 3 * nb
    if want_jac:
        for r in range(nx):
            for c in range(nx):
                J[r, c] = 0.0
    row = 0
    # revolute
    oi, of = ip[H_IOFF + S_REV], ip[H_FOFF + S_REV]
    for k in range(ip[H_NREV]):
        i = ip[oi + IR_REV * k]
        j = ip[oi + IR_REV * k + 1]
        f0 = of + FR_REV * k
        six, siy, sjx, sjy = fp[f0], fp[f0 + 1], fp[f0 + 2], fp[f0 + 3]
        xi = yi = ti = 0.0
        if i < nb:
            xi, yi, ti = x[3 * i], x[3 * i + 1], x[3 * i + 2]
        xj = yj = tj = 0.0
        if j < nb:
            xj, yj, tj = x[3 * j], x[3 * j + 1], x[3 * j + 2]
        ci, si = np.cos(ti), np.sin(ti)
        cj, sj = np.cos(tj), np.sin(tj)
        aix, aiy = ci * six - si * siy, si * six + ci * siy
        ajx, ajy = cj * sjx - sj * sjy, sj * sjx + cj * sjy
        F[row] = xi + aix - xj - ajx
        F[row + 1] = yi + aiy - yj - ajy
        if want_jac:
            if i < nb:
                J[row, 3 * i] = 1.0
                J[row + 1, 3 * i + 1] = 1.0
                J[row, 3 * i + 2] = -aiy
                J[row + 1, 3 * i + 2] = aix
            if j < nb:
                J[row, 3 * j] = -1.0
                J[row + 1, 3 * j + 1] = -1.0
                J[row, 3 * j + 2] = ajy
                J[row + 1, 3 * j + 2] = -ajx
        row += 2
    # prismatic
    oi, of = ip[H_IOFF + S_PRI], ip[H_FOFF + S_PRI]
    for k in range(ip[H_NPRI]):
        i = ip[oi + IR_PRI * k]
        j = ip[oi + IR_PRI * k + 1]
        f0 = of + FR_PRI * k
        ti, tj, aix, aiy, ux, uy, ajx, ajy, dx, dy = _pri_pose(x, nb, i, j, fp, f0)
        nx_, ny_ = -uy, ux
        F[row] = nx_ * dx + ny_ * dy
        F[row + 1] = tj - ti - fp[f0 + 6]
        if want_jac:
            if j < nb:
                J[row, 3 * j] = nx_
                J[row, 3 * j + 1] = ny_
                J[row, 3 * j + 2] = nx_ * (-ajy) + ny_ * ajx
                J[row + 1, 3 * j + 2] = 1.0
            if i < nb:
                J[row, 3 * i] = -nx_
                J[row, 3 * i + 1] = -ny_
                J[row, 3 * i + 2] = -(ux * dx + uy * dy) - (nx_ * (-aiy) + ny_ * aix)
                J[row + 1, 3 * i + 2] = -1.0
        row += 2
    # locks
    oi, of = ip[H_IOFF + S_LOCK], ip[H_FOFF + S_LOCK]
    for k in range(ip[H_NLOCK]):
        i = ip[oi + IR_LOCK * k]
        j = ip[oi + IR_LOCK * k + 1]
        f0 = of + FR_LOCK * k
        xi = yi = ti = 0.0
        if i < nb:
            xi, yi, ti = x[3 * i], x[3 * i + 1], x[3 * i + 2]
        xj = yj = tj = 0.0
        if j < nb:
            xj, yj, tj = x[3 * j], x[3 * j + 1], x[3 * j + 2]
        ci, si = np.cos(ti), np.sin(ti)
        acx, acy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
        F[row] = xj - xi - acx
        F[row + 1] = yj - yi - acy
        F[row + 2] = tj - ti - fp[f0 + 2]
        if want_jac:
            if j < nb:
                J[row, 3 * j] = 1.0
                J[row + 1, 3 * j + 1] = 1.0
                J[row + 2, 3 * j + 2] = 1.0
            if i < nb:
                J[row, 3 * i] = -1.0
                J[row + 1, 3 * i + 1] = -1.0
                J[row, 3 * i + 2] = acy
                J[row + 1, 3 * i + 2] = -acx
                J[row + 2, 3 * i + 2] = -1.0
        row += 3
    # coordinates
    oi, of = ip[H_IOFF + S_COORD], ip[H_FOFF + S_COORD]
    opi, opf = ip[H_IOFF + S_PRI], ip[H_FOFF + S_PRI]
    for c in range(ip[H_NQ]):
        kind = ip[oi + IR_COORD * c]
        off = fp[of + c]
        if kind == 0:  # absolute angle
            b = ip[oi + IR_COORD * c + 1]
            F[row] = x[3 * b + 2] + off - q[c]
            if want_jac:
                J[row, 3 * b + 2] = 1.0
        elif kind == 1:  # relative angle of a revolute
            i = ip[oi + IR_COORD * c + 1]
            j = ip[oi + IR_COORD * c + 2]
            ti = x[3 * i + 2] if i < nb else 0.0
            tj = x[3 * j + 2] if j < nb else 0.0
            F[row] = tj - ti + off - q[c]
            if want_jac:
                if j < nb:
                    J[row, 3 * j + 2] += 1.0
                if i < nb:
                    J[row, 3 * i + 2] -= 1.0
        else:  # travel of a prismatic
            p = ip[oi + IR_COORD * c + 3]
            i = ip[opi + IR_PRI * p]
            j = ip[opi + IR_PRI * p + 1]
            f0 = opf + FR_PRI * p
            ti, tj, aix, aiy, ux, uy, ajx, ajy, dx, dy = _pri_pose(x, nb, i, j, fp, f0)
            F[row] = ux * dx + uy * dy + off - q[c]
            if want_jac:
                if j < nb:
                    J[row, 3 * j] += ux
                    J[row, 3 * j + 1] += uy
                    J[row, 3 * j + 2] += ux * (-ajy) + uy * ajx
                if i < nb:
                    J[row, 3 * i] -= ux
                    J[row, 3 * i + 1] -= uy
                    J[row, 3 * i + 2] += (-uy * dx + ux * dy) - (ux * (-aiy) + uy * aix)
        row += 1


@_njit
def _gamma(x, v, ip, fp, g):
    """Right-hand side of [Phi_x; g_x] b = gamma for the acceleration bias."""
    nb = ip[H_NB]
    row = 0
    oi, of = ip[H_IOFF + S_REV], ip[H_FOFF + S_REV]
    for k in range(ip[H_NREV]):
        i = ip[oi + IR_REV * k]
        j = ip[oi + IR_REV * k + 1]
        f0 = of + FR_REV * k
        ti = x[3 * i + 2] if i < nb else 0.0
        tj = x[3 * j + 2] if j < nb else 0.0
        wi = v[3 * i + 2] if i < nb else 0.0
        wj = v[3 * j + 2] if j < nb else 0.0
        ci, si = np.cos(ti), np.sin(ti)
        cj, sj = np.cos(tj), np.sin(tj)
        aix, aiy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
        ajx, ajy = cj * fp[f0 + 2] - sj * fp[f0 + 3], sj * fp[f0 + 2] + cj * fp[f0 + 3]
        g[row] = aix * wi * wi - ajx * wj * wj
        g[row + 1] = aiy * wi * wi - ajy * wj * wj
        row += 2
    oi, of = ip[H_IOFF + S_PRI], ip[H_FOFF + S_PRI]
    for k in range(ip[H_NPRI]):
        i = ip[oi + IR_PRI * k]
        j = ip[oi + IR_PRI * k + 1]
        f0 = of + FR_PRI * k
        ti, tj, aix, aiy, ux, uy, ajx, ajy, dx, dy = _pri_pose(x, nb, i, j, fp, f0)
        wi, wj, ddx, ddy = _pri_rates(v, nb, i, j, aix, aiy, ajx, ajy)
        nx_, ny_ = -uy, ux
        quad = (-wi * wi * (nx_ * dx + ny_ * dy) - 2.0 * wi * (ux * ddx + uy * ddy)
                + nx_ * (-wj * wj * ajx + wi * wi * aix) + ny_ * (-wj * wj * ajy + wi * wi * aiy))
        g[row] = -quad
        g[row + 1] = 0.0
        row += 2
    oi, of = ip[H_IOFF + S_LOCK], ip[H_FOFF + S_LOCK]
    for k in range(ip[H_NLOCK]):
        i = ip[oi + IR_LOCK * k]
        f0 = of + FR_LOCK * k
        ti = x[3 * i + 2] if i < nb else 0.0
        wi = v[3 * i + 2] if i < nb else 0.0
        ci, si = np.cos(ti), np.sin(ti)
        acx, acy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
        g[row] = -acx * wi * wi
        g[row + 1] = -acy * wi * wi
        g[row + 2] = 0.0
        row += 3
    oi = ip[H_IOFF + S_COORD]
    opi, opf = ip[H_IOFF + S_PRI], ip[H_FOFF + S_PRI]
    for c in range(ip[H_NQ]):
        kind = ip[oi + IR_COORD * c]
        if kind != 2:
            g[row] = 0.0
        else:
            p = ip[oi + IR_COORD * c + 3]
            i = ip[opi + IR_PRI * p]
            j = ip[opi + IR_PRI * p + 1]
            f0 = opf + FR_PRI * p
            ti, tj, aix, aiy, ux, uy, ajx, ajy, dx, dy = _pri_pose(x, nb, i, j, fp, f0)
            wi, wj, ddx, ddy = _pri_rates(v, nb, i, j, aix, aiy, ajx, ajy)
            nx_, ny_ = -uy, ux
            quad = (-wi * wi * (ux * dx + uy * dy) + 2.0 * wi * (nx_ * ddx + ny_ * ddy)
                    + ux * (-wj * wj * ajx + wi * wi * aix) + uy * (-wj * wj * ajy + wi * wi * aiy))
            g[row] = -quad
        row += 1


@_njit
def _scale_cols(J, nx, ls):
    for r in range(nx):
        for b in range(nx // 3):
            J[r, 3 * b + 2] *= ls


@_njit
def _newton(q, ip, fp, ws, J, piv, F):
    """Solve the positions at q from the pose in ws; leaves the LU of the scaled Jacobian
    at the solution in (J, piv).  Returns 0 or 1 (no convergence)."""
    nb = ip[H_NB]
    nx = 3 * nb
    nq = ip[H_NQ]
    ls = fp[2]
    tol = fp[3]
    x = ws[:nx]
    ql = ws[nx:nx + nq]
    Bl = ws[nx + nq:nx + nq + nx * nq]
    flags = ws[ws.size - N_FLAGS:]
    xg = ws[ws.size - N_FLAGS - nx:ws.size - N_FLAGS]
    for r in range(nx):
        xg[r] = x[r]
    if flags[W_VALID] == 1.0:
        for r in range(nx):
            s = 0.0
            for c in range(nq):
                s += Bl[r * nq + c] * (q[c] - ql[c])
            x[r] += s
    prev = np.inf
    status = 1
    for it in range(40):
        _system(x, q, ip, fp, F, J, True)
        err = 0.0
        for r in range(nx):
            a = abs(F[r])
            if not a <= err:  # catches NaN
                err = a if a == a else np.inf
        _scale_cols(J, nx, ls)
        flags[W_PIVOT] = _lu(J, piv, nx)
        flags[W_ITER] = it
        flags[W_ERR] = err
        if err <= tol or (err >= 0.5 * prev and err <= 1e3 * tol):
            status = 0
            break
        if not err < np.inf or flags[W_PIVOT] == 0.0:
            break
        prev = err
        _lu_solve(J, piv, F, nx)
        for b in range(nb):
            F[3 * b + 2] *= ls
        for r in range(nx):
            x[r] -= F[r]
    if status == 0:
        for c in range(nq):
            ql[c] = q[c]
    else:  # keep the last good pose for the next start and the diagnosis
        for r in range(nx):
            x[r] = xg[r]
    flags[W_VALID] = 0.0
    return status


@_njit
def _interp(xs, ys, n, s, has_out, outside):
    if s < xs[0] or s > xs[n - 1]:
        if has_out:
            return outside
        return ys[0] if s < xs[0] else ys[n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= s:
            lo = mid
        else:
            hi = mid
    if xs[hi] == xs[lo]:
        return ys[lo]
    u = (s - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + u * (ys[hi] - ys[lo])


@_njit
def _value(ip, fp, irec, fval, t, q, qdot):
    if ip[irec] == 0:
        return fp[fval]
    tab0 = ip[H_FOFF + S_TAB] + ip[irec + 1]
    n = ip[irec + 2]
    kind = ip[irec + 3]
    idx = ip[irec + 4]
    if kind == 0:
        s = t
    elif kind == 1:
        s = q[idx]
    else:
        s = qdot[idx]
    flags = ip[irec + 5]
    if flags & 2:  # T_PERIODIC: wrap into [x0, x0 + period), as Table.wrap
        x0 = fp[tab0]
        per = fp[tab0 + 2 * n]
        u = (s - x0) % per
        if u >= per:
            u = 0.0
        s = x0 + u
    return _interp(fp[tab0:tab0 + n], fp[tab0 + n:tab0 + 2 * n], n, s, (flags & 1) == 1,
                   fp[fval + 1])


@_njit
def _apply(F, b, nb, armx, army, fx, fy):
    if b < nb:
        F[3 * b] += fx
        F[3 * b + 1] += fy
        F[3 * b + 2] += armx * fy - army * fx


@_njit
def _forces(t, q, qdot, x, v, ip, fp, F, Fnc, Qd):
    """Applied forces F (all) and Fnc (non-conservative part) on the poses, drives Qd."""
    nb = ip[H_NB]
    nq = ip[H_NQ]
    gx, gy = fp[0], fp[1]
    ob = ip[H_FOFF + S_BODY]
    for r in range(3 * nb):
        F[r] = 0.0
        Fnc[r] = 0.0
    for c in range(nq):
        Qd[c] = 0.0
    for b in range(nb):
        m = fp[ob + FR_BODY * b]
        cx, cy = fp[ob + FR_BODY * b + 2], fp[ob + FR_BODY * b + 3]
        th = x[3 * b + 2]
        c, s = np.cos(th), np.sin(th)
        _apply(F, b, nb, c * cx - s * cy, s * cx + c * cy, m * gx, m * gy)
    oi, of = ip[H_IOFF + S_SPR], ip[H_FOFF + S_SPR]
    for k in range(ip[H_NSPR]):
        i = ip[oi + IR_SPR * k]
        j = ip[oi + IR_SPR * k + 1]
        f0 = of + FR_SPR * k
        xi = yi = ti = vxi = vyi = wi = 0.0
        if i < nb:
            xi, yi, ti = x[3 * i], x[3 * i + 1], x[3 * i + 2]
            vxi, vyi, wi = v[3 * i], v[3 * i + 1], v[3 * i + 2]
        xj = yj = tj = vxj = vyj = wj = 0.0
        if j < nb:
            xj, yj, tj = x[3 * j], x[3 * j + 1], x[3 * j + 2]
            vxj, vyj, wj = v[3 * j], v[3 * j + 1], v[3 * j + 2]
        ci, si = np.cos(ti), np.sin(ti)
        cj, sj = np.cos(tj), np.sin(tj)
        aix, aiy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
        ajx, ajy = cj * fp[f0 + 2] - sj * fp[f0 + 3], sj * fp[f0 + 2] + cj * fp[f0 + 3]
        dx = xj + ajx - xi - aix
        dy = yj + ajy - yi - aiy
        L = np.sqrt(dx * dx + dy * dy)
        ex, ey = dx / L, dy / L
        vdx = vxj - wj * ajy - vxi + wi * aiy
        vdy = vyj + wj * ajx - vyi - wi * aix
        fc = fp[f0 + 4] * (L - fp[f0 + 5]) + fp[f0 + 7]
        fd = fp[f0 + 6] * (ex * vdx + ey * vdy)
        f = fc + fd
        _apply(F, i, nb, aix, aiy, f * ex, f * ey)
        _apply(F, j, nb, ajx, ajy, -f * ex, -f * ey)
        _apply(Fnc, i, nb, aix, aiy, fd * ex, fd * ey)
        _apply(Fnc, j, nb, ajx, ajy, -fd * ex, -fd * ey)
    oi, of = ip[H_IOFF + S_ROT], ip[H_FOFF + S_ROT]
    for k in range(ip[H_NROT]):
        i = ip[oi + IR_ROT * k]
        j = ip[oi + IR_ROT * k + 1]
        f0 = of + FR_ROT * k
        ti = x[3 * i + 2] if i < nb else 0.0
        tj = x[3 * j + 2] if j < nb else 0.0
        wi = v[3 * i + 2] if i < nb else 0.0
        wj = v[3 * j + 2] if j < nb else 0.0
        tc = -(fp[f0] * (tj - ti - fp[f0 + 1]) + fp[f0 + 3])
        td = -fp[f0 + 2] * (wj - wi)
        if j < nb:
            F[3 * j + 2] += tc + td
            Fnc[3 * j + 2] += td
        if i < nb:
            F[3 * i + 2] -= tc + td
            Fnc[3 * i + 2] -= td
    oi, of = ip[H_IOFF + S_FOR], ip[H_FOFF + S_FOR]
    for k in range(ip[H_NFOR]):
        i0 = oi + IR_FOR * k
        f0 = of + FR_FOR * k
        mag = _value(ip, fp, i0, f0 + 4, t, q, qdot)
        b = ip[i0 + IR_VAL]
        frame = ip[i0 + IR_VAL + 1]
        th = x[3 * b + 2] if b < nb else 0.0
        c, s = np.cos(th), np.sin(th)
        dx, dy = fp[f0 + 2], fp[f0 + 3]
        if frame == 1:
            dx, dy = c * dx - s * dy, s * dx + c * dy
        armx, army = c * fp[f0] - s * fp[f0 + 1], s * fp[f0] + c * fp[f0 + 1]
        _apply(F, b, nb, armx, army, mag * dx, mag * dy)
        _apply(Fnc, b, nb, armx, army, mag * dx, mag * dy)
    oi, of = ip[H_IOFF + S_TOR], ip[H_FOFF + S_TOR]
    for k in range(ip[H_NTOR]):
        i0 = oi + IR_TOR * k
        f0 = of + FR_TOR * k
        tq = _value(ip, fp, i0, f0, t, q, qdot)
        b = ip[i0 + IR_VAL]
        r = ip[i0 + IR_VAL + 1]
        if b < nb:
            F[3 * b + 2] += tq
            Fnc[3 * b + 2] += tq
        if r < nb:
            F[3 * r + 2] -= tq
            Fnc[3 * r + 2] -= tq
    oi, of = ip[H_IOFF + S_DRV], ip[H_FOFF + S_DRV]
    for k in range(ip[H_NDRV]):
        i0 = oi + IR_DRV * k
        f0 = of + FR_DRV * k
        Qd[ip[i0 + IR_VAL]] += _value(ip, fp, i0, f0, t, q, qdot)


@_njit
def _evaluate(t, q, qdot, ip, fp, ws, out):
    """q'' and P_nc at (t, q, qdot); out = [qdot | qddot | P_nc].  Status: 0 ok,
    1 position solve failed, 2 mass matrix not positive definite, 3 non-finite."""
    nb = ip[H_NB]
    nx = 3 * nb
    nq = ip[H_NQ]
    ls = fp[2]
    J = np.empty((nx, nx))
    piv = np.empty(nx, dtype=np.int64)
    F = np.empty(nx)
    ws[ws.size - N_FLAGS + W_COUNT] += 1.0
    st = _newton(q, ip, fp, ws, J, piv, F)
    if st != 0:
        return st
    x = ws[:nx]
    Bl = ws[nx + nq:nx + nq + nx * nq]
    v = ws[nx + nq + nx * nq:nx + nq + nx * nq + nx]
    flags = ws[ws.size - N_FLAGS:]
    # velocity analogs B (rows r, column c stored at r * nq + c)
    col = np.empty(nx)
    for c in range(nq):
        for r in range(nx):
            col[r] = 0.0
        col[nx - nq + c] = 1.0
        _lu_solve(J, piv, col, nx)
        for b in range(nb):
            col[3 * b + 2] *= ls
        for r in range(nx):
            Bl[r * nq + c] = col[r]
    flags[W_VALID] = 1.0
    for r in range(nx):
        s = 0.0
        for c in range(nq):
            s += Bl[r * nq + c] * qdot[c]
        v[r] = s
    # acceleration bias
    bb = np.empty(nx)
    _gamma(x, v, ip, fp, bb)
    _lu_solve(J, piv, bb, nx)
    for b in range(nb):
        bb[3 * b + 2] *= ls
    # mass matrix and c from the centre-of-mass analogs
    A = np.zeros((nq, nq))
    cc = np.zeros(nq)
    ob = ip[H_FOFF + S_BODY]
    bcx = np.empty(nq)
    bcy = np.empty(nq)
    for b in range(nb):
        m = fp[ob + FR_BODY * b]
        Jc = fp[ob + FR_BODY * b + 1]
        cx, cy = fp[ob + FR_BODY * b + 2], fp[ob + FR_BODY * b + 3]
        th = x[3 * b + 2]
        co, si = np.cos(th), np.sin(th)
        ax, ay = co * cx - si * cy, si * cx + co * cy
        w = v[3 * b + 2]
        for i in range(nq):
            bcx[i] = Bl[(3 * b) * nq + i] - ay * Bl[(3 * b + 2) * nq + i]
            bcy[i] = Bl[(3 * b + 1) * nq + i] + ax * Bl[(3 * b + 2) * nq + i]
        sx = bb[3 * b] - ay * bb[3 * b + 2] - w * w * ax
        sy = bb[3 * b + 1] + ax * bb[3 * b + 2] - w * w * ay
        sw = bb[3 * b + 2]
        for i in range(nq):
            bwi = Bl[(3 * b + 2) * nq + i]
            cc[i] += m * (bcx[i] * sx + bcy[i] * sy) + Jc * bwi * sw
            for j in range(i, nq):
                A[i, j] += m * (bcx[i] * bcx[j] + bcy[i] * bcy[j]) + \
                    Jc * bwi * Bl[(3 * b + 2) * nq + j]
    od_i, od_f = ip[H_IOFF + S_DRV], ip[H_FOFF + S_DRV]
    for k in range(ip[H_NDRV]):
        c = ip[od_i + IR_DRV * k + IR_VAL]
        A[c, c] += fp[od_f + FR_DRV * k + 2]
    for i in range(nq):
        for j in range(i):
            A[i, j] = A[j, i]
    # forces
    Fa = np.empty(nx)
    Fnc = np.empty(nx)
    Qd = np.empty(nq)
    _forces(t, q, qdot, x, v, ip, fp, Fa, Fnc, Qd)
    rhs = np.empty(nq)
    P = 0.0
    for r in range(nx):
        P += Fnc[r] * v[r]
    for c in range(nq):
        P += Qd[c] * qdot[c]
        s = Qd[c] - cc[c]
        for r in range(nx):
            s += Bl[r * nq + c] * Fa[r]
        rhs[c] = s
    # Cholesky A = L L^T (in the lower triangle of A)
    for j in range(nq):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return 2
        d = np.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, nq):
            s2 = A[i, j]
            for k in range(j):
                s2 -= A[i, k] * A[j, k]
            A[i, j] = s2 / d
    for i in range(nq):
        s = rhs[i]
        for k in range(i):
            s -= A[i, k] * rhs[k]
        rhs[i] = s / A[i, i]
    for i in range(nq - 1, -1, -1):
        s = rhs[i]
        for k in range(i + 1, nq):
            s -= A[k, i] * rhs[k]
        rhs[i] = s / A[i, i]
    ok = P == P
    for c in range(nq):
        out[c] = qdot[c]
        out[nq + c] = rhs[c]
        ok = ok and (rhs[c] - rhs[c] == 0.0)
    out[2 * nq] = P
    if not ok:
        return 3
    return 0


@_njit
def _first_order(t, y, ip, fp, ws, status):
    """y = (q, q', w) -> y' = (q', q'', P_nc); status[0] receives the kernel status."""
    nq = ip[H_NQ]
    out = np.empty(2 * nq + 1)
    status[0] = _evaluate(t, y[:nq], y[nq:2 * nq], ip, fp, ws, out)
    return out


@_njit
def _positions(q, ip, fp, ws):
    nx = 3 * ip[H_NB]
    J = np.empty((nx, nx))
    piv = np.empty(nx, dtype=np.int64)
    F = np.empty(nx)
    return _newton(q, ip, fp, ws, J, piv, F)


class CompiledKernel:
    """Compiled evaluation of one model's equations of motion, with its Newton cache.

    Attributes
    ----------
    compile_time : float
        Seconds spent compiling or loading the cached machine code for this kernel
        (first use in a process).
    status : int
        Status of the last call (0 ok, 1 position solve failed, 2 singular mass
        matrix, 3 non-finite).
    """

    STATUS = {0: "ok", 1: "position solve failed", 2: "mass matrix not positive definite",
              3: "non-finite values"}

    def __init__(self, ip, fp, n_x, n_q, compile_time):
        self.ip, self.fp = ip, fp
        self.n_x, self.n_q = n_x, n_q
        self.ws = np.zeros(n_x + n_q + n_x * n_q + 2 * n_x + N_FLAGS)
        self.compile_time = compile_time
        self.status = 0
        self._st = np.zeros(1, dtype=np.int64)

    @property
    def x(self) -> np.ndarray:
        """The last solved pose (n_x,) (a view)."""
        return self.ws[:self.n_x]

    @property
    def xdot(self) -> np.ndarray:
        """Body velocities (n_x,) of the last evaluation (a view)."""
        o = self.n_x + self.n_q + self.n_x * self.n_q
        return self.ws[o:o + self.n_x]

    @property
    def pivot_ratio(self) -> float:
        """min |u_ii| / max |u_ii| of the LU of the scaled position Jacobian (a cheap
        indicator of a near-singular position)."""
        return float(self.ws[-N_FLAGS + W_PIVOT])

    @property
    def B(self) -> np.ndarray:
        """Velocity analogs (n_x, n_q) of the last evaluation."""
        o = self.n_x + self.n_q
        return self.ws[o:o + self.n_x * self.n_q].reshape(self.n_x, self.n_q)

    def reset(self, x) -> None:
        """Restart the Newton continuation from pose x."""
        self.ws[:self.n_x] = x
        self.ws[-N_FLAGS + W_VALID] = 0.0

    def positions(self, q):
        """Solve the positions at q; returns x (a copy) or None on failure."""
        self.status = _positions(np.asarray(q, dtype=np.float64), self.ip, self.fp, self.ws)
        return None if self.status else self.ws[:self.n_x].copy()

    def rhs(self, t, q, qdot):
        """(q'', array([P_nc])) or None on failure (see ``status``)."""
        y = np.empty(2 * self.n_q + 1)
        y[:self.n_q] = q
        y[self.n_q:2 * self.n_q] = qdot
        out = _first_order(float(t), y, self.ip, self.fp, self.ws, self._st)
        self.status = int(self._st[0])
        if self.status:
            return None
        n = self.n_q
        return out[n:2 * n], out[2 * n:]

    @property
    def evaluations(self) -> int:
        """Evaluations of the equations by this kernel so far."""
        return int(self.ws[-N_FLAGS + W_COUNT])

    def first_order_function(self, on_failure):
        """A function ``fun(t, y) -> y'`` for y = (q, q', w) calling the kernel directly
        (the path with the least Python per evaluation); ``on_failure(t, y)`` is called
        (and must return y' or raise) when the kernel reports a failure."""
        ip, fp, ws, st = self.ip, self.fp, self.ws, self._st
        kern = _first_order

        def fun(t, y):
            out = kern(t, y, ip, fp, ws, st)
            if st[0]:
                self.status = int(st[0])
                return on_failure(t, y)
            return out

        return fun


_COMPILED = {"done": False, "time": 0.0}


def _warm_up(ip, fp, n_x, n_q):
    """Compile (or load from the cache) the kernels, once per process."""
    if _COMPILED["done"]:
        return 0.0
    t0 = time.perf_counter()
    ws = np.zeros(n_x + n_q + n_x * n_q + 2 * n_x + N_FLAGS)
    _positions(np.zeros(n_q), ip, fp, ws)
    _first_order(0.0, np.zeros(2 * n_q + 1), ip, fp, ws, np.zeros(1, dtype=np.int64))
    _COMPILED["done"] = True
    _COMPILED["time"] = time.perf_counter() - t0
    return _COMPILED["time"]


def compile_kernel(model, layout):
    """The compiled kernel of a model in one mode, or ``(None, reason)``.

    Returns
    -------
    kernel : CompiledKernel or None
    note : str
        Why the compiled path is not used, or ``""``.
    """
    if not _NUMBA:
        return None, "numba is not installed (pip install mechdyn[fast])"
    if model.n_x == 0 or model.n_q == 0:
        return None, "nothing to compile"
    if layout.n_rows + model.n_q != model.n_x:
        return None, "redundant constraints (non-square position Jacobian)"
    try:
        ip, fp = _Packer(model, layout).pack()
    except _Unsupported as exc:
        return None, str(exc)
    ct = _warm_up(ip, fp, model.n_x, model.n_q)
    return CompiledKernel(ip, fp, model.n_x, model.n_q, ct), ""
