"""The machine on a rigid frame and on its isolators, side by side.

:func:`compare_mounting` runs the machine twice on the one engine: on its fixed frame
(the rigid case) and :func:`~mechdyn.foundation.mounting.mounted` on its isolators
(two-way coupled), and beside them the one-way linear prediction: the rigid run's
frame loads applied to the base on its isolators (:func:`mounted_response`).  All three
give the force passed to the floor (the weights of machine and base included) and the
motion of the base.  Both mounted cases start with the base in its static deflection
under the rigid run's first frame load (inertia included), so that they differ only by
the feedback of the base's motion into the machine.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..brief import brief, number
from ..errors import ModelError
from ..kernels.planar import cross, rotate
from ..mechanism import Mechanism
from .frame_loads import frame_loads
from .mounting import _foundation, base_coordinates, isolator_forces, mounted, to_centre_of_mass
from .response import MountedResponse, mounted_response
from .supports import Foundation, shift_moment

__all__ = ["floor_forces", "MountingComparison", "compare_mounting"]


def floor_forces(trajectory, foundation: Foundation, base: str = "base",
                 point=(0.0, 0.0)) -> MountedResponse:
    """The isolators' forces on the floor over a run of a :func:`mounted` machine, from the
    base's coordinates (:func:`~mechdyn.foundation.mounting.isolator_forces`).

    Parameters
    ----------
    trajectory : Trajectory
        A run of ``mounted(mechanism, foundation, base)``.
    foundation : Foundation
    base : str
    point : (float, float)
        Point of the moment, m.

    Returns
    -------
    MountedResponse
        The base's displacement ``u`` and velocity ``v`` from its sketch position (where
        the isolators are unloaded), the isolators' forces on the floor, ``floor`` and
        per isolator ``supports``.

    Raises
    ------
    ModelError
        The run has no coordinates of that base.
    """
    names = list(trajectory.coordinate_names)
    missing = [c for c in base_coordinates(base) if c not in names]
    if missing:
        raise ModelError(f"floor_forces: the run has no coordinate(s) {', '.join(missing)}; "
                         f"it is not a run of mounted(..., base={base!r}) (coordinates: "
                         f"{', '.join(names)})")
    idx = [names.index(c) for c in base_coordinates(base)]
    u, v = trajectory.q[:, idx], trajectory.qdot[:, idx]
    per = isolator_forces(foundation, u, v)  # (n, iso, 2) on the floor
    # where the base points are: the floor takes the forces there
    at = rotate(u[:, 2, None], foundation.positions()) + u[:, None, :2] - np.asarray(point, float)
    m = np.sum(cross(at, per), axis=1)
    floor = np.column_stack([per.sum(axis=1), m])
    u, v = to_centre_of_mass(foundation, u, v)
    return MountedResponse(t=np.asarray(trajectory.t, float), u=u, v=v, floor=floor,
                       supports={n: per[:, i] for i, n in enumerate(foundation.names)},
                       point=np.asarray(point, float))


def _stats(F) -> dict:
    F = np.asarray(F, float)
    F = F[np.all(np.isfinite(F), axis=1)]  # a run that stopped early: its samples
    mag = np.hypot(F[:, 0], F[:, 1])
    dyn = F - F.mean(axis=0)
    return {"peak_N": float(mag.max()), "peak_Fx_N": float(np.abs(F[:, 0]).max()),
            "peak_Fy_N": float(np.abs(F[:, 1]).max()),
            "rms_dFx_N": float(np.sqrt(np.mean(dyn[:, 0] ** 2))),
            "rms_dFy_N": float(np.sqrt(np.mean(dyn[:, 1] ** 2)))}


@dataclass(frozen=True, repr=False)
class MountingComparison:
    """Rigid frame, one-way linear prediction and coupled mounting, on one time grid.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s.
    rigid : ndarray, shape (n, 3)
        Load a rigid base passes to the floor: the rigid run's frame loads plus the
        base's weight (Fx, Fy N, M about ``point`` N m).
    one_way : MountedResponse
        The base on its isolators under ``rigid`` (no feedback into the machine).
    coupled : MountedResponse
        The coupled run's isolator forces and base motion (:func:`floor_forces`).
    rigid_run, coupled_run : Trajectory
        The two runs.
    point : ndarray, shape (2,)
    """

    t: np.ndarray
    rigid: np.ndarray
    one_way: MountedResponse
    coupled: MountedResponse
    rigid_run: object
    coupled_run: object
    point: np.ndarray

    def __repr__(self) -> str:
        s = self.statistics()
        return brief(self, f"{self.t.size} samples", "peak |F| to the floor: " + ", ".join(
            f"{k} {number(s[k]['peak_N'], 'N')}" for k in ("rigid", "one_way", "coupled")),
            model=getattr(getattr(getattr(self.rigid_run, "model", None), "mechanism", None),
                          "name", None))

    def statistics(self) -> dict:
        """Peak force magnitude, peak |Fx|, |Fy| and RMS of the fluctuation of Fx, Fy about
        their means (N), and the peak base motion, for ``"rigid"``, ``"one_way"`` and
        ``"coupled"`` (over the samples a run reached)."""
        out = {"rigid": _stats(self.rigid), "one_way": _stats(self.one_way.floor),
               "coupled": _stats(self.coupled.floor)}
        for key, u in (("one_way", self.one_way.u), ("coupled", self.coupled.u)):
            u = u[np.all(np.isfinite(u), axis=1)]
            d = u - u[0]
            out[key].update(peak_dx_m=float(np.abs(d[:, 0]).max()),
                            peak_dy_m=float(np.abs(d[:, 1]).max()),
                            peak_dtheta_rad=float(np.abs(d[:, 2]).max()))
        return out

    def summary(self) -> str:
        """A text table of :meth:`statistics` (kN, mm, mrad)."""
        s = self.statistics()
        rows = [f"  {'(weights included)':32s}{'rigid':>12s}{'one-way':>12s}{'coupled':>12s}"]
        for key, label in (("peak_N", "peak |F| to floor, kN"), ("peak_Fx_N", "peak |Fx|, kN"),
                           ("peak_Fy_N", "peak |Fy|, kN"), ("rms_dFx_N", "RMS of Fx - mean, kN"),
                           ("rms_dFy_N", "RMS of Fy - mean, kN")):
            rows.append(f"  {label:32s}" + "".join(f"{s[c][key] / 1e3:12.5g}" for c in
                                                 ("rigid", "one_way", "coupled")))
        for key, label, scale in (("peak_dx_m", "base motion x from start, mm", 1e3),
                                  ("peak_dy_m", "base motion y from start, mm", 1e3),
                                  ("peak_dtheta_rad", "base rotation from start, mrad", 1e3)):
            rows.append(f"  {label:32s}{'-':>12s}" + "".join(
                f"{s[c][key] * scale:12.5g}" for c in ("one_way", "coupled")))
        return "\n".join(rows)

    def to_dataframe(self):
        """A pandas DataFrame: ``t_s``; ``Fx_floor_N``, ``Fy_floor_N``, ``M_floor_Nm`` with
        the suffixes ``_rigid``, ``_oneway``, ``_coupled``; ``x_base_m``, ``y_base_m``,
        ``theta_base_rad`` with ``_oneway`` and ``_coupled``; ``Fx_<isolator>_N_coupled``,
        ``Fy_<isolator>_N_coupled``."""
        import pandas as pd

        cols = {"t_s": self.t}
        for tag, F in (("rigid", self.rigid), ("oneway", self.one_way.floor),
                       ("coupled", self.coupled.floor)):
            for j, name in enumerate(("Fx_floor_N", "Fy_floor_N", "M_floor_Nm")):
                cols[f"{name}_{tag}"] = F[:, j]
        for tag, u in (("oneway", self.one_way.u), ("coupled", self.coupled.u)):
            for j, name in enumerate(("x_base_m", "y_base_m", "theta_base_rad")):
                cols[f"{name}_{tag}"] = u[:, j]
        for name, f in self.coupled.supports.items():
            cols[f"Fx_{name}_N_coupled"], cols[f"Fy_{name}_N_coupled"] = f[:, 0], f[:, 1]
        return pd.DataFrame(cols)


def _reaction_loads(run, names, at) -> np.ndarray:
    """The reactions (Fx, Fy, M about the origin), shape (n, 3), that the frame of ``run``
    takes from the ``Force`` loads ``names`` (their point of application as it moves),
    at the samples of the times ``at`` (n,) of the run."""
    from ..model.forces import applied_forces

    ok = np.all(np.isfinite(run.q), axis=1)
    args = (run.model, run.t[ok], run.x[ok], run.xdot[ok], run.q[ok], run.qdot[ok])
    R = applied_forces(*args, reacting_loads=tuple(names))[1] - applied_forces(*args)[1]
    return R if R.shape[0] == len(at) else _on(np.asarray(at), run.t[ok], R)


def _on(t, ts, values):
    """``values`` (m, k) sampled at ``ts`` (m,), linear at ``t`` (n,); NaN after ``ts[-1]``
    (a run that stopped early)."""
    values = np.asarray(values, float)
    out = np.column_stack([np.interp(t, ts, values[:, j]) for j in range(values.shape[1])])
    out[t > ts[-1] * (1 + 1e-12) + 1e-15] = np.nan
    return out


def compare_mounting(mechanism: Mechanism, foundation: Foundation | None = None,
                     t_end: float = 1.0, *, samples: int = 2001, base: str = "base",
                     reacting: Sequence[str] = (),
                     rigid_run=None, **simulate_kw) -> MountingComparison:
    """Run the machine on a rigid frame and coupled on its isolators, and compare.

    Parameters
    ----------
    mechanism : Mechanism
        The machine on its fixed frame.
    foundation : Foundation, optional
        Isolators, mass, inertia, com of frame and base (default the mechanism's).
    t_end : float
        End of both runs, s.
    samples : int
        Points of the common time grid (both runs are sampled on it).
    base, reacting
        As for :func:`~mechdyn.foundation.mounting.mounted`; the reactions of the
        ``reacting`` forces are also added to the rigid run's frame loads.
    rigid_run : Trajectory, optional
        A run of ``mechanism`` on its fixed frame already made with the same options (it
        is then not run again).
    **simulate_kw
        Passed to both :func:`mechdyn.simulate` runs (``q0`` and ``qdot0`` as mappings by
        coordinate name: the mounted machine has three coordinates more).

    Returns
    -------
    MountingComparison

    Raises
    ------
    ModelError
        As :func:`mounted`; fewer than 2 samples.

    Examples
    --------
    A pendulum on a base on two isolators, rigid and coupled:

    >>> from mechdyn.foundation import Isolator
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_body("bar", mass=2.0, inertia=0.05, com=(0.5, 0.0))
    >>> _ = m.add_revolute("O", "ground", "bar")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e6, 1e6, 2e3, 2e3),
    ...                 Isolator("R", 0.5, 0.0, 1e6, 1e6, 2e3, 2e3)], mass=100.0, inertia=10.0)
    >>> c = compare_mounting(m, f, 0.2, samples=41, progress=False)
    >>> s = c.statistics()
    >>> bool(abs(s["coupled"]["peak_N"] / s["one_way"]["peak_N"] - 1) < 1e-2)
    True
    """
    from ..simulate.run import simulate

    f = _foundation(mechanism, foundation)
    if samples < 2:
        raise ModelError(f"compare_mounting: samples must be >= 2, got {samples}")
    t0 = float(simulate_kw.get("t0", 0.0))
    t = np.linspace(t0, float(t_end), int(samples))
    simulate_kw.setdefault("t_eval", t)
    if rigid_run is None:
        rigid_run = simulate(mechanism, t_end, **simulate_kw)
    point = np.zeros(2)
    loads = frame_loads(rigid_run, point)
    machine = np.column_stack([loads.Fx, loads.Fy, loads.M])
    if reacting:
        machine = machine + _reaction_loads(rigid_run, reacting, loads.t)
    start = shift_moment(machine[0], point, f.com)
    mm = mounted(mechanism, f, base=base, load=start, reacting=reacting)
    coupled_run = simulate(mm, t_end, **simulate_kw)
    weight = shift_moment([*(f.mass * np.asarray(mechanism.gravity, float)), 0.0], f.com, point)
    rigid = _on(t, loads.t, machine) + weight
    one_way = mounted_response(f, t, rigid[:, 0], rigid[:, 1], rigid[:, 2], point=point)
    ff = floor_forces(coupled_run, f, base, point)
    good = np.isfinite(ff.t)
    ts = ff.t[good]
    coupled = MountedResponse(t=t, u=_on(t, ts, ff.u[good]), v=_on(t, ts, ff.v[good]),
                          floor=_on(t, ts, ff.floor[good]),
                          supports={k: _on(t, ts, v[good]) for k, v in ff.supports.items()},
                          point=point)
    return MountingComparison(t=t, rigid=rigid, one_way=one_way, coupled=coupled,
                              rigid_run=rigid_run, coupled_run=coupled_run, point=point)
