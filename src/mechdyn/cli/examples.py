"""``mechdyn examples``: list the bundled model files."""

from __future__ import annotations

from ..examples import list_examples, path


def register(sub) -> None:
    p = sub.add_parser("examples", help="list the bundled example models",
                       description="List the bundled example models (use a name wherever a "
                                   "MODEL.toml is expected).")
    p.add_argument("--path", metavar="NAME", help="print the file path of one example")


def run(args) -> int:
    if args.path:
        print(path(args.path))
        return 0
    items = list_examples()
    width = max(len(n) for n, _ in items)
    for name, text in items:
        print(f"{name:<{width}}  {text}")
    return 0
