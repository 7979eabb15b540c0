"""Constraint rows as data: every joint, coordinate, lock, stop and contact, lowered once.

Every scalar that the package measures on a pose has one form,

    m(x) = w . (p1 - p2) + ka theta_a + kb theta_b + c,
    p_k = r_(b_k) + A(theta_(b_k)) s_k,    w = A(theta_d) u,

with A the rotation matrix and body index ``nb`` (the number of moving bodies)
standing for the ground (zero pose).  A :class:`Rows` holds these numbers for a
set of rows as arrays; :mod:`mechdyn.kernels.rows_numpy` and
:mod:`mechdyn.kernels.rows_numba` evaluate them (value, Jacobian and the
velocity-quadratic part of the second derivative).  Nothing else in the package
knows a joint's formulas: a joint type is a lowering rule here plus its
reaction frame.

Lowering rules (parent i, child j):

* revolute: two rows, w = e_x and e_y of the ground, p1 = parent point,
  p2 = child point (so the rows are the ground components of p_i - p_j);
* prismatic: the normal row, w = A(theta_i) n_i (n_i the axis turned +90 deg),
  p1 = child point, p2 = parent point; and the angle row theta_j - theta_i - angle;
* weld (lock): the ground components of r_j - (r_i + A_i c), then
  theta_j - theta_i - angle;
* coordinates: an absolute angle is ka = 1 on its body; a relative angle
  theta_j - theta_i; a travel w = A(theta_i) u_i with p1 = child point,
  p2 = parent point; a body position (kinds ``x``, ``y``) w = e_x or e_y of the
  ground with p1 = the body's origin, p2 = the ground's; each plus its offset in ``c``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

__all__ = ["Rows", "concat", "revolute", "prismatic", "weld", "angle", "relative_angle",
           "point", "line", "EX", "EY"]

EX, EY = (1.0, 0.0), (0.0, 1.0)
#: the per-row arrays of a :class:`Rows`
ARRAYS = ("b1", "s1", "b2", "s2", "d", "u", "a", "ka", "bb", "kb", "c", "is_angle")


@dataclass(frozen=True, eq=False)
class Rows:
    """A set of constraint rows of the form m(x) = w . (p1 - p2) + ka th_a + kb th_b + c.

    Attributes
    ----------
    nb : int
        Number of moving bodies; a body index equal to ``nb`` is the ground.
    b1, b2, d, a, bb : ndarray of int, shape (n,)
        Bodies of the points p1 and p2, of the direction w, and of the two angles.
    s1, s2, u : ndarray, shape (n, 2)
        Points in their body frames (m) and the direction in the frame of body d.
    ka, kb, c : ndarray, shape (n,)
        Angle factors (m/rad for mixed rows, 1 for angle rows) and the constant.
    labels : tuple of str
        A label per row (``"B.x"``, ``"guide.normal"``, ``"phi"`` ...).
    elements : tuple of str
        The element (joint, coordinate, lock, stop, contact) each row belongs to.
    is_angle : ndarray of bool, shape (n,)
        True for rows in rad, False for rows in m.

    Examples
    --------
    >>> r = revolute("A", 2, (0.0, 0.0), 0, (0.1, 0.0), nb=2)
    >>> len(r), r.labels
    (2, ('A.x', 'A.y'))
    """

    nb: int
    b1: np.ndarray
    s1: np.ndarray
    b2: np.ndarray
    s2: np.ndarray
    d: np.ndarray
    u: np.ndarray
    a: np.ndarray
    ka: np.ndarray
    bb: np.ndarray
    kb: np.ndarray
    c: np.ndarray
    labels: tuple = ()
    elements: tuple = ()
    is_angle: np.ndarray = field(default=None)

    def __post_init__(self):
        n = len(np.atleast_1d(self.c))
        for name in ARRAYS[:-1]:
            shape = (n, 2) if name in ("s1", "s2", "u") else (n,)
            dtype = np.int64 if name in ("b1", "b2", "d", "a", "bb") else float
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype).reshape(shape))
        if self.is_angle is None:
            object.__setattr__(self, "is_angle", ~np.any(self.u != 0.0, axis=1))
        else:
            object.__setattr__(self, "is_angle", np.asarray(self.is_angle, bool).reshape(n))
        labels = tuple(self.labels) or tuple(f"row{k}" for k in range(n))
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "elements", tuple(self.elements) or labels)
        if len(self.labels) != n or len(self.elements) != n:
            raise ValueError(f"Rows: {n} rows but {len(self.labels)} labels and "
                             f"{len(self.elements)} elements")

    def __len__(self) -> int:
        return self.c.shape[0]

    @property
    def n_x(self) -> int:
        """Length of the pose vector, 3 nb."""
        return 3 * self.nb

    def take(self, index) -> Rows:
        """The rows at ``index`` (an index array or a boolean mask), in that order."""
        idx = np.arange(len(self))[index]
        return replace(self, **{k: getattr(self, k)[idx] for k in ARRAYS},
                       labels=tuple(self.labels[k] for k in idx),
                       elements=tuple(self.elements[k] for k in idx))

    def scaled(self, sign: float = 1.0, shift: float = 0.0) -> Rows:
        """sign * (m(x) + shift): a unilateral row's orientation and its held value."""
        return replace(self, u=sign * self.u, ka=sign * self.ka, kb=sign * self.kb,
                       c=sign * (self.c + shift))

    def renamed(self, labels, elements=None) -> Rows:
        """The same rows with other labels (and elements)."""
        labels = (labels,) * len(self) if isinstance(labels, str) else tuple(labels)
        elements = labels if elements is None else (
            (elements,) * len(self) if isinstance(elements, str) else tuple(elements))
        return replace(self, labels=labels, elements=elements)

    @cached_property
    def columns(self) -> tuple[np.ndarray, ...]:
        """Contiguous s1x, s1y, s2x, s2y, ux, uy, each (n,), for the evaluators."""
        return tuple(np.ascontiguousarray(a[:, k]) for a in (self.s1, self.s2, self.u)
                     for k in (0, 1))

    @cached_property
    def scatter(self) -> np.ndarray:
        """Flat indices into an (n, n_x + 1) array of the nine Jacobian terms of every row
        (columns of b1 x, y, theta; b2 x, y, theta; d theta; a theta; bb theta), the
        ground's columns sent to the last (dump) column."""
        n_x = self.n_x
        terms = ((self.b1, 0), (self.b1, 1), (self.b1, 2), (self.b2, 0), (self.b2, 1),
                 (self.b2, 2), (self.d, 2), (self.a, 2), (self.bb, 2))
        return np.concatenate([np.arange(len(self)) * (n_x + 1)
                               + np.where(b >= self.nb, n_x, 3 * b + k) for b, k in terms])

    def packed(self) -> tuple[np.ndarray, np.ndarray]:
        """(ints (n, 5): b1 b2 d a bb; floats (n, 9): s1 s2 u ka kb c) for the compiled
        evaluator."""
        ints = np.stack([self.b1, self.b2, self.d, self.a, self.bb], axis=1)
        flts = np.concatenate([self.s1, self.s2, self.u, self.ka[:, None], self.kb[:, None],
                               self.c[:, None]], axis=1)
        return np.ascontiguousarray(ints, np.int64), np.ascontiguousarray(flts, float)


