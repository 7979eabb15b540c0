"""Reading the ``[foundation]`` table of a model file: the supports of the frame.

``[foundation]`` holds the base's ``mass``, ``inertia`` and ``com``; its arrays of
tables ``[[foundation.bolts]]`` and ``[[foundation.isolators]]`` hold one
:class:`~mechdyn.mechanism.supports.AnchorBolt` or
:class:`~mechdyn.mechanism.supports.Isolator` each (docs/model-file.md,
"``[foundation]``").  :class:`_FoundationReader` reads them into a
:class:`~mechdyn.mechanism.supports.Foundation`, whose own checks (supports that
cannot hold the base ...) become problems of ``[foundation]``.
"""

from __future__ import annotations

from ..errors import ModelError
from ..mechanism.supports import AnchorBolt, Foundation, Isolator
from .reader import _Failed, _Reader
from .schema import locate, schema

__all__ = ["support_fields", "SUPPORT_TABLES"]

#: the array of tables of each kind of support
SUPPORT_TABLES = {"bolts": AnchorBolt, "isolators": Isolator}
#: the kind of quantity of each field of a support
_KINDS = {"x": "length", "y": "length", "k_axial": "stiffness", "k_shear": "stiffness",
          "preload": "force", "load_factor": "ratio", "kx": "stiffness", "ky": "stiffness",
          "cx": "damping", "cy": "damping"}
_DEFS = {AnchorBolt: "bolt", Isolator: "isolator"}


def support_fields(cls) -> dict[str, tuple[str, bool]]:
    """The fields of a support class: ``{field: (kind of quantity, required)}``, as the
    schema has them (also read by ``mechdyn foundation --support/--isolator``).

    Examples
    --------
    >>> support_fields(Isolator)["cy"]
    ('damping', False)
    """
    spec = schema()["$defs"][_DEFS[cls]]
    return {k: (_KINDS[k], k in spec["required"]) for k in spec["properties"] if k in _KINDS}


class _FoundationReader(_Reader):
    """Reads the ``[foundation]`` table."""

    def foundation(self) -> Foundation:
        """The foundation of the document; raises :class:`_Failed` if a problem was
        recorded in it (a support is left out: the others are still checked)."""
        P = ("foundation",)
        if self.broken(*P):  # a table of the wrong type, an unknown key: already named
            raise _Failed
        spec = self.doc["foundation"]
        supports, ok, taken = [], True, {}
        for table, cls in SUPPORT_TABLES.items():
            entries = spec.get(table, [])
            for k, e in enumerate(entries if isinstance(entries, list) else []):
                el = self.soft(self.support, cls, (*P, table, k), e, taken)
                ok = ok and el is not None
                supports.append(el)
        self.failed = False
        mass = self.opt(spec, "mass", "mass", *P, default=None)
        inertia = self.opt(spec, "inertia", "inertia", *P, default=None)
        com = self.opt(spec, "com", "length", *P, default=(0.0, 0.0), read=self.vector, size=2)
        if ("mass" in spec) != ("inertia" in spec):
            missing = "inertia" if "mass" in spec else "mass"
            self.problem(f"{self.where(*P)}: mass and inertia go together (the elastic "
                         f"analysis needs both); missing {missing!r}")
            self.failed = True
        if not any(isinstance(spec.get(t), list) and spec[t] for t in SUPPORT_TABLES):
            self.problem(f"{self.where(*P)}: no supports: add [[foundation.bolts]] or "
                         "[[foundation.isolators]] tables, at least two at distinct points")
            self.failed = True
        self.check()
        if not ok:
            raise _Failed
        return self.checked(Foundation, P, spec, supports, mass=mass, inertia=inertia,
                            com=com)

    def support(self, cls, P: tuple, e: dict, taken: dict):
        """One bolt or isolator at ``P``; ``taken``: the path of each support name so far."""
        if self.broken(*P) or not isinstance(e, dict):
            raise _Failed
        name = e["name"]
        if name in taken:
            self.problem(f"{self.where(*P, 'name')}: {name!r} is already the name of "
                         f"{locate('', taken[name], self.doc)}; support names must "
                         "be unique")
            raise _Failed
        taken[name] = P
        self.failed = False
        values = {key: self.opt(e, key, kind, *P, default=None)
                  for key, (kind, _) in support_fields(cls).items() if key in e}
        self.check()
        return self.checked(cls, P, e, name, **values)

    def checked(self, cls, P: tuple, spec: dict, *args, **kwargs):
        """``cls(*args, **kwargs)``; each problem of its own check (``"who: key must
        ..."``) is recorded at ``P`` and its key, with the value of the file."""
        try:
            return cls(*args, **kwargs)
        except (ModelError, ValueError, ArithmeticError) as exc:
            problems = exc.problems if isinstance(exc, ModelError) else [str(exc)]
        for p in problems:
            text = p.partition(": ")[2] or p
            key = text.split(" ", 1)[0]
            where = (f"{self.where(*P, key)}: {spec[key]!r}" if key in spec
                     else self.where(*P))
            self.problem(f"{where}: {text}")
        raise _Failed
