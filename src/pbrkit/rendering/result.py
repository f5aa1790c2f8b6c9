"""What :func:`pbrkit.render` returns: a rendering as arrays, with the writers that save
it (the ``pbrkit render`` command saves through them too).

A :class:`Rendering` holds linear images (float64, (H, W, 3), scene-referred radiance):
``image`` (the mode's picture: the real-time image, or the ground truth in reference
mode), ``realtime`` and ``reference`` (each None where the mode did not make it), the
ground truth's per-pixel standard error ``stderr``, the relative luminance error
``error`` of a comparison and the ``mask`` of pixels that see a surface; ``stats``, the
summary :func:`pbrkit.rendering.run.render_scene` returns (timings, sample counts,
errors).  :meth:`Rendering.to_srgb` tone-maps (``tonemap`` and ``exposure``, as the
command's ``--tonemap`` and ``--exposure``) and encodes sRGB 8-bit; :meth:`Rendering.save`
writes ``.exr`` (linear float32) or ``.png`` (tone-mapped sRGB), with the ground truth's
standard error beside it as ``<stem>.stderr.exr``, committed together; in Jupyter a
rendering shows itself (``_repr_png_``).  A comparison's picture is three panels side
by side: real time, ground truth, and the heat map of the relative luminance error
against a luminance floor (magma, 0 to 20 %; :mod:`pbrkit.rendering.compare`); as a PNG
(and inline) it is a figure with the panels' titles and the heat map's colour bar.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.color import TONEMAPS, linear_to_srgb, srgb_to_linear, tonemap

__all__ = ["Rendering", "OUTPUT_SUFFIXES", "MIN_PANEL_HEIGHT", "output_suffix_ok", "write_panels",
           "write_with_stderr", "titled_png"]

#: The file types a rendering is saved as.
OUTPUT_SUFFIXES = (".exr", ".png")


def output_suffix_ok(out):
    """``ValueError`` naming ``out`` unless it is a path ending in .exr or .png."""
    if not isinstance(out, (str, os.PathLike)):
        raise ValueError(f"the output must be a .exr or .png path; got {type(out).__name__} (pbrkit.render returns "
                         "the images as arrays without writing)")
    suffix = Path(out).suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise ValueError(f"{out}: output must be .exr (linear float32) or .png (tone-mapped sRGB); got "
                         f"{suffix or 'no suffix'!r}")


def _srgb_panels(panels, tonemap_name, exposure):
    """sRGB-encoded floats in [0, 1] of (array, kind) panels side by side: linear ones
    tone-mapped, ``srgb`` ones (heat maps) as they are."""
    return np.concatenate([p if kind == "srgb" else linear_to_srgb(tonemap(p, tonemap_name, exposure))
                           for p, kind in panels], axis=1)


def write_panels(out, panels, tonemap_name, exposure, titles=None):
    """Write (array, kind) panels side by side: EXR (float32, linear; heat maps decoded
    to linear) or PNG (tone-mapped, sRGB; with ``titles`` a titled figure,
    :func:`titled_png`)."""
    from ..io.exr import write_exr
    from ..io.png import write_png

    if Path(out).suffix.lower() == ".exr":
        pieces = [srgb_to_linear(p) if kind == "srgb" else p for p, kind in panels]
        write_exr(out, np.concatenate(pieces, axis=1).astype(np.float32))
    elif titles is not None:
        from ..core.atomic import atomic_path

        data = titled_png(panels, titles, tonemap_name, exposure)
        with atomic_path(out) as tmp:
            Path(tmp).write_bytes(data)
    else:
        write_png(out, _srgb_panels(panels, tonemap_name, exposure), srgb=False)


#: The height (pixels) a panel of a titled figure is shown at, at least (small renders
#: are enlarged without filtering).
MIN_PANEL_HEIGHT = 256


def titled_png(panels, titles, tonemap_name, exposure):
    """PNG bytes of the panels side by side, each under its title (``titles``: one per
    panel; the last panel, the heat map, with its colour bar: 0 to
    :data:`pbrkit.rendering.compare.HEATMAP_SCALE` of the floored relative error, in per
    cent), drawn with Matplotlib's Agg canvas and encoded as 8-bit RGB (no date or
    version in the file, so the same inputs give the same bytes)."""
    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from matplotlib.cm import ScalarMappable

    from .compare import HEATMAP_SCALE

    h, w = panels[0][0].shape[:2]
    zoom = max(1, -(-MIN_PANEL_HEIGHT // h))
    dpi = 100
    pw, ph = w * zoom / dpi, h * zoom / dpi
    n = len(panels)
    fig = Figure(figsize=(n * pw + 0.25 * (n + 1) + 0.9, ph + 0.6), dpi=dpi)
    FigureCanvasAgg(fig)
    for k, ((image, kind), title) in enumerate(zip(panels, titles)):
        rgb = image if kind == "srgb" else linear_to_srgb(tonemap(image, tonemap_name, exposure))
        ax = fig.add_axes(((0.25 + k * (pw + 0.25)) / fig.get_figwidth(), 0.15 / fig.get_figheight(),
                           pw / fig.get_figwidth(), ph / fig.get_figheight()))
        ax.imshow(np.clip(rgb, 0.0, 1.0), interpolation="nearest")
        ax.set_axis_off()
        ax.set_title(title, fontsize=9)
    bar = fig.add_axes(((0.25 + n * (pw + 0.25)) / fig.get_figwidth(), 0.15 / fig.get_figheight(),
                        0.15 / fig.get_figwidth(), ph / fig.get_figheight()))
    mappable = ScalarMappable(Normalize(0.0, 100.0 * HEATMAP_SCALE), colormaps["magma"])
    fig.colorbar(mappable, cax=bar).set_label("%", fontsize=8)
    canvas = fig.canvas
    canvas.draw()
    return _png_bytes(np.asarray(canvas.buffer_rgba())[..., :3])


def _png_bytes(srgb8):
    """PNG bytes of an 8-bit RGB image (imageio; no time or text chunks)."""
    import io

    import imageio.v3 as iio

    buffer = io.BytesIO()
    iio.imwrite(buffer, np.ascontiguousarray(srgb8), extension=".png")
    return buffer.getvalue()


def write_with_stderr(out, panels, stderr_path, stderr, tonemap_name, exposure, titles=None):
    """The image and its standard-error EXR, committed together (both or neither,
    :func:`pbrkit.core.atomic.atomic_group`)."""
    from ..core.atomic import atomic_group
    from ..io.exr import write_exr

    with atomic_group([out, stderr_path]) as (out_tmp, stderr_tmp):
        write_exr(stderr_tmp, stderr.astype(np.float32))
        write_panels(out_tmp, panels, tonemap_name, exposure, titles)


def _check_tonemap(name, exposure):
    if name not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {name!r}; choose one of {', '.join(TONEMAPS)}")
    if not np.isfinite(float(exposure)):
        raise ValueError(f"exposure must be finite; got {exposure!r}")


@dataclass
class Rendering:
    """A rendering as arrays (module docstring)."""

    mode: str
    image: np.ndarray
    mask: np.ndarray
    realtime: np.ndarray | None = None
    reference: np.ndarray | None = None
    stderr: np.ndarray | None = None
    error: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    tonemap: str = "aces"
    exposure: float = 0.0

    def panels(self):
        """The picture's (array, kind) panels: the image, or for a comparison the real
        time, the ground truth and the error heat map (kind ``srgb``)."""
        if self.mode != "compare":
            return [(self.image, "linear")]
        from .compare import error_heatmap

        return [(self.realtime, "linear"), (self.reference, "linear"), (error_heatmap(self.error, self.mask), "srgb")]

    def titles(self):
        """The panels' titles of a comparison's figure (None for one image)."""
        if self.mode != "compare":
            return None
        engine = (self.stats.get("realtime") or {}).get("engine", "pbrkit")
        spp = (self.stats.get("reference") or {}).get("spp")
        errors = self.stats.get("errors") or {}
        floor = errors.get("floor_fraction", 0.1)
        return [f"real time ({engine})", "ground truth" + (f" ({spp} spp)" if spp else ""),
                f"|Y - Y_ref| / max(Y_ref, {floor:g} mean Y_ref)"]

    def to_srgb(self, tonemap=None, exposure=None):
        """The picture as 8-bit sRGB (H, W', 3) ``uint8``, the panels side by side without
        titles: tone-mapped with ``tonemap`` (default the rendering's, ``aces``) at
        ``exposure`` stops, then sRGB-encoded."""
        name = self.tonemap if tonemap is None else tonemap
        stops = self.exposure if exposure is None else exposure
        _check_tonemap(name, stops)
        return np.rint(np.clip(_srgb_panels(self.panels(), name, stops), 0.0, 1.0) * 255.0).astype(np.uint8)

    def save(self, path, tonemap=None, exposure=None):
        """Write the picture to ``path`` (.exr: linear float32, the panels side by side;
        .png: tone-mapped sRGB, a comparison as a titled figure with the error's colour
        bar, :func:`titled_png`), and where there is a ground truth its standard error to
        ``<stem>.stderr.exr``, committed together.  Returns the paths written."""
        output_suffix_ok(path)
        name = self.tonemap if tonemap is None else tonemap
        stops = self.exposure if exposure is None else exposure
        _check_tonemap(name, stops)
        path = Path(path)
        if self.stderr is None:
            write_panels(path, self.panels(), name, stops, self.titles())
            return [path]
        stderr_path = path.with_name(path.stem + ".stderr.exr")
        write_with_stderr(path, self.panels(), stderr_path, self.stderr, name, stops, self.titles())
        return [path, stderr_path]

    def _repr_png_(self):
        """The 8-bit sRGB picture as PNG bytes (Jupyter and IPython show it inline; a
        comparison as its titled figure)."""
        if self.mode == "compare":
            return titled_png(self.panels(), self.titles(), self.tonemap, self.exposure)
        return _png_bytes(self.to_srgb())

    def __repr__(self):
        h, w = self.image.shape[:2]
        parts = [f"mode={self.mode!r}", f"{w} x {h}"]
        errors = self.stats.get("errors") or {}
        if "flip" in errors:
            parts.append(f"HDR-FLIP {errors['flip']:.4f}")
        if "mean_floored_error" in errors:
            parts.append(f"relative error (floor {errors['floor_fraction']:g} mean Y) mean "
                         f"{errors['mean_floored_error']:.4f}, median {errors['median_floored_error']:.4f}")
        return f"Rendering({', '.join(parts)})"
