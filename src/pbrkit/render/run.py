"""Rendering a scene to files in one of the three modes (the ``pbrkit render`` command).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.color import TONEMAPS, tonemap
from .compare import compare_images, error_heatmap
from .environment import EnvironmentLight
from .geometry import Geometry
from .realtime import render_realtime
from .reference import render_reference

__all__ = [
    "MODES",
    "render_scene",
]

MODES = ("realtime", "reference", "compare")


# ============================================================ the command


def _write_outputs(out, panels, tonemap_name, exposure):
    """Write linear panels side by side: EXR (float32, linear; heat maps decoded to
    linear) or PNG (tone-mapped, sRGB)."""
    from ..core.color import linear_to_srgb, srgb_to_linear
    from ..io.exr import write_exr
    from ..io.png import write_png

    suffix = Path(out).suffix.lower()
    if suffix == ".exr":
        pieces = [srgb_to_linear(p) if kind == "srgb" else p for p, kind in panels]
        write_exr(out, np.concatenate(pieces, axis=1).astype(np.float32))
    else:
        pieces = [p if kind == "srgb" else linear_to_srgb(tonemap(p, tonemap_name, exposure)) for p, kind in panels]
        write_png(out, np.concatenate(pieces, axis=1), srgb=False)


def output_suffix_ok(out):
    suffix = Path(out).suffix.lower()
    if suffix not in (".exr", ".png"):
        raise ValueError(f"{out}: output must be .exr (linear float32) or .png (tone-mapped sRGB); got "
                         f"{suffix or 'no suffix'!r}")


def render_scene(scene, out, mode="realtime", spp=64, bounces=0, seed=0, tonemap_name="aces", exposure=0.0,
                 diffuse="sh", energy_compensation=False, bake_size=256, strategy="mis", flip=True, occlusion=True):
    """Render ``scene`` in ``mode`` and write ``out`` (.exr or .png); reference and
    compare modes also write ``<out stem>.stderr.exr``.  Nothing is written unless
    rendering succeeds.  Returns a summary dict (timings, sample counts, errors)."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; choose one of {', '.join(MODES)}")
    if tonemap_name not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {tonemap_name!r}; choose one of {', '.join(TONEMAPS)}")
    if not math.isfinite(float(exposure)):
        raise ValueError(f"exposure must be finite; got {exposure!r}")
    output_suffix_ok(out)
    from ..io.exr import write_exr

    out = Path(out)
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    summary = {"scene": scene.source, "mode": mode, "environment": env.source,
               "width": scene.camera.width, "height": scene.camera.height, "notes": list(geometry.notes)}
    rt = ref = None
    if mode in ("realtime", "compare"):
        rt = render_realtime(scene, geometry, env, diffuse=diffuse, energy_compensation=energy_compensation,
                             bake_size=bake_size)
        summary["realtime"] = rt.stats
    if mode in ("reference", "compare"):
        ref = render_reference(scene, spp=spp, bounces=bounces, seed=seed, geometry=geometry, env=env,
                               strategy=strategy, occlusion=occlusion)
        summary["reference"] = ref.stats
    stderr_path = out.with_name(out.stem + ".stderr.exr")
    if mode == "realtime":
        _write_outputs(out, [(rt.image, "linear")], tonemap_name, exposure)
    elif mode == "reference":
        write_exr(stderr_path, ref.stderr.astype(np.float32))
        _write_outputs(out, [(ref.image, "linear")], tonemap_name, exposure)
    else:
        metrics = compare_images(rt.image, ref.image, rt.mask & ref.mask, ref.stderr, flip=flip)
        heat = error_heatmap(metrics.pop("relative_error_map"), rt.mask & ref.mask)
        write_exr(stderr_path, ref.stderr.astype(np.float32))
        _write_outputs(out, [(rt.image, "linear"), (ref.image, "linear"), (heat, "srgb")], tonemap_name, exposure)
        summary["errors"] = metrics
    summary["outputs"] = [str(out)] + ([str(stderr_path)] if mode != "realtime" else [])
    return summary