def _one(nb, *, label: str, element: str = "", is_angle: bool = False, **row) -> dict:
    """One row: the ground (index ``nb``) and zeros wherever ``row`` gives nothing."""
    return {"b1": nb, "s1": (0.0, 0.0), "b2": nb, "s2": (0.0, 0.0), "d": nb, "u": (0.0, 0.0),
            "a": nb, "ka": 0.0, "bb": nb, "kb": 0.0, "c": 0.0, **row, "label": label,
            "element": element or label, "is_angle": is_angle}


def _rows(nb: int, recs: list[dict]) -> Rows:
    return Rows(nb, **{k: [r[k] for r in recs] for k in ARRAYS},
                labels=tuple(r["label"] for r in recs), elements=tuple(r["element"] for r in recs))


def concat(nb: int, *parts: Rows) -> Rows:
    """All rows of ``parts`` in order, as one :class:`Rows`."""
    parts = [p for p in parts if len(p)]
    if not parts:
        return _rows(nb, [])
    if any(p.nb != nb for p in parts):
        raise ValueError("Rows of different models cannot be joined")
    return Rows(nb, **{k: np.concatenate([getattr(p, k) for p in parts]) for k in ARRAYS},
                labels=sum((p.labels for p in parts), ()),
                elements=sum((p.elements for p in parts), ()))


