"""Parts of a run's table evaluated on first use: :class:`LazyDict`.

A run records its samples as it goes; the forces of every element, the loads on the
frame and the energies are evaluated from them batched over each mode's samples (see
:mod:`mechdyn.simulate.samples`).  That evaluation costs about as much as a short
run itself, and many runs never read it (a study reading the end state, a benchmark):
the :class:`~mechdyn.results.trajectory.Trajectory` of a run holds it as a
:class:`LazyDict` (``energy``) and a lazily filled
:class:`~mechdyn.results.trajectory.SwitchedSamples`, which evaluate it on first use --
the same columns, values and errors as an evaluation at the end of the run.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["LazyDict"]


class LazyDict(dict):
    """A dict whose items are computed on first use (:meth:`lazy`): any read or write
    first adds the items ``fill()`` returns (once; an error of ``fill`` is raised again by
    the next use).  Made as a dict is (``LazyDict(mapping, **items)``), it is one.

    Examples
    --------
    >>> calls = []
    >>> d = LazyDict.lazy(lambda: calls.append(1) or {"a": 1.0, "b": 2.0})
    >>> calls
    []
    >>> d["a"], sorted(d), dict(d) == {"a": 1.0, "b": 2.0}, len(calls)
    (1.0, ['a', 'b'], True, 1)
    """

    __slots__ = ("_fill",)

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._fill = None

    @classmethod
    def lazy(cls, fill: Callable) -> LazyDict:
        """The dict of the items ``fill() -> mapping`` returns, computed on first use."""
        d = cls()
        d._fill = fill
        return d

    def _filled(self) -> LazyDict:
        fill = self._fill
        if fill is not None:
            items = fill()
            dict.update(self, items)
            self._fill = None
        return self

    @property
    def evaluated(self) -> bool:
        """Whether the items have been computed."""
        return self._fill is None

    # reads: overriding __iter__ also keeps dict(d), {**d} and f(**d) off the C fast path
    # that would read the storage directly (they go through keys() and __getitem__)
    def __getitem__(self, key):
        return dict.__getitem__(self._filled(), key)

    def __contains__(self, key) -> bool:
        return dict.__contains__(self._filled(), key)

    def __iter__(self):
        return dict.__iter__(self._filled())

    def __reversed__(self):
        return dict.__reversed__(self._filled())

    def __len__(self) -> int:
        return dict.__len__(self._filled())

    def __repr__(self) -> str:
        return dict.__repr__(self._filled())

    def __eq__(self, other):
        return dict.__eq__(self._filled(), other)

    def __ne__(self, other):
        return dict.__ne__(self._filled(), other)

    __hash__ = None

    def __or__(self, other):
        return dict(self._filled()) | other

    def __ror__(self, other):
        return other | dict(self._filled())

    def __ior__(self, other):
        dict.update(self._filled(), other)
        return self

    def keys(self):
        return dict.keys(self._filled())

    def values(self):
        return dict.values(self._filled())

    def items(self):
        return dict.items(self._filled())

    def get(self, key, default=None):
        return dict.get(self._filled(), key, default)

    def copy(self) -> dict:
        return dict(dict.items(self._filled()))

    def __reduce__(self):  # pickled and copied as the plain dict of its items
        return dict, (self.copy(),)

    # writes
    def __setitem__(self, key, value) -> None:
        dict.__setitem__(self._filled(), key, value)

    def __delitem__(self, key) -> None:
        dict.__delitem__(self._filled(), key)

    def update(self, *args, **kwargs) -> None:
        dict.update(self._filled(), *args, **kwargs)

    def setdefault(self, key, default=None):
        return dict.setdefault(self._filled(), key, default)

    def pop(self, key, *default):
        return dict.pop(self._filled(), key, *default)

    def popitem(self):
        return dict.popitem(self._filled())

    def clear(self) -> None:
        self._fill = None
        dict.clear(self)
