"""Matplotlib figures of the reports and the demo, saved as deterministic PNGs.

:func:`new_figure` makes a figure with Matplotlib's non-interactive Agg
backend (no display needed); :func:`save_figure` writes it atomically
(:func:`pbrkit.core.atomic.atomic_path`) without the "Software" text chunk
that would record Matplotlib's version, so the same data give the same
bytes, and closes it.  Matplotlib is imported only when a figure is made.
"""

from __future__ import annotations

import numpy as np

from ..core.atomic import atomic_path

__all__ = ["pyplot", "new_figure", "colors", "save_figure"]


def pyplot():
    """``matplotlib.pyplot`` with the Agg backend selected."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def new_figure(rows=1, cols=1, **subplots_kwargs):
    """``(fig, axes)`` from ``pyplot.subplots(rows, cols, **subplots_kwargs)``
    (``figsize``, ``sharex``, ``squeeze`` ...), on the Agg backend."""
    return pyplot().subplots(rows, cols, **subplots_kwargs)


def colors(n, name="viridis"):
    """``n`` RGBA colours evenly spaced over the colour map ``name``, shape (n, 4)."""
    import matplotlib

    return matplotlib.colormaps[name](np.linspace(0.0, 1.0, n))


def save_figure(fig, path, dpi):
    """Write ``fig`` to ``path`` as a PNG at ``dpi`` atomically, with no
    "Software" metadata (deterministic bytes), and close it."""
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png", metadata={"Software": None})
    finally:
        pyplot().close(fig)
