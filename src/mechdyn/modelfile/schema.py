"""The JSON schema of the model file and the translation of its errors into plain words.

The schema (``schema.json`` beside this module) checks the *structure* of a model
file: which tables and keys exist, which are required, and the TOML type of each
value.  Units and physical sense (``"-2 kg"`` for a mass) are checked by the
loader.  Every schema error becomes one message that cites the file, the table
and the key, e.g. ``press.toml: [bodies.rod]: missing key 'mass' (mass, e.g. "4.6 kg")``.
"""

from __future__ import annotations

import difflib
import json
from collections.abc import Sequence
from functools import lru_cache
from importlib import resources
from typing import Any

__all__ = ["schema", "schema_problems", "locate", "toml_type"]

#: top-level tables whose sub-tables are named elements ([bodies.NAME], ...)
_NAMED_SECTIONS = ("bodies", "joints", "coordinates")
#: top-level arrays of tables ([[loads]], ...)
_ARRAY_SECTIONS = ("loads", "drives", "coordinate_locks", "stops", "contacts", "switches")
#: arrays of tables inside a table ([[foundation.bolts]], ...)
_NESTED_ARRAYS = (("foundation", "bolts"), ("foundation", "isolators"))


@lru_cache(maxsize=1)
def schema() -> dict:
    """The JSON schema of the model file (a dict, loaded once from ``schema.json``)."""
    text = resources.files(__package__).joinpath("schema.json").read_text(encoding="utf-8")
    return json.loads(text)


def _type_only_refs(sch: dict) -> dict[str, tuple[str, ...]]:
    """The ``$ref`` of every definition that states nothing but a type (``quantity``:
    a string or a number) -> its types."""
    out = {}
    for name, d in sch.get("$defs", {}).items():
        if isinstance(d, dict) and set(d) <= {"type", "description"} and "type" in d:
            t = d["type"]
            out[f"#/$defs/{name}"] = (t,) if isinstance(t, str) else tuple(t)
    return out


@lru_cache(maxsize=1)
def _validator():
    """The schema's validator, built once.

    Its ``items`` keyword checks an array whose items refer to a type-only definition
    (the points of a table: ``{"$ref": "#/$defs/quantity"}``) by a type test per item
    instead of resolving the reference for every item (a 50 000-point table spent most of
    its load time there); an item that fails the test is validated the standard way, so
    its error, and the message made of it, are those of the plain validator.
    """
    from jsonschema import Draft202012Validator, validators

    plain_items = Draft202012Validator.VALIDATORS["items"]
    simple = _type_only_refs(schema())

    def items(validator, items, instance, schema):
        types = (simple.get(items.get("$ref")) if isinstance(items, dict)
                 and set(items) <= {"$ref", "description"} else None)
        if types is None or not validator.is_type(instance, "array"):
            yield from plain_items(validator, items, instance, schema)
            return
        for index in range(len(schema.get("prefixItems", [])), len(instance)):
            item = instance[index]
            if not any(validator.is_type(item, t) for t in types):
                yield from validator.descend(instance=item, schema=items, path=index)

    fast = validators.extend(Draft202012Validator, {"items": items})
    return fast(schema())


_TOML_TYPES = ((bool, "a boolean"), (int, "an integer"), (float, "a float"), (str, "a string"),
               (dict, "a table"), (list, "an array"))


def toml_type(value: Any) -> str:
    """How a value is called in TOML words (for messages)."""
    return next((w for t, w in _TOML_TYPES if isinstance(value, t)), type(value).__name__)


def _show(value: Any) -> str:
    """Short text of a value for a message."""
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = ..." for k in list(value)[:4]) + (
            ", ...}" if len(value) > 4 else "}")
    text = repr(value) if not isinstance(value, bool) else str(value).lower()
    return text if len(text) <= 60 else text[:57] + "..."


