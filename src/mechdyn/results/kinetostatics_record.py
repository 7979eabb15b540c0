"""The record of a kinetostatic analysis: :class:`Kinetostatics` (tables, summary,
harmonics of the frame loads).  Computed by :func:`mechdyn.kinetostatics.inverse.kinetostatics`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..brief import brief, number, status_text
from ..errors import ModelError, did_you_mean
from ..model import Model
from .records import KinetostaticsStats
from .table import coordinate_columns, force_columns, mode_columns

__all__ = ["Kinetostatics"]


@dataclass(frozen=True, repr=False)
class Kinetostatics:
    """Result of a kinetostatic (inverse-dynamics) analysis over ``n`` positions.

    Attributes
    ----------
    over : str
        The coordinate that labels the positions (the crank angle, usually).
    t : ndarray, shape (n,)
        Time, s (zeros for a static analysis).
    values : ndarray, shape (n,)
        Values of ``over`` (rad or m).
    q, qdot, qddot : ndarray, shape (n, n_q)
        All generalized coordinates and their rates, measured on the poses.
    x, xdot, xddot : ndarray, shape (n, n_x)
        Body-frame poses, velocities and accelerations.
    driven : tuple of str
        Coordinates whose motion is prescribed (each has a driving torque/force).
    reactions : dict str -> ndarray, shape (n, 2)
        Per joint, the force ON THE CHILD FROM THE PARENT at the joint point, in
        the ground frame, N.
    moments : dict str -> ndarray, shape (n,)
        Per joint, the moment on the child about the joint point, N m (zero for
        revolutes).
    joint_frame : dict str -> ndarray, shape (n, 2)
        The reaction in the joint frame: prismatic (tangential along the axis,
        normal = axis turned +90 deg); revolute and lock: components along the
        parent body's x and y axes.
    joint_points : dict str -> ndarray, shape (n, 2)
        Where each reaction acts (ground frame), m.
    driving : dict str -> ndarray, shape (n,)
        Torque (N m) or force (N) the drive must apply to each driven coordinate.
    power : dict str -> ndarray, shape (n,)
        Driving power ``driving * qdot`` per driven coordinate, W.
    frame_force : ndarray, shape (n, 2)
        Sum of all forces the frame receives (shaking force), N.
    frame_moment : ndarray, shape (n,)
        Sum of the moments the frame receives about ``frame_point`` (shaking
        moment), N m.
    frame_point : ndarray, shape (2,)
        The point of the frame moments, m.
    frame_loads : dict str -> ndarray, shape (n, 3)
        Per contributor (every joint to the ground by name, ``"drives"`` for
        the stator reactions, ``"loads"`` for spring/torque ends): force x, y
        (N) and moment about ``frame_point`` (N m) that the frame receives.
    multipliers : ndarray, shape (n, n_rows)
        Lagrange multipliers of the joint equations (layout row order; for a
        switched trajectory the row order of each sample's mode, NaN-padded).
    joint_kinds : dict str -> str
        "revolute", "prismatic" or "lock" for each reported joint.
    mode : frozenset of str
        Engaged locks (switched trajectory: every token active in some sample;
        see ``sample_modes``).
    redundant_joints : tuple of str
        Joints whose equations are linearly dependent (their reactions are not
        unique to rigid-body statics): shared by the joints' compliances where every
        one of them has a ``compliance`` (``stats.redundant_shared_by`` is
        ``"compliance"``, ``docs/indeterminacy.md``), else the minimum-norm solution.
    status : str
        "success", "redundant" (dependent joint equations, see ``redundant_joints``) or
        "singular-position" (positions where the driven coordinates lose control of the
        mechanism).
    message : str
    warnings : tuple of str
    stats : KinetostaticsStats
        Run figures (:class:`~mechdyn.results.records.KinetostaticsStats`): positions,
        seconds, position (Newton) solves, power-balance residual (relative), smallest
        rcond, ...; for a switched trajectory also ``segments`` (a
        :class:`~mechdyn.results.records.SegmentStats` per segment: mode, sample range,
        times, driven coordinates, status, power-balance residual).  Also read as the
        mapping it used to be (``stats["power_balance_rel"]``).
    element_forces : dict str -> ndarray, shape (n,)
        Switchable elements other than weld locks (coordinate locks, closed stops
        and contacts, ``"<contact>.tangent"`` for a sticking contact): the
        multiplier in the convention of ``mechdyn.simulate`` (``M xddot = F +
        Phi_x^T lambda``): the normal force of a stop or contact (>= 0 while it
        pushes), the torque (N m) or force (N) a coordinate lock applies along its
        variable.  NaN where the element is not active.
    element_units : dict str -> str
        "N" or "N m" for each entry of ``element_forces``.
    sample_modes : tuple of frozenset or None
        Switched trajectory: the mode of every sample (None otherwise).
    mode_index : ndarray of int, shape (n,), or None
        Switched trajectory: index of each sample's mode in ``modes``.
    modes : tuple of frozenset
        Switched trajectory: the distinct modes in order of appearance.
    losses : dict str -> ndarray, shape (n,)
        Models with friction in their pairs (``docs/friction.md``): the power lost in
        each pair with friction, W (>= 0); empty without friction.  With friction the
        reactions include it: a prismatic joint's tangential component is its friction
        force, a revolute joint's ``moments`` entry its friction moment on the child.
    power_out : ndarray, shape (n,), or None
        With friction: the useful output power, W: minus the power of the applied
        forces (loads, process forces, gravity, springs, dampers, drives kept as
        loads) on the motion, i.e. the power the mechanism delivers against them.
    locked : ndarray of bool, shape (n,), or None
        With friction: the self-locked positions (no finite driving torque moves the
        mechanism in the prescribed direction; their torques and reactions are NaN).
    """

    over: str
    t: np.ndarray
    values: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    coordinate_names: tuple
    driven: tuple
    reactions: dict
    moments: dict
    joint_frame: dict
    joint_points: dict
    driving: dict
    power: dict
    frame_force: np.ndarray
    frame_moment: np.ndarray
    frame_point: np.ndarray
    frame_loads: dict
    multipliers: np.ndarray
    joint_kinds: dict
    mode: frozenset
    redundant_joints: tuple
    status: str
    message: str
    warnings: tuple
    stats: KinetostaticsStats
    model: Model | None = field(default=None, compare=False)
    element_forces: dict = field(default_factory=dict)
    element_units: dict = field(default_factory=dict)
    sample_modes: tuple | None = None
    mode_index: np.ndarray | None = None
    modes: tuple = ()
    losses: dict = field(default_factory=dict)
    power_out: np.ndarray | None = None
    locked: np.ndarray | None = None

    def __repr__(self) -> str:
        peaks = []
        for c in self.driven[:2]:
            sym, unit = self._drive_unit(c)
            tau = np.asarray(self.driving[c], float)
            peak = float(np.nanmax(np.abs(tau))) if np.isfinite(tau).any() else None
            peaks.append(f"peak {sym}_drive_{c} {number(peak, 'N m' if sym == 'M' else 'N')}")
        return brief(self, f"{self.n} positions over {self.over!r}",
                     f"driven={list(self.driven)}", f"{len(self.reactions)} joints",
                     f"{len(self.modes)} modes" if self.switched else "",
                     status_text(self), *peaks)

    @property
    def switched(self) -> bool:
        """True for the analysis of a variable-structure (switched) trajectory."""
        return self.sample_modes is not None

    # ------------------------------------------------------------ helpers
    @property
    def n(self) -> int:
        """Number of positions."""
        return int(self.t.shape[0])

    @property
    def over_is_angle(self) -> bool:
        """True when ``over`` is an angle coordinate."""
        return self._is_angle(self.coordinate_names.index(self.over))

    def _is_angle(self, k: int) -> bool:
        return self.model is None or bool(self.model.coord_is_angle[k])

    def _drive_unit(self, name: str) -> tuple[str, str]:
        k = self.coordinate_names.index(name)
        return ("M", "Nm") if self._is_angle(k) else ("F", "N")

    def force_magnitude(self, joint: str) -> np.ndarray:
        """Resultant |R| of a joint reaction, N, shape (n,)."""
        R = self._reaction(joint)
        return np.hypot(R[:, 0], R[:, 1])

    def force_angle(self, joint: str) -> np.ndarray:
        """Direction angle of a joint reaction in the ground frame, rad (-pi, pi], shape (n,)."""
        R = self._reaction(joint)
        return np.arctan2(R[:, 1], R[:, 0])

    def _reaction(self, joint: str) -> np.ndarray:
        try:
            return self.reactions[joint]
        except KeyError:
            raise ModelError(did_you_mean(joint, self.reactions, "joint")) from None

    @property
    def driving_total_power(self) -> np.ndarray:
        """Sum of the driving powers, W, shape (n,)."""
        return sum(self.power.values(), np.zeros(self.n))

    # ------------------------------------------------------------ friction and efficiency
    @property
    def power_loss(self) -> np.ndarray:
        """Power lost in all the pairs, W, shape (n,) (zeros without friction)."""
        return sum(self.losses.values(), np.zeros(self.n))

    @property
    def efficiency(self) -> np.ndarray:
        """Instantaneous efficiency ``power_out / P_in``, shape (n,), ``P_in`` the total
        driving power; NaN where the drives do not deliver power (``P_in <= 0``: the
        loads drive the motion) or without friction data (``power_out`` None)."""
        if self.power_out is None:
            return np.full(self.n, np.nan)
        p_in = self.driving_total_power
        ok = p_in > 0
        return np.where(ok, self.power_out / np.where(ok, p_in, 1.0), np.nan)

    def energies(self) -> dict:
        """Energies over the analysed motion, J (trapezoidal rule in time): ``input``
        (the drives), ``output`` (useful, against the applied forces), ``losses`` (all
        pairs) and per pair ``loss_<joint>``; NaN for a static analysis, without
        friction data, or if a position is self-locked."""
        t = self.t
        moving = self.n > 1 and t[-1] > t[0] and self.power_out is not None

        def work(p):
            return float(np.trapezoid(p, t)) if moving else float("nan")

        out = {"input": work(self.driving_total_power),
               "output": work(self.power_out) if moving else float("nan"),
               "losses": work(self.power_loss)}
        out.update({f"loss_{j}": work(p) for j, p in self.losses.items()})
        return out

    @property
    def cycle_efficiency(self) -> float:
        """Efficiency over the analysed motion (a cycle): output energy / input energy
        (see :meth:`energies`)."""
        e = self.energies()
        return e["output"] / e["input"] if e["input"] != 0 else float("nan")

    # ------------------------------------------------------------ tables
    def to_dataframe(self):
        """One row per position, unit-suffixed columns.

        Columns: ``t_s``; per coordinate ``<c>_deg`` (or ``<c>_m``),
        ``<c>_dot_rad_s``, ``<c>_ddot_rad_s2`` (or m/s, m/s^2); per driven
        coordinate ``M_drive_<c>_Nm`` (``F_drive_<c>_N`` for a travel) and
        ``P_drive_<c>_W``; per joint ``Fx_<J>_N``, ``Fy_<J>_N``, ``F_<J>_N``,
        ``angle_F_<J>_deg``, for prismatic joints ``Ft_<J>_N``, ``Fn_<J>_N`` and
        ``M_<J>_Nm``, for locks ``M_<J>_Nm``; per joint to the ground
        ``Fx_frame_<J>_N``, ``Fy_frame_<J>_N``, ``M_frame_<J>_Nm``; and the
        totals ``Fx_frame_N``, ``Fy_frame_N``, ``F_frame_N``, ``M_frame_Nm``; with
        friction ``P_loss_<J>_W`` per pair with friction, ``P_loss_W``, ``P_out_W``
        (useful output power), ``efficiency`` (instantaneous) and ``self_locked``.
        """
        import pandas as pd

        cols: dict[str, np.ndarray] = {"t_s": self.t}
        if self.switched:
            cols.update(mode_columns(self.sample_modes, self.mode_index))
        is_angle = [self._is_angle(k) for k in range(len(self.coordinate_names))]
        cols.update(coordinate_columns(self.coordinate_names, is_angle, self.q, self.qdot,
                                       self.qddot, radians=False))
        for c in self.driven:
            sym, unit = self._drive_unit(c)
            cols[f"{sym}_drive_{c}_{unit}"] = self.driving[c]
            cols[f"P_drive_{c}_W"] = self.power[c]
        for j, R in self.reactions.items():
            cols.update(force_columns(j, R, magnitude=True))
            cols[f"angle_F_{j}_deg"] = np.rad2deg(np.arctan2(R[:, 1], R[:, 0]))
            kind = self.joint_kinds[j]
            if kind == "prismatic":
                cols[f"Ft_{j}_N"] = self.joint_frame[j][:, 0]
                cols[f"Fn_{j}_N"] = self.joint_frame[j][:, 1]
            if kind in ("prismatic", "lock"):
                cols[f"M_{j}_Nm"] = self.moments[j]
        for el, f in self.element_forces.items():
            sym, unit = ("M", "Nm") if self.element_units.get(el) == "N m" else ("F", "N")
            cols[f"{sym}_{el.replace('@', '_')}_{unit}"] = f
        for j, L in self.frame_loads.items():
            if j in self.reactions:
                cols.update(force_columns(f"frame_{j}", L))
        cols.update(force_columns("frame", self.frame_force, magnitude=True))
        cols["M_frame_Nm"] = self.frame_moment
        if self.power_out is not None:  # friction: losses and efficiency
            for j, p in self.losses.items():
                cols[f"P_loss_{j}_W"] = p
            cols["P_loss_W"] = self.power_loss
            cols["P_out_W"] = self.power_out
            cols["efficiency"] = self.efficiency
            cols["self_locked"] = self.locked
        return pd.DataFrame(cols)

    # ------------------------------------------------------------ summaries
    def rms(self, series) -> float:
        """RMS of a series over the positions, weighted by time when time advances
        (trapezoidal rule), else by position count."""
        y = np.asarray(series, dtype=float)
        t = self.t
        ok = np.isfinite(y)
        if not ok.all():  # time-weighted over each run of finite samples if time advances
            if not ok.any():
                return float("nan")
            if y.size > 1 and np.all(np.diff(t) >= 0) and t[-1] > t[0]:
                num = den = 0.0
                edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
                for a, b in zip(edges[0::2], edges[1::2], strict=True):
                    if t[b - 1] > t[a]:
                        num += float(np.trapezoid(y[a:b] ** 2, t[a:b]))
                        den += float(t[b - 1] - t[a])
                if den > 0:
                    return float(np.sqrt(num / den))
            return float(np.sqrt(np.mean(y[ok] ** 2)))
        if y.size < 2:
            return float(np.sqrt(np.mean(y**2)))
        if np.all(np.diff(t) > 0):
            return float(np.sqrt(np.trapezoid(y**2, t) / (t[-1] - t[0])))
        v = self.values
        if np.all(np.diff(v) > 0) or np.all(np.diff(v) < 0):
            return float(np.sqrt(np.trapezoid(y**2, v) / (v[-1] - v[0])))
        return float(np.sqrt(np.mean(y**2)))

    def _peak(self, y, name: str = "peak", rank=None) -> dict:
        """``name``, ``name_at`` (position) and ``name_t`` (time) of the sample of y where
        ``rank`` (default y) is largest, NaN samples aside."""
        r = np.asarray(y if rank is None else rank, dtype=float)
        ok = np.isfinite(r)
        k = int(np.argmax(np.where(ok, r, -np.inf))) if ok.any() else -1
        return {name: _at(y, k), f"{name}_at": _at(self.values, k), f"{name}_t": _at(self.t, k)}

    def peaks(self) -> dict:
        """The figures of :meth:`summary` as a dict (SI units; positions in ``over``'s unit;
        ``*_at`` the positions and ``*_t`` the times of the extremes)."""
        # NaN marks samples where a drive, joint or element is not part of the mode
        # (switched trajectories); extremes are taken over the others
        out: dict = {"driving": {}, "joints": {}, "elements": {}}
        for c in self.driven:
            m = self.driving[c]
            out["driving"][c] = {
                **self._peak(m, "peak_abs", np.abs(m)), **self._peak(m, "max"),
                **self._peak(m, "min", -m), "rms": self.rms(m), "mean": _nanext(m, np.nanmean),
                "peak_power": _nanext(np.abs(self.power[c]), np.nanmax)}
        for j in self.reactions:
            F = self.force_magnitude(j)
            out["joints"][j] = {**self._peak(F), "rms": self.rms(F)}
            if self.joint_kinds[j] != "revolute":
                M = self.moments[j]
                out["joints"][j].update(self._peak(M, "peak_moment", np.abs(M)))
        for el, f in self.element_forces.items():
            out["elements"][el] = {**self._peak(f, rank=np.abs(f)),
                                   "unit": self.element_units.get(el, "N")}
        Ff, Mf = np.hypot(self.frame_force[:, 0], self.frame_force[:, 1]), self.frame_moment
        out["frame"] = {**self._peak(Ff, "force_peak"),
                        **self._peak(Mf, "moment_peak", np.abs(Mf))}
        for key, y in (("Fx", self.frame_force[:, 0]), ("Fy", self.frame_force[:, 1]),
                       ("M", Mf)):
            out["frame"].update({f"{key}_min": _nanext(y, np.nanmin),
                                 f"{key}_max": _nanext(y, np.nanmax)})
        return out

    def summary(self) -> str:
        """Peak and RMS driving torque (motor sizing), peak force per joint and where,
        shaking force and moment extremes; warnings last."""
        p = self.peaks()
        unit, f = ("deg", np.rad2deg(1.0)) if self.over_is_angle else ("m", 1.0)
        lines = [f"kinetostatics over {self.over}: {self.n} positions, "
                 f"{self.over} from {self.values[0] * f:.4g} to {self.values[-1] * f:.4g} "
                 f"{unit}; status {self.status}"]

        def at(d, key, when=True):  # where an extreme is (and, switched, when)
            t = f" (t = {d[key + '_t']:.6g} s)" if when and self.switched else ""
            return f"{d[key + '_at'] * f:.4g} {unit}{t}"

        if self.switched:
            segs = self.stats.segments or ()
            lines.append(f"  switched trajectory: {len(segs)} segment(s) in {len(self.modes)} "
                         f"mode(s); the quantities of a joint, drive or element that is not "
                         f"part of a sample's mode are NaN there")
            for sg in segs:
                lines.append(f"    t = {sg.t_start:.6g} .. {sg.t_end:.6g} s, samples "
                             f"{sg.start}..{sg.stop - 1}, mode "
                             f"{{{', '.join(sorted(sg.mode))}}}: driven "
                             f"{', '.join(sg.driven) or '-'}; {sg.status}")
        for c, d in p["driving"].items():
            u = "N m" if self._drive_unit(c)[1] == "Nm" else "N"
            lines.append(
                f"  drive {c}: peak {d['peak_abs']:.6g} {u} at {self.over} = "
                f"{at(d, 'peak_abs')}; max {d['max']:.6g} {u} at {at(d, 'max', False)}; min "
                f"{d['min']:.6g} {u} at {at(d, 'min', False)}; RMS {d['rms']:.6g} {u}; mean "
                f"{d['mean']:.6g} {u}; peak power {d['peak_power']:.6g} W")
        for j, d in p["joints"].items():
            s = (f"  joint {j} ({self.joint_kinds[j]}): peak force {d['peak']:.6g} N at "
                 f"{self.over} = {at(d, 'peak')}")
            if "peak_moment" in d:
                s += f"; peak moment {d['peak_moment']:.6g} N m at {at(d, 'peak_moment')}"
            lines.append(s)
        for el, d in p["elements"].items():
            lines.append(f"  element {el}: peak {d['peak']:.6g} {d['unit']} at {self.over} = "
                         f"{at(d, 'peak')}")
        fr = p["frame"]
        lines.append(
            f"  frame: shaking force peak {fr['force_peak']:.6g} N at {self.over} = "
            f"{at(fr, 'force_peak', False)} (Fx {fr['Fx_min']:.6g}..{fr['Fx_max']:.6g} N,"
            f" Fy {fr['Fy_min']:.6g}..{fr['Fy_max']:.6g} N); shaking moment about "
            f"({self.frame_point[0]:.4g}, {self.frame_point[1]:.4g}) m: "
            f"{fr['M_min']:.6g}..{fr['M_max']:.6g} N m")
        if self.power_out is not None:
            lines.append(self._efficiency_line())
        for w in self.warnings:
            lines.append(f"  warning: {w}")
        return "\n".join(lines)

    def _efficiency_line(self) -> str:
        """The summary line of friction: cycle efficiency, energies, the lossiest pair,
        the instantaneous efficiency at the peak driving power and the self-locked
        positions."""
        e = self.energies()
        eta = self.efficiency
        s = (f"  friction: cycle efficiency {self.cycle_efficiency:.6g} (input "
             f"{e['input']:.6g} J, output {e['output']:.6g} J, losses {e['losses']:.6g} J")
        if self.losses:
            j = max(self.losses, key=lambda k: np.nan_to_num(e[f"loss_{k}"]))
            s += f", most in {j}: {e[f'loss_{j}']:.6g} J"
        s += ")"
        if np.isfinite(eta).any():  # at the peak driving power (the working stroke)
            k = int(np.nanargmax(self.driving_total_power))
            unit, f = ("deg", np.rad2deg(1.0)) if self.over_is_angle else ("m", 1.0)
            s += (f"; instantaneous efficiency at the peak driving power {eta[k]:.4g} "
                  f"({self.over} = {self.values[k] * f:.4g} {unit})")
        if self.locked is not None and self.locked.any():
            s += f"; {int(self.locked.sum())} self-locked position(s) (see the warnings)"
        return s

    def harmonics(self, n_orders: int | None = None):
        """Harmonics of the shaking force and moment per order of the ``over`` cycle.

        The positions must sample one full turn of an angle coordinate
        uniformly (an end point equal to the start point modulo 2 pi is
        dropped); at constant speed this is the Fourier series in time, order k
        at ``k`` times the crank frequency.

        Parameters
        ----------
        n_orders : int, optional
            Highest order returned (default: all, up to the Nyquist order).

        Returns
        -------
        pandas.DataFrame
            Columns ``order``, ``f_Hz`` (k times the mean crank frequency; NaN
            for a static analysis), and amplitude and phase of ``Fx_frame_N``,
            ``Fy_frame_N``, ``M_frame_Nm`` (columns ``<name>`` for the
            amplitude, ``<name>_phase_deg``) in the cosine series
            ``y = sum_k A_k cos(k |phi - phi_0| + phase_k)`` (angle travelled
            from the first position); order 0 is the (signed) mean.

        Raises
        ------
        ValueError
            If the samples are not one uniformly sampled turn.
        """
        import pandas as pd

        v = np.asarray(self.values, dtype=float)
        if not self.over_is_angle:
            raise ValueError(f"harmonics need an angle coordinate; {self.over!r} is a travel")
        n = v.size
        if n >= 2 and np.isclose(abs(v[-1] - v[0]), 2 * np.pi, rtol=1e-9, atol=1e-12):
            n -= 1  # the end point repeats the start point
        step = 2 * np.pi / n if n else np.nan
        if n < 4 or not np.allclose(np.abs(np.diff(v)), step, rtol=1e-6, atol=1e-12):
            raise ValueError(
                f"harmonics need one full turn of {self.over!r} sampled uniformly "
                f"(e.g. values = linspace(0, 2 pi, 361)); got {v.size} positions from "
                f"{np.rad2deg(v[0]):.6g} to {np.rad2deg(v[-1]):.6g} deg")
        series = {"Fx_frame_N": self.frame_force[:n, 0], "Fy_frame_N": self.frame_force[:n, 1],
                  "M_frame_Nm": self.frame_moment[:n]}
        kmax = n // 2 if n_orders is None else min(int(n_orders), n // 2)
        orders = np.arange(kmax + 1)
        tt = self.t
        period = (tt[n] - tt[0]) if n < tt.size else (tt[n - 1] - tt[0]) * n / (n - 1)
        freq = orders / period if period > 0 else orders * np.nan
        cols: dict = {"order": orders, "f_Hz": freq}
        for name, y in series.items():
            Y = np.fft.rfft(y)[: kmax + 1] / n
            amp = 2 * np.abs(Y)
            ph = np.angle(Y)
            amp[0], ph[0] = Y[0].real, 0.0
            if n % 2 == 0 and kmax == n // 2:
                amp[-1] = np.abs(Y[-1])
            cols[name] = amp
            cols[f"{name}_phase_deg"] = np.rad2deg(ph)
        return pd.DataFrame(cols)


def _at(y, k: int) -> float:
    return float(np.asarray(y)[k]) if k >= 0 else float("nan")


def _nanext(y, fn) -> float:
    y = np.asarray(y, dtype=float)
    return float(fn(y)) if np.isfinite(y).any() else float("nan")