# ----------------------------------------------------------------------------- lowering rules
def revolute(name: str, i: int, si, j: int, sj, *, nb: int) -> Rows:
    """Two rows: ground x and y of p_i - p_j (parent point minus child point), m."""
    return _rows(nb, [_one(nb, b1=i, s1=si, b2=j, s2=sj, u=e, label=f"{name}.{c}",
                           element=name) for e, c in ((EX, "x"), (EY, "y"))])


def prismatic(name: str, i: int, si, ui, j: int, sj, held_angle: float, *, nb: int) -> Rows:
    """The normal row n_i . (p_j - p_i) (m) and the angle row theta_j - theta_i - angle."""
    return concat(nb, line(f"{name}.normal", j, sj, i, si, ui, normal=True, nb=nb, element=name),
                  relative_angle(f"{name}.angle", i, j, -held_angle, nb=nb, element=name))


def weld(name: str, i: int, c, j: int, held_angle: float, *, nb: int) -> Rows:
    """Three rows: ground x and y of r_j - (r_i + A_i c) (m), then theta_j - theta_i - angle."""
    return concat(nb, revolute(name, j, (0.0, 0.0), i, c, nb=nb),
                  relative_angle(f"{name}.angle", i, j, -held_angle, nb=nb, element=name))


def angle(label: str, b: int, offset: float = 0.0, *, nb: int, element: str = "") -> Rows:
    """theta_b + offset, rad."""
    return _rows(nb, [_one(nb, a=b, ka=1.0, c=offset, label=label, element=element,
                           is_angle=True)])


def relative_angle(label: str, i: int, j: int, offset: float = 0.0, *, nb: int,
                   element: str = "") -> Rows:
    """theta_j - theta_i + offset, rad."""
    return _rows(nb, [_one(nb, a=j, ka=1.0, bb=i, kb=-1.0, c=offset, label=label,
                           element=element, is_angle=True)])


def point(label: str, b: int, s, comp: int, *, offset: float = 0.0, nb: int,
          element: str = "") -> Rows:
    """Ground x (comp 0) or y (comp 1) of a body point, plus ``offset``, m.

    Examples
    --------
    >>> r = point("h", 0, (0.0, 0.0), 1, offset=-0.5, nb=1)
    >>> r.u.tolist(), r.c.tolist()
    ([[0.0, 1.0]], [-0.5])
    """
    return _rows(nb, [_one(nb, b1=b, s1=s, u=EX if comp == 0 else EY, c=offset, label=label,
                           element=element)])


def line(label: str, b1: int, s1, b2: int, s2, u, *, normal: bool, offset: float = 0.0,
         nb: int, element: str = "") -> Rows:
    """Point s1 of body b1 against the line through s2 of body b2 along u (in b2's frame).

    ``normal=True``: n . (p1 - p2), n = u turned +90 deg (a gap); ``normal=False``:
    t . (p1 - p2) (a travel along the line); plus ``offset``; m.
    """
    ux, uy = np.asarray(u, float) / np.hypot(*u)
    w = (-uy, ux) if normal else (ux, uy)
    return _rows(nb, [_one(nb, b1=b1, s1=s1, b2=b2, s2=s2, d=b2, u=w, c=offset, label=label,
                           element=element)])
