"""Read-only mapping access to the fields of a typed stats dataclass.

The ``stats`` of every record is a typed dataclass
(:mod:`mechdyn.results.records`).  They used to be plain dicts, so code written
against them (``trajectory.stats["evaluations"]``, ``dict(stats)``, ``"streamed" in
stats``) keeps working through :class:`FieldMapping`: its keys are the dataclass's
fields whose value is not None (the keys a dict would have held), read-only.

It lives below every package of mechdyn (beside :mod:`mechdyn.errors`) so that the
records of every layer (the integrators', the sweeps', the simulations') share it.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import fields
from typing import Any

__all__ = ["FieldMapping"]


class FieldMapping(Mapping):
    """A dataclass read as the read-only mapping of its fields that are not None.

    Mix it into a ``@dataclass``: ``stats["steps"]`` is ``stats.steps``,
    :meth:`keys` lists the fields set (a field that is None, as a key the dict of
    old did not have, is left out), ``dict(stats)`` copies them.  There is no item
    assignment: the stats of a record are read-only.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Counts(FieldMapping):
    ...     steps: int = 0
    ...     note: str | None = None
    >>> c = Counts(steps=3)
    >>> c["steps"], c.keys(), "note" in c, dict(c)
    (3, ('steps',), False, {'steps': 3})
    """

    __slots__ = ()

    def keys(self) -> tuple[str, ...]:  # type: ignore[override]
        """The names of the fields that are not None, in their declared order."""
        return tuple(f.name for f in fields(self) if getattr(self, f.name) is not None)

    def __getitem__(self, key: str) -> Any:
        if not isinstance(key, str) or key not in self.keys():
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self) -> Iterator[str]:
        return iter(self.keys())

    def __len__(self) -> int:
        return len(self.keys())

    def __contains__(self, key: object) -> bool:
        return isinstance(key, str) and key in self.keys()
