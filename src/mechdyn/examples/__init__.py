"""Bundled example mechanisms (TOML model files) and the modules that load and run them.

>>> from mechdyn import examples
>>> [name for name, _ in examples.list_examples()][:2]
['andrews_squeezer', 'bolt_buffer']
>>> mech = examples.load("four_bar")
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from ..errors import ModelError, did_you_mean
from ..modelfile import load as _load

__all__ = ["list_examples", "path", "load", "names"]


def _files():
    return resources.files(__package__)


def names() -> list[str]:
    """Names of the bundled examples (file names without ``.toml``), sorted."""
    return sorted(p.name[:-5] for p in _files().iterdir() if p.name.endswith(".toml"))


def list_examples() -> list[tuple[str, str]]:
    """The bundled examples as ``(name, one-line description)`` pairs, sorted by name.

    The description is the ``[model] description`` of each file.
    """
    out = []
    for name in names():
        doc = tomllib.loads(_files().joinpath(f"{name}.toml").read_text(encoding="utf-8"))
        out.append((name, " ".join(str(doc.get("model", {}).get("description", "")).split())))
    return out


def path(name: str) -> Path:
    """Path of a bundled example file.

    Parameters
    ----------
    name : str
        Example name, with or without ``.toml`` (see :func:`list_examples`).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ModelError
        Unknown name; the message lists the bundled examples.
    """
    stem = name[:-5] if name.endswith(".toml") else name
    if stem not in names():
        raise ModelError(did_you_mean(name, names(), "example"))
    return Path(str(_files().joinpath(f"{stem}.toml")))


def load(name: str):
    """Load a bundled example as a validated :class:`~mechdyn.mechanism.Mechanism`."""
    return _load(path(name))