def locate(fname: str, path: Sequence, doc: Any = None) -> str:
    """Where a value sits, as ``"file: [table.sub] key"``.

    Parameters
    ----------
    fname : str
        File name shown first.
    path : sequence of str or int
        Keys and array indices from the top of the document.
    doc : dict, optional
        The document, to show the ``name`` of a ``[[loads]]`` entry.
    """
    path = list(path)
    if not path:
        return fname
    head = path[0]
    array = (path[:1] if head in _ARRAY_SECTIONS
             else path[:2] if tuple(path[:2]) in _NESTED_ARRAYS else [])
    if array and len(path) > len(array) and isinstance(path[len(array)], int):
        k = path[len(array)]
        label = f"[[{'.'.join(array)}]] #{k + 1}"
        try:
            entries = doc[head] if len(array) == 1 else doc[head][path[1]]
            name = entries[k].get("name")
        except (TypeError, KeyError, IndexError, AttributeError):
            name = None
        if isinstance(name, str):
            label += f" {name!r}"
        rest = path[len(array) + 1:]
    else:
        depth = 1
        if head in _NAMED_SECTIONS and len(path) >= 2:
            depth = 2
            if head == "bodies" and len(path) >= 4 and path[2] == "points":
                depth = 3
        elif head == "ground" and len(path) >= 3 and path[1] == "points":
            depth = 2
        label = "[" + ".".join(str(p) for p in path[:depth]) + "]"
        rest = path[depth:]
    key = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in rest).removeprefix(".")
    return (f"{fname}: " if fname else "") + label + (f" {key}" if key else "")


def _message(err, fname: str, doc: Any) -> str:
    path = list(err.absolute_path)
    where = locate(fname, path, doc)
    v, inst = err.validator, err.instance
    what = "table" if not path else "key"
    if v == "required":
        missing = [k for k in err.validator_value if not (isinstance(inst, dict) and k in inst)]
        key = missing[0] if missing else "?"
        prop = err.schema.get("properties", {}).get(key)
        desc = prop.get("description") if isinstance(prop, dict) else None
        return f"{where}: missing {what} {key!r}" + (f" ({desc})" if desc else "")
    if v == "additionalProperties":
        valid = list(err.schema.get("properties", {}))
        extra = [k for k in inst if k not in valid] if isinstance(inst, dict) else []
        names = ", ".join(repr(k) for k in extra) or "?"
        close = [m for k in extra for m in difflib.get_close_matches(str(k), valid, n=1)]
        hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
        return (f"{where}: unknown {what} {names}{hint}; valid {what}s: "
                + (", ".join(repr(k) for k in valid) or "(none)"))
    if v == "type":
        want = err.validator_value
        want = [want] if isinstance(want, str) else list(want)
        words = {"string": "a string", "number": "a number", "integer": "an integer",
                 "object": "a table", "array": "an array", "boolean": "true or false"}
        expected = " or ".join(words.get(w, w) for w in want)
        return f"{where}: {_show(inst)}: wrong type: expected {expected}, got {toml_type(inst)}"
    if v == "enum":
        opts = ", ".join(repr(o) for o in err.validator_value)
        return f"{where}: {_show(inst)}: must be one of {opts}"
    if v in ("minItems", "maxItems"):
        n = err.validator_value
        if "minItems" in err.schema and err.schema.get("minItems") == err.schema.get("maxItems"):
            need = f"exactly {n}"
        else:
            need = f"at least {n}" if v == "minItems" else f"at most {n}"
        return (f"{where}: {_show(inst)}: expected {need} components, got "
                f"{len(inst) if isinstance(inst, list) else '?'}")
    if v == "minProperties":
        section = path[-1] if path else "model"
        return f"{where}: at least one entry is needed in [{section}]"
    if v == "pattern":
        return (f"{where}: name {inst!r} is not allowed: use letters, digits, '_' and '-', "
                "starting with a letter or '_'")
    return f"{where}: {_show(inst)}: {err.message}"


def schema_problems(doc: Any, fname: str) -> tuple[list[str], list[tuple]]:
    """Check a parsed TOML document against the schema.

    Returns
    -------
    messages : list of str
        One message per problem, in document order, duplicates removed.
    paths : list of tuple
        The path of each problem (to skip the broken elements when building).
    """
    found: dict[str, tuple] = {}  # message -> path of its first error
    for err in sorted(_validator().iter_errors(doc),
                      key=lambda e: [str(p) for p in e.absolute_path]):
        found.setdefault(_message(err, fname, doc), tuple(err.absolute_path))
    return list(found), list(found.values())
