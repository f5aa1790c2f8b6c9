"""Rendering a scene in one of the three modes: :func:`render` returns the arrays
(:class:`pbrkit.rendering.result.Rendering`; ``pbrkit.render``), :func:`render_scene`
writes them to files (the ``pbrkit render`` command).
"""

from __future__ import annotations

import os

from ..choices import MODES as _MODES
from ..core import checks
from ..core.errors import InputError
from .budget import check_render_memory
from .compare import compare_images
from .environment import EnvironmentLight
from .geometry import Geometry
from .realtime import render_engine, render_realtime
from .reference import render_reference
from .result import output_suffix_ok

__all__ = [
    "MODES",
    "STAGES",
    "render",
    "render_scene",
    "check_style_flag",
    "approximation_split",
    "comparison_lines",
]

MODES = _MODES  # pbrkit.choices
#: The stages :func:`render_scene` reports to its ``progress`` callback, per mode.
STAGES = {
    "realtime": ("load", "bake", "realtime", "write"),
    "reference": ("load", "reference", "write"),
    "compare": ("load", "bake", "realtime", "reference", "compare", "split", "write"),
}


# ============================================================ the command


def approximation_split(scene, geometry, env, bake, full, reference, stderr, mask, diffuse="sh",
                        energy_compensation=False):
    """The real-time error split by approximation (:data:`pbrkit.rendering.realtime.APPROXIMATIONS`),
    by swapping one approximation at a time for an exact computation, in order:
    the SH irradiance for the irradiance cube (an exact convolution), then the
    F* diffuse weight for the exact albedo of the model's diffuse weighting;
    what remains against the reference is the split sum (``split_sum``), and
    with area lights the split sum and the LTC (``split_sum_ltc``).  Each entry is the RMS
    relative luminance difference the swap makes
    (:func:`pbrkit.rendering.compare.rms_relative_error`, over the pixels the
    headline measures; the last one against the reference with its variance
    removed), the measure of the headline
    ``rms_relative_error_noise_removed``; errors of opposite sign partly cancel
    in the headline, so the shares need not add up to it."""
    from .compare import relative_error_pixels, rms_relative_error
    from .realtime import APPROXIMATIONS

    valid = relative_error_pixels(reference, mask)

    def share(a, b):
        return rms_relative_error(a, reference, valid, baseline=b)

    options = dict(energy_compensation=energy_compensation)
    split = {}
    current = full
    if diffuse == "sh":
        cube = render_realtime(scene, geometry, env, bake=bake, diffuse="cube", **options).image
        split["sh"] = share(current, cube)
        current = cube
    exact = render_realtime(scene, geometry, env, bake=bake, diffuse="cube", diffuse_weight="exact", **options).image
    split["fstar"] = share(current, exact)
    remainder = "split_sum_ltc" if len(geometry.area_lights) else "split_sum"
    split[remainder] = rms_relative_error(exact, reference, valid, stderr)
    return {name: {"rms_relative_error": value, "description": APPROXIMATIONS[name]} for name, value in split.items()}


def _styled(style):
    """Whether ``style`` changes the real-time image (not ``pbr`` without outlines)."""
    return style is not None and (style.shading != "pbr" or style.outline != "none")


def check_style_flag(mode, style):
    """Refuse ``--style`` (a resolved style that changes the image) in a mode other than
    ``realtime``, naming the flag (:func:`_check_style_mode`; also ``pbrkit batch render``'s
    check before any scene is loaded)."""
    if mode != "realtime" and style is not None and _styled(style):
        raise ValueError(f"--style {style.shading} (outline {style.outline}) applies to --mode realtime only "
                         f"(styles are real-time shading); --mode {mode} renders the scene's materials as they "
                         "are: drop --style, or use --mode realtime")


def _check_style_mode(scene, mode, style):
    """Styles are real-time shading: in ``reference`` and ``compare`` modes a style
    that changes the image (``--style``, else the scene's ``[style]``) is refused
    before any work, naming the flag or the key (the ground truth renders the
    scene's materials as they are: a styled reference does not exist, and compare
    would set a styled image against the unstyled truth).  ``--style pbr`` (no
    style) is what renders a styled scene's materials in those modes."""
    if mode == "realtime":
        return
    check_style_flag(mode, style)
    if style is None and _styled(scene.style):
        raise InputError(f"[style] ({scene.style.shading}, outline {scene.style.outline}) applies to --mode "
                         f"realtime only (styles are real-time shading); --mode {mode} renders the scene's "
                         "materials as they are: give --style pbr to render them without the style, or use "
                         "--mode realtime", scene.source)


