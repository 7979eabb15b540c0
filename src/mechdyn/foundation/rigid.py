"""Rigid frame: the load a machine sends into its frame, shared among the supports.

The frame and its base form one rigid body on the supports, each a linear spring.
A load (Fx, Fy, M about a point) on the base displaces it by u = K^-1 f (see
:mod:`mechdyn.foundation.supports`); support i then carries k_i T_i u.  This shares a
statically indeterminate load by stiffness, and the support forces add up to the load
exactly: sum_i T_i^T k_i T_i u = K u = f.

Sign convention: a support force is the force the support passes ON TO THE FLOOR,
positive along +x / +y (for a bolt: axial share > 0 pulls the floor up, i.e. uplift);
the floor pushes back on the base with the opposite.  The frame loads of mechdyn are
the load the machine exerts ON its frame, so they enter as they are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..brief import brief, number
from ..errors import ModelError
from .frame_loads import frame_loads
from .supports import AnchorBolt, Foundation, shift_moment, support_matrix

__all__ = ["SupportLoads", "distribute", "bolt_forces", "support_loads"]


@dataclass(frozen=True, repr=False)
class SupportLoads:
    """The loads of every support over a load history of ``n`` samples.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s.
    names : tuple of str
        Support names.
    fx, fy : dict str -> ndarray, shape (n,)
        Force each support passes to the floor, N (bolts: shear = fx, axial share = fy).
    tension, clamp : dict str -> ndarray, shape (n,)
        Anchor bolts only: bolt tension (N, > 0 pulls) and clamp (contact) force of the
        joint (N, > 0 presses), preload included.
    applied : ndarray, shape (n, 3)
        The load on the base: Fx, Fy (N) and moment about ``point`` (N m).
    point : ndarray, shape (2,)
        The point of the moments, m.
    """

    t: np.ndarray
    names: tuple
    fx: dict
    fy: dict
    tension: dict
    clamp: dict
    applied: np.ndarray
    point: np.ndarray

    def __repr__(self) -> str:
        peak = np.hypot(self.applied[:, 0], self.applied[:, 1]) if self.t.size else []
        opening = self.first_opening
        return brief(self, f"{self.t.size} samples", f"supports={list(self.names)[:6]}",
                     f"peak |F| on the base {number(np.max(peak) if len(peak) else None, 'N')}",
                     "" if not self.tension else "no bolt opens" if opening is None else
                     f"{opening[0]!r} opens at {number(opening[1], 's')}")

    @property
    def first_opening(self) -> tuple[str, float] | None:
        """(name, time in s) of the first bolt whose clamp force falls to zero (the joint
        opens: the bolt has lost its preload), or None.

        The time is interpolated linearly between the samples around the crossing."""
        best = None
        for name, c in self.clamp.items():
            k = np.flatnonzero(c <= 0.0)
            if not k.size:
                continue
            i = int(k[0])
            t = float(self.t[i])
            if i > 0 and c[i - 1] > 0.0:
                t = float(self.t[i - 1] + (self.t[i] - self.t[i - 1]) * c[i - 1]
                          / (c[i - 1] - c[i]))
            if best is None or t < best[1]:
                best = (name, t)
        return best

    def peaks(self) -> dict:
        """Per support: largest |fx|, |fy|, |resultant| (N), and for bolts the largest
        tension and the smallest clamp force (N), each with its time (s)."""
        out = {}
        for name in self.names:
            row: dict = {}
            f = np.hypot(self.fx[name], self.fy[name])
            for key, y in (("fx", np.abs(self.fx[name])), ("fy", np.abs(self.fy[name])),
                           ("resultant", f), ("tension", self.tension.get(name))):
                if y is not None and y.size:
                    k = int(np.nanargmax(y))
                    row[f"{key}_max_N"], row[f"{key}_max_t_s"] = float(y[k]), float(self.t[k])
            c = self.clamp.get(name)
            if c is not None and c.size:
                k = int(np.nanargmin(c))
                row["clamp_min_N"], row["clamp_min_t_s"] = float(c[k]), float(self.t[k])
            out[name] = row
        return out

    def to_dataframe(self):
        """A pandas DataFrame, one row per sample: ``t_s``, the applied load
        (``Fx_base_N``, ``Fy_base_N``, ``M_base_Nm``), and per support the forces it
        passes to the floor, ``Fx_<name>_N`` (bolts: the shear ``V_<name>_N``) and
        ``Fy_<name>_N`` (bolts: the axial share, uplift > 0), for bolts also the tension
        ``N_<name>_N`` and the clamp force ``clamp_<name>_N``."""
        import pandas as pd

        cols = {"t_s": self.t, "Fx_base_N": self.applied[:, 0],
                "Fy_base_N": self.applied[:, 1], "M_base_Nm": self.applied[:, 2]}
        for name in self.names:
            cols[f"{'V' if name in self.tension else 'Fx'}_{name}_N"] = self.fx[name]
            cols[f"Fy_{name}_N"] = self.fy[name]
            if name in self.tension:
                cols[f"N_{name}_N"] = self.tension[name]
                cols[f"clamp_{name}_N"] = self.clamp[name]
        return pd.DataFrame(cols)

    def summary(self) -> str:
        """Lines: the peaks per support and the first opening."""
        lines = []
        for name, p in self.peaks().items():
            text = f"  {name}: |F| max {p['resultant_max_N'] / 1e3:.4g} kN at " \
                   f"{p['resultant_max_t_s']:.4g} s"
            if "tension_max_N" in p:
                text += (f"; tension max {p['tension_max_N'] / 1e3:.4g} kN, clamp min "
                         f"{p['clamp_min_N'] / 1e3:.4g} kN at {p['clamp_min_t_s']:.4g} s")
            lines.append(text)
        opening = self.first_opening
        lines.append("  no bolt joint opens" if opening is None else
                     f"  first to open: {opening[0]} at t = {opening[1]:.6g} s")
        return "\n".join(lines)


def bolt_forces(bolt: AnchorBolt, share) -> tuple[np.ndarray, np.ndarray]:
    """Tension and clamp force of a bolt for its axial share (uplift > 0), N.

    With ``bolt.load_factor`` None: the bounds on the safe side, tension
    ``preload + max(share, 0)``, clamp ``preload - share``.  With a load factor Phi:
    while the joint is closed tension ``preload + Phi share`` and clamp
    ``preload - (1 - Phi) share``; once open, tension ``share`` and clamp 0.

    Examples
    --------
    >>> b = AnchorBolt("b", 0.0, 0.0, 1e8, 1e8, preload=1000.0)
    >>> [v.tolist() for v in bolt_forces(b, [-500.0, 400.0, 1500.0])]
    [[1000.0, 1400.0, 2500.0], [1500.0, 600.0, -500.0]]
    """
    s = np.asarray(share, float)
    P, phi = float(bolt.preload), bolt.load_factor
    if phi is None:
        return P + np.maximum(s, 0.0), P - s
    clamp = P - (1.0 - phi) * s
    open_ = clamp <= 0.0
    return np.where(open_, s, P + phi * s), np.where(open_, 0.0, clamp)


def distribute(foundation: Foundation, Fx, Fy, M, point=(0.0, 0.0), t=None,
               gravity=None) -> SupportLoads:
    """Share a load history on the rigid base among the supports, by stiffness.

    Parameters
    ----------
    foundation : Foundation
    Fx, Fy : array_like, shape (n,)
        Force the machine exerts on its frame (and so on the base), N.
    M : array_like, shape (n,)
        Its moment about ``point``, N m (counter-clockwise positive).
    point : (float, float)
        The point of ``M``, m.
    t : array_like, shape (n,), optional
        Times, s (default 0, 1, 2, ...).
    gravity : (float, float), optional
        Add the weight of the frame and base, ``foundation.mass`` times this (m/s^2, e.g.
        ``(0, -9.81)``), at ``foundation.com`` (default: not added).

    Returns
    -------
    SupportLoads
        Force per support passed to the floor (see the module's sign convention); their
        sum is the load (Fx, Fy) and their moment about ``point`` is M (weight included),
        to round-off.

    Raises
    ------
    ModelError
        Arrays of different lengths or non-finite values; ``gravity`` without
        ``foundation.mass``.

    Examples
    --------
    Two bolts at x = -/+0.5 m, a 10 kN uplift at the middle and a 1 kN m moment:

    >>> from mechdyn.foundation import AnchorBolt, Foundation
    >>> f = Foundation([AnchorBolt("L", -0.5, 0.0, 1e8, 1e8, preload=8e3),
    ...                 AnchorBolt("R", 0.5, 0.0, 1e8, 1e8, preload=8e3)])
    >>> s = distribute(f, [0.0], [1e4], [1e3])
    >>> np.round([s.fy["L"][0], s.fy["R"][0], s.clamp["R"][0]], 6).tolist()
    [4000.0, 6000.0, 2000.0]
    >>> print(s.first_opening)
    None
    """
    columns = [np.atleast_1d(np.asarray(v, float)) for v in (Fx, Fy, M)]
    if len({c.shape for c in columns}) != 1:
        raise ModelError("distribute: Fx, Fy and M must have the same length")
    load = np.column_stack(columns)
    n = load.shape[0]
    t = np.arange(n, dtype=float) if t is None else np.atleast_1d(np.asarray(t, float))
    if t.shape != (n,):
        raise ModelError(f"distribute: t has {t.size} samples, the loads {n}")
    if not np.all(np.isfinite(load)):
        raise ModelError("distribute: the load history has non-finite values (a run that "
                         "stopped early? drop its NaN rows)")
    point = np.asarray(point, float)
    if gravity is not None:
        load = load + _weight(foundation, gravity, point)
    u = np.linalg.solve(foundation.stiffness_matrix(point), load.T).T  # (n, 3)
    T = support_matrix(foundation.supports, point)
    f = np.einsum("sk,ski,ni->nsk", foundation.stiffnesses(), T, u)  # (n, s, 2)
    fx = {s.name: f[:, i, 0] for i, s in enumerate(foundation.supports)}
    fy = {s.name: f[:, i, 1] for i, s in enumerate(foundation.supports)}
    tension, clamp = {}, {}
    for s in foundation.supports:
        if isinstance(s, AnchorBolt):
            tension[s.name], clamp[s.name] = bolt_forces(s, fy[s.name])
    return SupportLoads(t=t, names=foundation.names, fx=fx, fy=fy, tension=tension,
                        clamp=clamp, applied=load, point=point)


def _weight(foundation: Foundation, gravity, point) -> np.ndarray:
    """(Fx, Fy, M about ``point``) of the weight of the frame and base, shape (3,)."""
    if foundation.mass is None:
        raise ModelError("distribute: the weight of the base needs the foundation's mass")
    g = np.asarray(gravity, float)
    if g.shape != (2,) or not np.all(np.isfinite(g)):
        raise ModelError(f"distribute: gravity must be a finite (gx, gy) in m/s^2, got "
                         f"{gravity!r}")
    return shift_moment([*(foundation.mass * g), 0.0], foundation.com, point)


def support_loads(foundation: Foundation, source, point=None, gravity=None) -> SupportLoads:
    """The loads of every support over a run: :func:`distribute` of its frame loads.

    Parameters
    ----------
    foundation : Foundation
    source : Trajectory, Kinetostatics or pandas.DataFrame
        What :func:`mechdyn.foundation.frame_loads.frame_loads` reads: the load the
        machine exerts ON its frame, ``Fx_frame_N``, ``Fy_frame_N``, ``M_frame_Nm``.
    point : (float, float), optional
        The point of ``M_frame_Nm``, m (default: the record's ``frame_point``, else the
        ground origin; give the ``point`` of ``simulate(..., point=...)`` if one was used).
    gravity : (float, float), optional
        Add the weight of the frame and base (see :func:`distribute`), e.g. the model's
        ``gravity``.

    Returns
    -------
    SupportLoads
        The forces the supports pass to the floor (the floor pushes back on the base
        with the opposite), bolt tension and clamp force with the preload.

    Examples
    --------
    >>> import pandas as pd
    >>> from mechdyn.foundation import AnchorBolt, Foundation
    >>> f = Foundation([AnchorBolt("L", -0.5, 0.0, 1e8, 1e8, preload=1e3),
    ...                 AnchorBolt("R", 0.5, 0.0, 1e8, 1e8, preload=1e3)])
    >>> df = pd.DataFrame({"t_s": [0.0, 1.0], "Fx_frame_N": [0.0, 0.0],
    ...                    "Fy_frame_N": [0.0, 0.0], "M_frame_Nm": [0.0, 2e3]})
    >>> name, t = support_loads(f, df).first_opening
    >>> name, round(t, 9)
    ('R', 0.5)
    """
    h = frame_loads(source, point)
    return distribute(foundation, h.Fx, h.Fy, h.M, point=h.point, t=h.t, gravity=gravity)
