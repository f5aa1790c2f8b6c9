"""Matplotlib figures of the reports and the demo, saved as deterministic PNGs.

:func:`new_figure` makes a figure with Matplotlib's non-interactive Agg
backend (no display needed); :func:`figure_png` renders it to PNG bytes in memory
without the "Software" text chunk that would record Matplotlib's version, so
the same data give the same bytes, and closes it; :func:`save_figure` writes
those bytes atomically (:func:`pbrkit.core.atomic.write_bytes`).  Matplotlib
never writes to disk itself, so a full disk is one clean error naming the
file (no "Exception ignored" noise from a half-written PNG), and reports that
commit several files together (:func:`pbrkit.core.atomic.atomic_group`) can
render every figure before they write anything.  Matplotlib is imported only when a figure is made.
:func:`plot_error_map` draws an error map with its colour bar on a scale
chosen from the data (:func:`error_scale`, :func:`nice_ceiling`).
"""

from __future__ import annotations

import io

import numpy as np

from ..core.atomic import write_bytes

__all__ = ["pyplot", "new_figure", "colors", "figure_png", "save_figure", "nice_ceiling", "error_scale",
           "plot_error_map"]


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


def figure_png(fig, dpi):
    """``fig`` as PNG bytes at ``dpi``, rendered in memory with no "Software"
    metadata (deterministic bytes); the figure is closed."""
    try:
        buffer = io.BytesIO()
        fig.savefig(buffer, dpi=dpi, format="png", metadata={"Software": None})
        return buffer.getvalue()
    finally:
        pyplot().close(fig)


def save_figure(fig, path, dpi):
    """Write ``fig`` to ``path`` as a PNG at ``dpi`` (:func:`figure_png`)
    atomically, and close it.  With ``path`` None nothing is written and the
    PNG bytes are returned."""
    data = figure_png(fig, dpi)
    if path is None:
        return data
    write_bytes(path, data)
    return None


def nice_ceiling(x):
    """The smallest number 1, 2, 2.5 or 5 times a power of ten that is >= ``x`` (> 0)."""
    x = float(x)
    if not (x > 0.0 and np.isfinite(x)):
        raise ValueError(f"nice_ceiling needs a finite positive number; got {x!r}")
    power = 10.0 ** np.floor(np.log10(x))
    for step in (1.0, 2.0, 2.5, 5.0, 10.0):
        if step * power >= x * (1.0 - 1e-12):
            return float(step * power)
    return float(10.0 * power)  # not reached


def error_scale(values, percentile=99.0, floor=1e-3):
    """Upper end of an error map's colour scale: the ``percentile`` of ``values``
    rounded up by :func:`nice_ceiling` (at least ``floor``), so that at most
    100 - ``percentile`` % of the pixels saturate.  Returns ``(scale, percentile
    value, maximum)``."""
    values = np.asarray(values, dtype=float).ravel()
    if values.size == 0:
        return floor, 0.0, 0.0
    p = float(np.percentile(values, percentile))
    return nice_ceiling(max(p, floor)), p, float(values.max())


def plot_error_map(path, error, valid, scale, quantity, title=None, percent=True, dpi=100):
    """Write the error map ``error`` (H, W) as a figure: the pixels ``valid`` through
    the 'magma' colour map from 0 to ``scale`` (pixels above it at the top colour,
    marked by the colour bar's arrow), the others light grey, and below the image a
    horizontal colour bar with its numbers (percentages with ``percent``) and
    ``quantity`` as its label.  The image spans the figure's width: 4 inches at
    ``dpi`` (400 pixels at the default 100).  With ``path`` None the PNG bytes
    are returned instead (:func:`save_figure`)."""
    import matplotlib
    from matplotlib.ticker import PercentFormatter

    error = np.ma.masked_array(np.asarray(error, dtype=float), mask=~np.asarray(valid, dtype=bool))
    cmap = matplotlib.colormaps["magma"].with_extremes(bad="0.86")
    height, width = error.shape
    fig_w = 4.0
    img_w = 3.96
    img_h = img_w * height / width
    bar_h = 1.15 + (0.3 if title else 0.0)
    fig_h = img_h + bar_h
    with matplotlib.rc_context({"font.size": 10}):
        fig = pyplot().figure(figsize=(fig_w, fig_h))
        ax = fig.add_axes(((fig_w - img_w) / 2 / fig_w, (fig_h - img_h - (0.3 if title else 0.04)) / fig_h,
                           img_w / fig_w, img_h / fig_h))
        im = ax.imshow(error, cmap=cmap, vmin=0.0, vmax=scale, interpolation="nearest")
        ax.set_axis_off()
        if title:
            ax.set_title(title, fontsize=10)
        cax = fig.add_axes((0.08, 0.62 / fig_h, 0.84, 0.16 / fig_h))
        extend = "max" if bool(np.any(error.filled(0.0) > scale)) else "neither"
        bar = fig.colorbar(im, cax=cax, orientation="horizontal", extend=extend)
        if percent:
            decimals = 0 if scale >= 0.1 else 1 if scale >= 0.01 else 2
            bar.ax.xaxis.set_major_formatter(PercentFormatter(xmax=1.0, decimals=decimals))
        bar.set_label(quantity, fontsize=10)
        bar.ax.tick_params(labelsize=9)
        return save_figure(fig, path, dpi=dpi)