def render(scene, mode="realtime", spp=64, bounces=0, seed=0, diffuse="sh", energy_compensation=False,
           bake_size=256, strategy="mis", flip=True, occlusion=None, split=True, progress=None, engine="pbrkit",
           style=None, tonemap="aces", exposure=0.0, width=None, height=None, environment=None):
    """Render ``scene`` in ``mode`` (``realtime``, ``reference`` or ``compare``) and
    return a :class:`pbrkit.rendering.result.Rendering` (linear arrays, statistics;
    ``.save()``, ``.to_srgb()``, shown inline in Jupyter).  ``scene``: a
    :class:`pbrkit.rendering.scene.Scene`, a dict of a scene file's tables
    (:func:`pbrkit.rendering.scene.scene_from_dict`), a built-in scene's name
    (``spheres``, ``sphere``, ``area``) or a scene file's path; ``width`` / ``height``
    override its camera's, ``environment`` (an image file or a bake folder) its
    environment.  Every option is checked before any work.

    ``occlusion`` (objects blocking the environment in the ground truth)
    defaults to on for ``reference`` (the scene's ground truth) and off for
    ``compare`` (on when ``bounces`` > 0, which need it).  ``compare`` with its
    defaults thus compares like with like: the same BRDF, the same unoccluded
    environment, the same shadowed punctual lights, direct light only, so that
    its error measures the real-time approximations only (split sum, F*, SH;
    with ``split`` each one's share, :func:`approximation_split`).  ``engine``
    (:data:`pbrkit.rendering.realtime.ENGINES`) picks whose IBL evaluation the real-time
    image follows.  ``style`` (a :class:`pbrkit.npr.style.Style`; default the scene's
    ``[style]``) renders the real-time image in that style
    (:func:`pbrkit.npr.render.render_styled`; real-time mode only: a style that changes
    the image is refused in the other modes, :func:`_check_style_mode`).  ``progress(stage)``
    is called with each stage's name as it starts (:data:`STAGES` but ``write``)."""
    from .result import Rendering, _check_tonemap
    from .scene import BUILTIN_SCENES, Scene, scene_from_dict
    from .sources import command_scene

    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; choose one of {', '.join(MODES)}")
    _check_tonemap(tonemap, exposure)
    spp = checks.integer(spp, "--spp", 1, 1 << 20)
    bounces = checks.integer(bounces, "--bounces", 0, 64)
    if isinstance(scene, dict):
        scene = scene_from_dict(scene)
    if not isinstance(scene, (Scene, str, os.PathLike)):
        raise ValueError(f"scene must be a Scene, a dict of a scene file's tables, a built-in scene's name "
                         f"({', '.join(BUILTIN_SCENES)}) or a scene file's path; got {type(scene).__name__}")
    if not isinstance(scene, Scene):
        scene = command_scene(scene, width, height, environment)
    elif width is not None or height is not None or environment is not None:
        raise ValueError("width, height and environment apply to a scene given by name or file; change a Scene "
                         "object with dataclasses.replace")
    _check_style_mode(scene, mode, style)
    check_render_memory(scene, mode, spp, bounces, bake_size)

    def stage(name):
        if progress is not None:
            progress(name)

    if occlusion is None:  # bounces need rays that hit the other objects
        occlusion = mode == "reference" or int(bounces) > 0
    stage("load")
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    summary = {"scene": scene.source, "mode": mode, "environment": env.source,
               "width": scene.camera.width, "height": scene.camera.height, "notes": list(geometry.notes)}
    rt = ref = None
    if mode in ("realtime", "compare"):
        stage("bake")
        spec = render_engine(engine)  # the chain the engine samples, prefiltered with the bake
        curve = None if spec is None else spec.extra_chain
        bake = env.bake(size=bake_size, **({"chains": (curve,)} if curve else {}))
        stage("realtime")
        style = style or scene.style
        if _styled(style):
            from ..npr.render import render_styled

            rt = render_styled(scene, style, geometry, env, bake=bake)
        else:
            rt = render_realtime(scene, geometry, env, bake=bake, diffuse=diffuse,
                                 energy_compensation=energy_compensation, bake_size=bake_size, engine=engine)
        summary["realtime"] = rt.stats
    if mode in ("reference", "compare"):
        stage("reference")
        ref = render_reference(scene, spp=spp, bounces=bounces, seed=seed, geometry=geometry, env=env,
                               strategy=strategy, occlusion=occlusion)
        summary["reference"] = ref.stats
        summary["reference"]["includes"] = {"occlusion": bool(occlusion), "bounces": int(bounces)}
    common = dict(stats=summary, tonemap=tonemap, exposure=float(exposure))
    if mode == "realtime":
        return Rendering(mode, rt.image, rt.mask, realtime=rt.image, **common)
    if mode == "reference":
        return Rendering(mode, ref.image, ref.mask, reference=ref.image, stderr=ref.stderr, **common)
    stage("compare")
    mask = rt.mask & ref.mask
    metrics = compare_images(rt.image, ref.image, mask, ref.stderr, flip=flip)
    if split and engine == "pbrkit":
        stage("split")
        metrics["split"] = approximation_split(scene, geometry, env, bake, rt.image, ref.image, ref.stderr,
                                               mask, diffuse=diffuse, energy_compensation=energy_compensation)
    metrics.pop("relative_error_map")
    error = metrics.pop("floored_error_map")
    summary["errors"] = metrics
    return Rendering(mode, rt.image, mask, realtime=rt.image, reference=ref.image, stderr=ref.stderr, error=error,
                     **common)


