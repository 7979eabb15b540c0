"""The compiled (Numba) twin of the load evaluation of :mod:`mechdyn.model.forces`.

Gravity, springs and dampers, bushings, rotary springs, forces and torques of constant or
tabulated magnitude, and drives (constant, tabulated, torque-speed curves) are
packed by :class:`LoadPacker` into one integer and one float array; the
function :func:`forces` returns the applied forces on the body poses, their
non-conservative part and the drive torques on the declared coordinates.  A
load given by a Python callable raises :class:`Unsupported`: such a model runs
on the NumPy path.  ``tests/unit/test_tables.py`` and the dynamics tests check
the two paths against each other through whole runs.
"""

from __future__ import annotations

import numpy as np

from ..mechanism.drive import TorqueSpeedCurve
from ..mechanism.load import Bushing, Force, RotarySpring, Spring, Table, Torque
from .rows_numba import body_pose, njit
from .table_regions import region_value, sharp_breakpoints

__all__ = ["LoadPacker", "Unsupported", "forces", "body_inertia", "load_value", "interp",
           "H_NB", "H_NQ", "H_NDRV", "H_IOFF", "H_FOFF", "S_BODY", "S_DRV", "FR_BODY", "IR_DRV",
           "FR_DRV", "IR_VAL", "H_NTAB", "S_LOCK", "IR_LOCK"]

# header of the int array: counts, then section offsets
H_NB, H_NQ, H_NSPR, H_NROT, H_NFOR, H_NTOR, H_NDRV, H_NTAB, H_NBUS = range(9)
H_IOFF = 16  # int offsets of sections start here
H_FOFF = 32  # float offsets of sections start here
HEADER = 48
# sections (same index in the int and the float offset tables)
# (S_LOCK: a record per table whose piece the DOP853 loop holds through a step,
# :mod:`mechdyn.kernels.table_regions`: variable kind, variable index, table offset,
# points, flags)
S_BODY, S_SPR, S_ROT, S_FOR, S_TOR, S_DRV, S_TAB, S_LOCK, S_BUS = range(9)
N_SECTIONS = 9
IR_LOCK = 5
IR_SPR, FR_SPR = 2, 8
IR_ROT, FR_ROT = 2, 4
IR_BUS, FR_BUS = 2, 8  # body1, body2 | s1x, s1y, s2x, s2y, kx, ky, cx, cy
# value records (forces, torques, drives): mode, tab_off, tab_len, var_kind, var_index,
# table flags (T_OUTSIDE | T_PERIODIC | its hold slot << 2), then a target part; a table is
# stored in the table section as xs (tab_len), ys (tab_len) and, if periodic, its period;
# a table with sharp points has a hold slot (1, 2, ...: see S_LOCK), others 0
IR_VAL = 6
IR_FOR, FR_FOR = IR_VAL + 2, 5 + 1  # body, frame | sx, sy, dx, dy, value, outside
IR_TOR, FR_TOR = IR_VAL + 2, 2  # body, reaction | value, outside
IR_DRV, FR_DRV = IR_VAL + 1, 3  # coordinate | value, outside, extra inertia
FR_BODY = 4  # m, J, cx, cy
F_GLOBAL = 4  # gx, gy, length_scale, tol (at the start of the float array)
# value modes and table variables
V_CONST, V_TABLE = 0, 1
T_OUTSIDE, T_PERIODIC = 1, 2  # table flags
VAR_T, VAR_Q, VAR_QDOT, VAR_ROW = 0, 1, 2, 3  # VAR_ROW: a row of ``variable_rows``
_VAR_KINDS = {"t": VAR_T, "q": VAR_Q, "qdot": VAR_QDOT}


class Unsupported(Exception):
    """A load that the compiled path does not evaluate (the NumPy path is used)."""


