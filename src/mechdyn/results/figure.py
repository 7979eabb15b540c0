"""The figures of the plots: panels on matplotlib's Agg canvas, written atomically.

Nothing here needs a screen or changes pyplot's backend.
"""

from __future__ import annotations

from pathlib import Path

from .table import output_path, written

__all__ = ["figure", "save"]


def figure(n_rows: int, width: float = 8.0, height: float = 2.6, sharex: bool = True):
    """A figure on the Agg canvas with ``n_rows`` gridded panels (sharing x unless
    ``sharex`` is False): (fig, axes)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height * n_rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(n_rows, 1, sharex=sharex, squeeze=False)[:, 0]
    for ax in axes:
        ax.grid(True, alpha=0.3)
    return fig, axes


def save(fig, path, dpi) -> Path:
    """Write ``fig`` to ``path`` (its type from the suffix), atomically; returns the path."""
    path = output_path(path)
    with written(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return path