def render_scene(scene, out, mode="realtime", spp=64, bounces=0, seed=0, tonemap_name="aces", exposure=0.0,
                 diffuse="sh", energy_compensation=False, bake_size=256, strategy="mis", flip=True, occlusion=None,
                 split=True, progress=None, engine="pbrkit", style=None):
    """Render ``scene`` in ``mode`` (:func:`render`) and write ``out`` (.exr or .png);
    reference and compare modes also write ``<out stem>.stderr.exr``, committed
    together with ``out``.  Nothing is written unless rendering succeeds.  Returns a
    summary dict (timings, sample counts, errors, the outputs)."""
    output_suffix_ok(out)
    result = render(scene, mode, spp=spp, bounces=bounces, seed=seed, diffuse=diffuse,
                    energy_compensation=energy_compensation, bake_size=bake_size, strategy=strategy, flip=flip,
                    occlusion=occlusion, split=split, progress=progress, engine=engine, style=style,
                    tonemap=tonemap_name, exposure=exposure)
    if progress is not None:
        progress("write")
    summary = result.stats
    summary["outputs"] = [str(p) for p in result.save(out)]
    return summary


def comparison_lines(summary):
    """What ``pbrkit render --mode compare`` prints about its comparison: what the
    ground truth includes, the headline (HDR-FLIP and the relative luminance error
    against a stated luminance floor, :mod:`pbrkit.rendering.compare`: robust on dark
    pixels; the approximations only when the ground truth has neither occlusion nor
    bounces), the relative error without the floor (the RMS with the ground truth's
    noise removed, mean, median, p90, max) and its split by approximation."""
    errors = summary.get("errors")
    if errors is None:
        return []
    includes = summary["reference"].get("includes", {})
    occluded, bounces = includes.get("occlusion", False), includes.get("bounces", 0)
    like = not occluded and bounces == 0
    if like:
        lines = ["ground truth: the same BRDF by Monte Carlo, the environment and area lights unoccluded, direct "
                 "light only (as the real-time path); punctual lights shadowed in both"]
    else:
        lines = [f"ground truth: the same BRDF by Monte Carlo with "
                 f"{'inter-object occlusion' if occluded else 'no occlusion'} and {bounces} "
                 f"bounce{'s' if bounces != 1 else ''}: the error includes what the real-time path leaves out"]
    label = "approximation error" if like else "error"
    rms = errors.get("rms_relative_error_noise_removed", errors["rms_relative_error"])
    flip = f"HDR-FLIP {errors['flip']:.4f}; " if "flip" in errors else ""
    lines.append(f"real time vs ground truth, {label}: {flip}relative luminance error with a floor (|Y - Y_ref| / "
                 f"max(Y_ref, {errors['floor_fraction']:g} x mean Y_ref = {errors['luminance_floor']:.4g})): "
                 f"mean {errors['mean_floored_error']:.4f}, median {errors['median_floored_error']:.4f}, p90 "
                 f"{errors['p90_floored_error']:.4f}")
    lines.append(f"  without the floor (dark pixels weigh most): RMS relative error {rms:.4f} (ground-truth noise "
                 f"removed); mean relative error {errors['mean_relative_error']:.4f}, median "
                 f"{errors['median_relative_error']:.4f}, p90 {errors['p90_relative_error']:.4f}, max "
                 f"{errors['max_relative_error']:.4f}; ground-truth noise "
                 f"{errors.get('mean_relative_stderr', 0.0):.4f}")
    split = errors.get("split", {})
    if split:
        lines.append("split by approximation (RMS relative error each swap removes):")
        for name, entry in split.items():
            lines.append(f"  {name:<10} {entry['rms_relative_error']:.4f}  {entry['description']}")
    return lines
