"""Evaluators over data: the constraint rows (NumPy, batched; and the Numba twin), the
packed loads and the small dense linear algebra of the compiled kernels.

The Numba kernels are compiled once per machine and kept in the user's cache folder
(:func:`cache_dir`, ``platformdirs.user_cache_dir("mechdyn")``, e.g.
``~/.cache/mechdyn`` on Linux) rather than next to the installed sources, which may be
read-only, in a subfolder named after a digest of the kernels' sources: Numba checks a
cached function against its own file only, so a kernel that inlines a changed helper of
another file (the linear algebra, the rows) would otherwise keep the old code.  A
``NUMBA_CACHE_DIR`` the user has set is respected.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

__all__ = ["cache_dir", "sources_digest"]


def sources_digest() -> str:
    """A short digest (12 hex digits) of the sources of the kernels (this package's
    ``*.py`` files): the name of the cache subfolder their compiled code is valid for.

    Examples
    --------
    >>> d = sources_digest()
    >>> len(d), d == sources_digest()
    (12, True)
    """
    h = hashlib.sha1()
    for f in sorted(Path(__file__).parent.glob("*.py")):
        h.update(f.name.encode() + b"\0" + f.read_bytes())
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
