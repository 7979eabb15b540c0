"""The initial state of a run: coordinates, rates and the assembled pose.

Values given by the caller override those of the model file's ``initial`` table,
which override the sketch (rates: zero); the pose is reached from the assembled
sketch by Newton continuation, which keeps the sketch's assembly branch.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .errors import ModelError, did_you_mean
from .kinematics.assembly import assemble, solve_position
from .model import Model
from .model.constraints import coordinates

__all__ = ["initial_state"]


def _values(model: Model, given, base: np.ndarray, what: str) -> np.ndarray:
    """Coordinates from an array (n_q,) or a mapping {name: value} over ``base``."""
    out = np.array(base, dtype=float)
    if given is None:
        return out
    if isinstance(given, Mapping):
        for name, v in given.items():
            if name not in model.coordinate_names:
                raise ModelError(f"{what}: " + did_you_mean(name, model.coordinate_names,
                                                            "coordinate"))
            out[model.coordinate_index(name)] = float(v)
        return out
    arr = np.asarray(given, dtype=float).reshape(-1)
    if arr.shape != (model.n_q,):
        names = ", ".join(model.coordinate_names)
        raise ModelError(f"{what} must have {model.n_q} values ({names}), got {arr.size}")
    return arr


#: the most continuation steps from the sketch to the initial coordinates (about 16 turns)
MAX_WALK = 2000


def initial_state(model: Model, q0=None, qdot0=None, *, mode=None, workspace=None):
    """Initial (q, qdot, x): arguments, else ``mechanism.extras["initial"]``, else the sketch.

    Parameters
    ----------
    q0, qdot0 : array_like (n_q,) or mapping {coordinate name: value}, optional
        Values given override those of the model file; missing ones come from the
        model file's ``initial`` table, then from the sketch (rates: zero).
    mode : sequence of str, optional
        The engaged locks (default: the initial mode).
    workspace : Workspace, optional
        Keeps the pose for the next run given the same workspace.

    Returns
    -------
    q, qdot : ndarray, shape (n_q,)
    x : ndarray, shape (n_x,)
        The assembled pose at q, reached by continuation from the sketch.
    """
    layout = model.layout(mode)
    x_sk = getattr(model, "x0", None)
    if x_sk is None:
        x_sk = assemble(model, layout=layout)
    q_sk = getattr(model, "q_sketch", None)
    if q_sk is None:
        q_sk = coordinates(model, x_sk)
    init = model.mechanism.extras.get("initial") or {}
    q = _values(model, init.get("q"), q_sk, "initial q")
    qd = _values(model, init.get("qdot"), np.zeros(model.n_q), "initial qdot")
    q = _values(model, q0, q, "q0")
    qd = _values(model, qdot0, qd, "qdot0")
    if not (np.isfinite(q).all() and np.isfinite(qd).all()):
        raise ModelError(f"the initial state must be finite, got q = {q}, qdot = {qd}")
    # the continuation is a function of the sketch, the mode and q alone: a caller that
    # passes the same workspace to many runs from one state walks once
    key = (tuple(sorted(mode or ())), np.asarray(x_sk, float).tobytes(), q.tobytes())
    x = None if workspace is None else workspace.poses.get(key)
    if x is None:
        x = _walk(model, layout, q, q_sk, x_sk)
        if workspace is not None:
            workspace.keep(workspace.poses, key, x)
    return q, qd, np.array(x, float)


def _walk(model: Model, layout, q, q_sk, x_sk) -> np.ndarray:
    """The pose at ``q`` by Newton continuation from the sketch (keeps its branch), in
    steps of 0.05 rad or 0.05 length scale."""
    dq = q - q_sk
    size = np.where(model.coord_is_angle, np.abs(dq) / 0.05,
                    np.abs(dq) / (0.05 * model.length_scale))
    if float(np.max(size, initial=0.0)) > MAX_WALK:
        k = int(np.argmax(size))
        unit = "deg" if model.coord_is_angle[k] else "mm"
        far = np.rad2deg(q[k]) if model.coord_is_angle[k] else 1e3 * q[k]
        raise ModelError(f"initial {model.coordinate_names[k]} = {far:.6g} {unit} is too far "
                         f"from the sketch to be reached by continuation (more than "
                         f"{MAX_WALK} steps of 0.05 rad or 0.05 length scale); give it "
                         "within a few turns of the sketch (angles modulo 360 deg)")
    n = max(1, int(math.ceil(float(np.max(size, initial=0.0)))))
    x = np.array(x_sk, float)
    for k in range(1, n + 1):
        x = solve_position(model, q_sk + dq * (k / n), x, layout=layout, check_singular=False)
    return x
