"""Model files: TOML text -> :class:`~mechdyn.mechanism.Mechanism`.

The format is documented in ``docs/model-file.md``; its structure is the JSON
schema ``schema.json`` in this package (see :func:`schema`).
"""

from .loader import build, load, loads, read_document
from .schema import schema

__all__ = ["load", "loads", "build", "read_document", "schema"]