class LoadPacker:
    """Pack a model's bodies, loads and drives into (ip, fp) for :func:`forces`.

    Parameters
    ----------
    model : Model
    force_model : ForceModel
        The model's parsed loads (:func:`mechdyn.model.forces.force_model`).
    variable : callable, optional
        ``variable(name) -> (kind, ref)`` resolves a table variable: ``("t", None)``,
        ``("q", k)`` or ``("qdot", k)`` for a declared coordinate k or its rate,
        ``("row", rows)`` for a one-row measure (a body point such as
        ``"slider.com.x"``, a joint, an angle), ``(None, None)`` for anything else.
        Measured rows are collected in :attr:`variable_rows`; their values reach
        :func:`forces` as ``varv``.
    """

    def __init__(self, model, force_model, variable=None):
        self.model, self.fm = model, force_model
        self.variable = variable
        #: rows measuring the table variables that are not coordinates (body points)
        self.variable_rows: list = []
        self._var_index: dict[str, int] = {}
        self.tabs: list[float] = []
        self.held: list[list[int]] = []  # the value records of the tables with a hold slot
        self.ints: dict[int, list[int]] = {s: [] for s in range(N_SECTIONS)}
        self.flts: dict[int, list[float]] = {s: [] for s in range(N_SECTIONS)}

    def value(self, v, where):
        """(int record, value, outside) of a load magnitude."""
        if isinstance(v, bool):
            raise Unsupported(f"{where}: boolean value")
        if isinstance(v, int | float | np.floating | np.integer):
            return [V_CONST, 0, 0, VAR_T, 0, 0], float(v), 0.0
        if isinstance(v, TorqueSpeedCurve):
            return self.table(v.omega, v.torque, VAR_QDOT, -1, None)
        if isinstance(v, Table):
            var = v.variable
            kind, ref = self.variable(var) if self.variable is not None else (None, None)
            if kind == "row":
                if var not in self._var_index:
                    self._var_index[var] = len(self.variable_rows)
                    self.variable_rows.append(ref)
                kind, idx = VAR_ROW, self._var_index[var]
            elif kind in _VAR_KINDS:
                kind, idx = _VAR_KINDS[kind], int(ref or 0)
            else:
                raise Unsupported(f"{where}: table over {var!r} is evaluated on the NumPy "
                                  f"path")
            return self.table(v.x, v.y, kind, idx, v.outside, v.period)
        raise Unsupported(f"{where}: value {type(v).__name__} is not compiled "
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
        rec = [V_TABLE, off, len(xs), kind, idx, flags]
        if sharp_breakpoints(xs, ys, outside, period).size:
            self.held.append(rec)
            rec[5] |= len(self.held) << 2
        return rec, 0.0, 0.0 if outside is None else float(outside)

    def pack(self):
        m, fm = self.model, self.fm
        nb = m.n_bodies
        for k in range(nb):
            self.flts[S_BODY] += [m.mass[k], m.inertia[k], m.com[k, 0], m.com[k, 1]]
        for (_, i, si, j, sj, k, L0, c, pre) in fm.springs:
            self.ints[S_SPR] += [int(i), int(j)]
            self.flts[S_SPR] += [*si, *sj, k, L0, c, pre]
        for (_, i, si, j, sj, kx, ky, cx, cy) in fm.bushings:
            self.ints[S_BUS] += [int(i), int(j)]
            self.flts[S_BUS] += [*si, *sj, kx, ky, cx, cy]
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
                    raise Unsupported(f"drive {dr.name!r}: characteristic "
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
                 if not isinstance(ld, Spring | Bushing | RotarySpring | Force | Torque)]
        if extra:
            raise Unsupported(f"load {getattr(extra[0], 'name', '?')!r} "
                               f"({type(extra[0]).__name__}) is evaluated on the NumPy path")
        self.flts[S_TAB] = self.tabs
        for rec in self.held:  # variable kind and index as patched above
            self.ints[S_LOCK] += [rec[3], rec[4], rec[1], rec[2], rec[5]]

        head = np.zeros(HEADER, dtype=np.int64)
        head[H_NB], head[H_NQ] = nb, m.n_q
        head[H_NSPR], head[H_NROT] = len(fm.springs), len(fm.rotary)
        head[H_NFOR], head[H_NTOR], head[H_NDRV] = len(fm.forces), len(fm.torques), len(fm.drives)
        head[H_NTAB] = len(self.held)
        head[H_NBUS] = len(fm.bushings)
        ip_parts, fp_parts = [head], [np.array([*m.gravity, m.length_scale,
                                                1e-13 * max(m.length_scale, 1e-3)])]
        ioff, foff = HEADER, F_GLOBAL
        for s in range(N_SECTIONS):
            head[H_IOFF + s] = ioff
            head[H_FOFF + s] = foff
            a = np.array(self.ints[s], dtype=np.int64)
            f = np.array(self.flts[s], dtype=np.float64)
            ip_parts.append(a)
            fp_parts.append(f)
            ioff += a.size
            foff += f.size
        return np.concatenate(ip_parts).astype(np.int64), np.concatenate(fp_parts)


@njit
def interp(xs, ys, n, s, has_out, outside):
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


@njit
def load_value(ip, fp, irec, fval, t, q, qdot, varv, locks):
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
    elif kind == 2:
        s = qdot[idx]
    else:
        s = varv[idx]
    flags = ip[irec + 5]
    slot = flags >> 2
    if slot > 0 and 2 * slot <= locks.size and locks[2 * slot - 2] > 0.0:  # a held piece
        per = fp[tab0 + 2 * n] if flags & 2 else 0.0
        return region_value(fp[tab0:tab0 + n], fp[tab0 + n:tab0 + 2 * n], n, per,
                            int(locks[2 * slot - 2]) - 1, locks[2 * slot - 1], s,
                            (flags & 1) == 1, fp[fval + 1])
    if flags & 2:  # T_PERIODIC: wrap into [x0, x0 + period), as Table.wrap
        x0 = fp[tab0]
        per = fp[tab0 + 2 * n]
        u = (s - x0) % per
        if u >= per:
            u = 0.0
        s = x0 + u
    return interp(fp[tab0:tab0 + n], fp[tab0 + n:tab0 + 2 * n], n, s, (flags & 1) == 1,
                   fp[fval + 1])


@njit
def body_inertia(fp, ob, b, cs):
    """Mass, inertia about the centre of mass and the centre-of-mass arm A(theta) c
    (ground frame) of body b; ``cs`` the bodies' rotations at the pose
    (:func:`~mechdyn.kernels.rows_numba.body_rotations`)."""
    m = fp[ob + FR_BODY * b]
    Jc = fp[ob + FR_BODY * b + 1]
    cx, cy = fp[ob + FR_BODY * b + 2], fp[ob + FR_BODY * b + 3]
    co, si = cs[b, 0], cs[b, 1]
    return m, Jc, co * cx - si * cy, si * cx + co * cy


@njit
def _apply(F, b, nb, armx, army, fx, fy):
    if b < nb:
        F[3 * b] += fx
        F[3 * b + 1] += fy
        F[3 * b + 2] += armx * fy - army * fx


@njit
def _ends(x, v, nb, cs, fp, f0, i, j):
    """The two ends of a spring or bushing, at ``fp[f0:f0 + 4]`` on bodies i and j (nb:
    the ground): their arms (aix, aiy, ajx, ajy), the vector from end i to end j, the
    velocity of end j less that of end i, and body i's angular velocity."""
    xi, yi, _ = body_pose(x, nb, i)
    vxi, vyi, wi = body_pose(v, nb, i)
    xj, yj, _ = body_pose(x, nb, j)
    vxj, vyj, wj = body_pose(v, nb, j)
    ci, si = cs[min(i, nb), 0], cs[min(i, nb), 1]
    cj, sj = cs[min(j, nb), 0], cs[min(j, nb), 1]
    aix, aiy = ci * fp[f0] - si * fp[f0 + 1], si * fp[f0] + ci * fp[f0 + 1]
    ajx, ajy = cj * fp[f0 + 2] - sj * fp[f0 + 3], sj * fp[f0 + 2] + cj * fp[f0 + 3]
    return (aix, aiy, ajx, ajy, xj + ajx - xi - aix, yj + ajy - yi - aiy,
            vxj - wj * ajy - vxi + wi * aiy, vyj + wj * ajx - vyi - wi * aix, wi)


@njit
def forces(t, q, qdot, x, v, ip, fp, F, Fnc, Qd, varv, locks, cs):
    """Applied forces F (all) and Fnc (non-conservative part) on the poses, drives Qd.
    ``locks``: the held table pieces, ``[region + 1, period count]`` per hold slot (0:
    none; an empty array holds none); ``cs`` the bodies' rotations at x
    (:func:`~mechdyn.kernels.rows_numba.body_rotations`, the ground's in row nb)."""
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
        m, _, ax, ay = body_inertia(fp, ob, b, cs)
        _apply(F, b, nb, ax, ay, m * gx, m * gy)
    oi, of = ip[H_IOFF + S_SPR], ip[H_FOFF + S_SPR]
    for k in range(ip[H_NSPR]):
        i = ip[oi + IR_SPR * k]
        j = ip[oi + IR_SPR * k + 1]
        f0 = of + FR_SPR * k
        aix, aiy, ajx, ajy, dx, dy, vdx, vdy, _ = _ends(x, v, nb, cs, fp, f0, i, j)
        L = np.sqrt(dx * dx + dy * dy)
        ex, ey = dx / L, dy / L
        fc = fp[f0 + 4] * (L - fp[f0 + 5]) + fp[f0 + 7]
        fd = fp[f0 + 6] * (ex * vdx + ey * vdy)
        f = fc + fd
        _apply(F, i, nb, aix, aiy, f * ex, f * ey)
        _apply(F, j, nb, ajx, ajy, -f * ex, -f * ey)
        _apply(Fnc, i, nb, aix, aiy, fd * ex, fd * ey)
        _apply(Fnc, j, nb, ajx, ajy, -fd * ex, -fd * ey)
    oi, of = ip[H_IOFF + S_BUS], ip[H_FOFF + S_BUS]
    for k in range(ip[H_NBUS]):
        # d = A_i^T (r_j - r_i) in body i's axes; -A_i (K d + C d') on j, the opposite on
        # i where end j is (the twin of pair_loads.BushingSet)
        i = ip[oi + IR_BUS * k]
        j = ip[oi + IR_BUS * k + 1]
        f0 = of + FR_BUS * k
        aix, aiy, ajx, ajy, ddx, ddy, vdx, vdy, wi = _ends(x, v, nb, cs, fp, f0, i, j)
        aix, aiy = aix + ddx, aiy + ddy  # body i's arm to end j, and its point's velocity
        vdx, vdy = vdx + wi * ddy, vdy - wi * ddx
        ci, si = cs[min(i, nb), 0], cs[min(i, nb), 1]
        fcx = fp[f0 + 4] * (ci * ddx + si * ddy)
        fcy = fp[f0 + 5] * (ci * ddy - si * ddx)
        fdx = fp[f0 + 6] * (ci * vdx + si * vdy)
        fdy = fp[f0 + 7] * (ci * vdy - si * vdx)
        fx, fy = ci * (fcx + fdx) - si * (fcy + fdy), si * (fcx + fdx) + ci * (fcy + fdy)
        _apply(F, i, nb, aix, aiy, fx, fy)
        _apply(F, j, nb, ajx, ajy, -fx, -fy)
        fx, fy = ci * fdx - si * fdy, si * fdx + ci * fdy
        _apply(Fnc, i, nb, aix, aiy, fx, fy)
        _apply(Fnc, j, nb, ajx, ajy, -fx, -fy)
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
        mag = load_value(ip, fp, i0, f0 + 4, t, q, qdot, varv, locks)
        b = ip[i0 + IR_VAL]
        frame = ip[i0 + IR_VAL + 1]
        c, s = cs[min(b, nb), 0], cs[min(b, nb), 1]
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
        tq = load_value(ip, fp, i0, f0, t, q, qdot, varv, locks)
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
        Qd[ip[i0 + IR_VAL]] += load_value(ip, fp, i0, f0, t, q, qdot, varv, locks)
