"""Evaluators over data: the constraint rows (NumPy, batched; and the Numba twin), the
packed loads and the small dense linear algebra of the compiled kernels.

The Numba kernels are compiled once per machine and kept in the user's cache folder
(:func:`cache_dir`, ``platformdirs.user_cache_dir("mechdyn")``, e.g.
``~/.cache/mechdyn`` on Linux) rather than next to the installed sources, which may be
read-only, in a subfolder named after a digest of the kernels' sources: Numba checks a
cached function against its own file only, so a kernel that inlines a changed helper of
another file (the linear algebra, the rows) would otherwise keep the old code.  The digest
covers this package's files and the modules of :mod:`mechdyn.integrate` the kernels
compile (:data:`COMPILED_INTEGRATE`: the DOP853 tableau, step control and dense output,
written there once for the Python stepper and the compiled loop).  A ``NUMBA_CACHE_DIR``
the user has set is respected.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

__all__ = ["cache_dir", "sources_digest", "digested_sources", "COMPILED_INTEGRATE"]

#: the modules of :mod:`mechdyn.integrate` whose functions and constants the kernels
#: compile into their code (every one a kernel imports; a test keeps the list complete)
COMPILED_INTEGRATE = ("dop853_control.py", "dop853_dense.py", "dop853_tableau.py")


def digested_sources() -> list[Path]:
    """The files :func:`sources_digest` covers: this package's ``*.py`` files, then
    :data:`COMPILED_INTEGRATE` of :mod:`mechdyn.integrate`.

    Examples
    --------
    >>> [f.name for f in digested_sources()][-3:]
    ['dop853_control.py', 'dop853_dense.py', 'dop853_tableau.py']
    """
    here = Path(__file__).parent
    integrate = here.parent / "integrate"
    return sorted(here.glob("*.py")) + [integrate / name for name in COMPILED_INTEGRATE]


def sources_digest() -> str:
    """A short digest (12 hex digits) of the sources of the kernels
    (:func:`digested_sources`): the name of the cache subfolder their compiled code is
    valid for.

    Examples
    --------
    >>> d = sources_digest()
    >>> len(d), d == sources_digest()
    (12, True)
    """
    h = hashlib.sha1()
    for f in digested_sources():
        h.update(f.parent.name.encode() + b"/" + f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:12]


def cache_dir() -> str:
    """The folder the compiled kernels are cached in: ``NUMBA_CACHE_DIR`` when set (by
    the user, or by this package on import), else ``kernels-<digest>`` in the user's cache
    folder for mechdyn (:func:`sources_digest`).

    Examples
    --------
    >>> import os
    >>> cache_dir() == os.environ["NUMBA_CACHE_DIR"]
    True
    """
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if chosen:
        return chosen
    from platformdirs import user_cache_dir

    return os.path.join(user_cache_dir("mechdyn", appauthor=False),
                        f"kernels-{sources_digest()}")


def _use_cache_dir() -> None:
    """Point Numba's disk cache at :func:`cache_dir` before any kernel is decorated (Numba
    reads the setting when a cached function is defined, and at its own import)."""
    folder = cache_dir()
    os.environ["NUMBA_CACHE_DIR"] = folder
    numba_config = sys.modules.get("numba.core.config")  # numba imported before mechdyn
    if numba_config is not None and not numba_config.CACHE_DIR:
        numba_config.CACHE_DIR = folder


_use_cache_dir()
