"""``pbrkit demo``: bake the bundled environment, render the sphere grid in real
time and as Monte Carlo ground truth, and write one self-contained web page
(``index.html``) with every image, the numbers and the bake's manifest.

The page uses relative links only and no script, so it opens from the file
system without a server.  The ground truth of the demo is rendered without
occlusion between the spheres and with direct light only
(``render_reference(..., occlusion=False)``): each sphere sees the whole
environment, as real-time IBL assumes, so the error map shows the shading
approximations (:data:`pbrkit.rendering.realtime.APPROXIMATIONS`) rather than
the missing inter-object shadows; the page says what the ground truth
includes (``summary["reference"]["includes"]``).

The bake has :data:`DEMO_LEVELS` specular levels (roughness steps of 0.2),
the error map its colour bar on a scale taken from the data (the 99th
percentile rounded up, :func:`pbrkit.io.figures.error_scale`), and the
error's split by approximation (:func:`pbrkit.rendering.run.approximation_split`)
is tabulated (``summary["errors"]["split"]``).
"""

from __future__ import annotations

import html
import json
import time
from pathlib import Path

import numpy as np

from ..core import checks
from ..core.atomic import atomic_directory, write_text
from ..core.inputs import read_text
from ..io.exr import write_exr
from ..io.png import write_png
from ..io.figures import new_figure, save_figure
from .demo_sections import (DEMO_LEVELS, ERROR_QUANTITY, FURNACE_LOBES, GLTF_EXTENSION_MATERIALS,  # noqa: F401
                            area_light_comparison, gltf_extensions_comparison, gltf_extensions_scene, npr_gallery,
                            sphere_discs, whole_image_errors, write_comparison)

__all__ = ["run_demo", "FURNACE_LOBES", "DEMO_LEVELS", "DEMO_ENTRIES", "ERROR_QUANTITY", "GLTF_EXTENSION_MATERIALS",
           "gltf_extensions_scene"]



def _lut_plot(path, table, spec):
    fig, axes = new_figure(1, 2, figsize=(8.0, 3.6))
    for c, (ax, name) in enumerate(zip(axes, ("DFG1", "DFG2 = E(mu), F = 1"))):
        im = ax.imshow(table[..., c], origin="lower", extent=(0.0, 1.0, 0.0, 1.0), vmin=0.0, vmax=1.0,
                       cmap="viridis", interpolation="nearest")
        ax.set_xlabel("n.v")
        ax.set_ylabel("perceptual roughness r")
        ax.set_title(name, fontsize=9)
        fig.colorbar(im, ax=ax, fraction=0.046)
    fig.suptitle(f"DFG lookup table ({spec.size} x {spec.size}, {spec.visibility} Smith GGX)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)


def _fmt(x, digits=4):
    return f"{x:.{digits}g}" if isinstance(x, float) else str(x)


def _seconds(x):
    """Every timing of the page: seconds with three decimals and the unit."""
    return f"{float(x):.3f} s"


def _write_previews(out, baked, face_size=64, gap=4):
    """The bake's preview crosses (:func:`pbrkit.ibl.bake.preview_strip`, one exposure
    for all) as one PNG each: ``preview/specular_m{m}.png`` per specular level and
    ``preview/irradiance.png``; returns their paths relative to ``out``."""
    from ..ibl.bake import preview_strip

    strip = preview_strip(baked, face_size=face_size, gap=gap)
    width = 4 * face_size
    names = [f"preview/specular_m{m}.png" for m in range(len(baked.specular))] + ["preview/irradiance.png"]
    (out / "preview").mkdir(parents=True, exist_ok=True)
    for k, name in enumerate(names):
        x = k * (width + gap)
        write_png(out / name, strip[:, x:x + width], bits=8, srgb=True)
    return names


def _model_description(scene):
    spec = scene.materials[scene.objects[0].material]
    terms = f"{spec.distribution} D, {spec.masking} Smith, {spec.fresnel} Fresnel, {spec.diffuse} diffuse"
    return {"model": spec.model, "terms": terms}


def run_demo(out_dir, size=384, spp=192, bake_size=128, seed=0, furnace=(32, 11, 256), progress=None):
    """Run the demo into ``out_dir`` and return its summary (also in ``summary.json``).

    ``size``: the sphere grid's image side in pixels; ``spp``: ground-truth samples
    per pixel; ``bake_size``: the specular cube's level-0 size (a power of two
    >= 32: the chain has :data:`DEMO_LEVELS` levels down to ``bake_size / 32``);
    ``furnace``: the furnace report's (n.v values, roughness values, Monte Carlo
    samples).  ``progress(step)`` is called with the name of each finished step.

    The outputs are committed together: everything is written into a temporary
    folder beside ``out_dir`` that becomes ``out_dir`` only when the page is
    written (:func:`pbrkit.core.atomic.atomic_directory`), so a failure or an
    interruption leaves ``out_dir`` as it was.  ``out_dir`` must be absent,
    empty, or a previous demo's folder (only names the demo writes,
    :data:`DEMO_ENTRIES`), which is then replaced as a whole; a folder holding
    anything else is refused before any work.  The memory the comparison needs
    is checked up front (:func:`pbrkit.rendering.budget.check_render_memory`)."""
    from ..data import environment_path
    from ..rendering.budget import check_render_memory
    from ..rendering.scene import EnvironmentSpec, builtin_scene

    size = checks.integer(size, "--size", 16, 4096)
    spp = checks.integer(spp, "--spp", 1, 1 << 16)
    bake_size = checks.power_of_two(bake_size, "--bake-size", 1 << (DEMO_LEVELS - 1), 2048)
    out = Path(out_dir)
    replace = _check_demo_folder(out)
    env_path = environment_path()
    scene = builtin_scene("spheres", size, size, EnvironmentSpec(file=str(env_path)))
    check_render_memory(scene, "compare", spp, bake_size=bake_size)
    # Every file is written into a temporary folder beside OUT, renamed to OUT when all are there.
    with atomic_directory(out, force=replace) as tmp:
        summary = _run_demo(tmp, scene, env_path, size, spp, bake_size, seed, furnace, progress)
        foreign = _foreign_entries(out)
        if foreign:
            raise ValueError(f"{out}: files other than a demo's appeared meanwhile ({', '.join(foreign)}); "
                             "nothing written")
    return summary


#: What the demo writes at the top of its folder: a folder holding only these (a
#: previous demo's) is replaced as a whole; one holding anything else is refused.
DEMO_ENTRIES = frozenset({"index.html", "summary.json", "realtime.png", "reference.png", "error.png", "lut.png",
                          "realtime.exr", "reference.exr", "reference_stderr.exr", "relative_error.exr", "bake",
                          "preview", "furnace", "area_realtime.png", "area_reference.png", "area_error.png",
                          "npr_toon.png", "npr_mtoon.png", "npr_hatching.png", "model.glb", "npr_model_pbr.png",
                          "npr_model_toon.png", "npr_model_mtoon.png", "npr_model_hatching.png",
                          "npr_model_outline.png", "gltf_realtime.png", "gltf_reference.png", "gltf_error.png",
                          "gltf_extensions"})


def _demo_entries():
    from ..data import ENVIRONMENT

    return DEMO_ENTRIES | {ENVIRONMENT["licence_file"]}


def _foreign_entries(out):
    """Names in the folder ``out`` (if it is one) that the demo does not write, sorted."""
    if not out.is_dir():
        return []
    return sorted(entry.name for entry in out.iterdir() if entry.name not in _demo_entries())


def _check_demo_folder(out):
    """Whether ``out`` holds a previous demo to replace: False if it is absent or
    empty; True if every entry is one the demo writes (:data:`DEMO_ENTRIES`);
    ValueError if it is not a folder or holds anything else (never deleted)."""
    if not (out.exists() or out.is_symlink()):
        return False
    if not out.is_dir():
        raise ValueError(f"{out}: exists and is not a directory")
    foreign = _foreign_entries(out)
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        raise ValueError(f"{out}: directory holds files other than a previous demo's ({shown}); give a new or "
                         "empty folder")
    return any(out.iterdir())


def _run_demo(out, scene, env_path, size, spp, bake_size, seed, furnace, progress):
    """The demo's work, written into the folder ``out`` (run_demo's temporary folder),
    with the parallel warm-up of :mod:`pbrkit.app.warmup` on a first run."""
    from .warmup import WarmUp

    warm = WarmUp.start(env_path)
    try:
        return _demo_steps(out, scene, env_path, size, spp, bake_size, seed, furnace, progress, warm)
    finally:
        if warm is not None:
            warm.close()


def _demo_steps(out, scene, env_path, size, spp, bake_size, seed, furnace, progress, warm):
    from .. import __version__
    from ..albedo.furnace import furnace_lobes
    from ..albedo.lut import lookup_table
    from ..data import ENVIRONMENT, environment_licence_path
    from ..ibl.bake import bake as bake_environment
    from ..io.bake_files import write_bake
    from ..io.environment import load_environment
    from ..rendering.environment import EnvironmentLight
    from ..rendering.geometry import Geometry
    from ..rendering.realtime import APPROXIMATIONS, render_realtime
    from ..rendering.reference import render_reference
    from ..rendering.run import approximation_split
    from .report import albedo_families, furnace_report

    step = progress or (lambda name: None)
    timings = {}
    t_start = time.perf_counter()

    def signal(name):  # the worker may compile what needs this step's kernels
        if warm is not None:
            warm.signal(name)

    def wait(name):  # the step's kernels: claim them, or wait for the worker that compiles them
        if warm is not None:
            warm.ready(name)

    # 1. bake the bundled environment, with roughness steps of 1 / (DEMO_LEVELS - 1) = 0.2
    t = time.perf_counter()
    environment = load_environment(env_path)
    baked = bake_environment(environment, size=bake_size, min_size=bake_size >> (DEMO_LEVELS - 1))
    write_bake(baked, out / "bake", force=True)
    previews = _write_previews(out, baked)
    timings["bake (incl. writing)"] = time.perf_counter() - t
    signal("bake")
    step("bake")

    # 2. the sphere grid, real time and ground truth
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    env.bake_data = baked
    rt = render_realtime(scene, geometry, env, bake=baked)
    timings["real-time render"] = rt.stats["timings"]["total"]
    signal("realtime")
    step("realtime")
    # 3. furnace and lookup-table plots (before the ground truth: on a first run their kernels
    # compile here while the warm-up process compiles the ground truth's)
    wait("furnace")
    t = time.perf_counter()
    lobes = [name for name in FURNACE_LOBES if name in furnace_lobes()]
    n_mu, n_rough, samples = furnace
    furnace_summary, _ = furnace_report(out / "furnace", n_mu=n_mu, roughness=np.linspace(0.0, 1.0, n_rough),
                                        samples=samples, seed=seed, lobes=lobes)
    families = albedo_families(lobes)
    furnace_figures = ([f"furnace/furnace_{family}.png" for family in families] if len(families) > 1
                       else ["furnace/furnace.png"])
    timings["furnace report"] = time.perf_counter() - t
    step("furnace")
    t = time.perf_counter()
    table, spec = lookup_table("dfg", 64)
    _lut_plot(out / "lut.png", table, spec)
    timings["lookup table"] = time.perf_counter() - t
    step("lut")
    # the sphere grid in the non-photorealistic styles, lit by the environment and a key light (before
    # the ground truth: on a first run their kernels compile here while the warm-up process compiles
    # the ground truth's)
    wait("npr")
    t = time.perf_counter()
    npr = npr_gallery(out, scene, env, baked, max(16, size // 2))
    timings["styles"] = time.perf_counter() - t
    step("npr")
    # the area-light scene: LTC against the ground truth (its real-time half compiles while the
    # warm-up process compiles the ground truth's kernel, which it then waits for)
    wait("area")
    t = time.perf_counter()
    area = area_light_comparison(out, size, spp, seed, before_reference=lambda: wait("reference"))
    timings["area-light scene"] = time.perf_counter() - t
    step("area")
    wait("reference")
    ref = render_reference(scene, spp=spp, seed=seed, geometry=geometry, env=env, occlusion=False)
    timings["ground-truth render"] = ref.stats["timings"]["total"]
    # the glTF material extensions, one sphere each, in both modes (after the sphere grid's ground
    # truth: its kernels are compiled by then; the extensions' by the warm-up process, on a first run)
    wait("gltf")
    t = time.perf_counter()
    gltf_extensions = gltf_extensions_comparison(out, scene.environment, env, baked, size, spp, seed)
    timings["glTF extensions"] = time.perf_counter() - t
    step("reference")
    t = time.perf_counter()
    mask, metrics, rel, valid, (scale, p99, peak) = whole_image_errors(rt, ref)
    per_sphere = _per_sphere_errors(scene, rt, ref)
    timings["errors (incl. FLIP)"] = time.perf_counter() - t
    # the error split by approximation (summary["errors"]["split"], rendered by _split_table)
    t = time.perf_counter()
    metrics["split"] = approximation_split(scene, geometry, env, baked, rt.image, ref.image, ref.stderr, mask)
    timings["error split by approximation"] = time.perf_counter() - t
    write_comparison(out, "", rt, ref, rel, valid, scale)
    write_exr(out / "realtime.exr", rt.image.astype(np.float32))
    write_exr(out / "reference.exr", ref.image.astype(np.float32))
    write_exr(out / "reference_stderr.exr", ref.stderr.astype(np.float32))
    write_exr(out / "relative_error.exr", np.where(valid, rel, 0.0).astype(np.float32))
    step("images")




    manifest_path = out / "bake" / "manifest.json"
    manifest = json.loads(read_text(manifest_path)) if manifest_path.exists() else dict(baked.manifest)
    timings["total"] = time.perf_counter() - t_start
    if warm is not None:  # a first run: the worker compiled the later steps' kernels meanwhile
        timings["waited for the warm-up process"] = warm.waited
    summary = {
        "pbrkit": __version__,
        "environment": dict(ENVIRONMENT),
        "image": {"width": size, "height": size, "spheres": len(scene.objects), **_model_description(scene)},
        "bake": {"size": bake_size, "min_size": bake_size >> (DEMO_LEVELS - 1), "levels": len(baked.specular),
                 "roughness": [float(r) for r in baked.roughness],
                 "irradiance_size": int(np.asarray(baked.irradiance).shape[1]), "previews": previews},
        "realtime": {"diffuse": rt.stats["diffuse"], "timings": rt.stats["timings"],
                     "approximations": dict(APPROXIMATIONS)},
        "reference": {**{k: ref.stats[k] for k in ("spp", "bounces", "seed", "strategy", "occlusion", "paths",
                                                   "surface_paths", "paths_per_second", "engine")},
                      "includes": {"occlusion": bool(ref.stats["occlusion"]), "bounces": int(ref.stats["bounces"])}},
        "errors": metrics,
        "error_map": {"quantity": ERROR_QUANTITY, "colour_map": "magma", "scale_max": scale,
                      "scale_rule": "99th percentile of the compared pixels, rounded up to 1, 2, 2.5 or 5 x 10^k",
                      "percentile_99": p99, "max": peak, "pixels_above_scale": int(np.count_nonzero(rel[valid] > scale))},
        "per_sphere_signed_relative_error": per_sphere,
        "area_light": area,
        "gltf_extensions": gltf_extensions,
        "npr": npr,
        "furnace": {name: furnace_summary["per_lobe"][name] for name in lobes},
        "furnace_options": {"mu": n_mu, "roughness": n_rough, "samples": samples,
                            "monte_carlo": furnace_summary.get("monte_carlo", ""), "figures": furnace_figures},
        "timings_s": timings,
    }
    write_text(out / "summary.json", json.dumps(summary, indent=2, default=float) + "\n")
    write_text(out / ENVIRONMENT["licence_file"], environment_licence_path().read_text(encoding="utf-8"))
    write_text(out / "index.html", _page(summary, manifest))
    step("page")
    return summary


def _npr_section(summary):
    """The page's styles section (summary["npr"], when present)."""
    npr = summary.get("npr")
    if not npr:
        return ""
    figures = "\n".join(
        f'<figure><img src="{html.escape(e["file"])}" alt="sphere grid, {html.escape(name)} style">'
        f"<figcaption><b>{html.escape(name)}</b>, outline {html.escape(e['outline'])} "
        f"({e['seconds']:.2f} s)</figcaption></figure>" for name, e in npr["styles"].items())
    model = npr.get("model", {}).get("styles", {})
    model_figures = "\n".join(
        f'<figure><img src="{html.escape(e["file"])}" alt="model, {html.escape(name)} style">'
        f"<figcaption><b>{html.escape(name)}</b>: {html.escape(e['shading'])}, outline {html.escape(e['outline'])} "
        f"({e['seconds']:.2f} s)</figcaption></figure>" for name, e in model.items())
    return f"""<h2>Non-photorealistic styles</h2>
<p class="note">The sphere grid ({npr["size"]}&sup2;) with a key light added, rendered in real time with
<code>pbrkit render --style</code>'s presets (<code>pbrkit.npr</code>): toon bands over the summed lighting with
thresholded highlights, a banded SH irradiance and rim light; VRM MToon 1.0; hatching with pbrkit's tonal art
map; outlines from the G-buffers.</p>
<div class="grid">
{figures}
</div>
<p class="note">A glTF model (<a href="model.glb">model.glb</a>: a torus knot on a box that pbrkit generates, CC0)
in the same light: toon with G-buffer and mesh outlines (silhouettes, the box's creases, the edge between the two
materials), MToon with the inverted hull, hatching in texture space (the strokes follow the mesh's TEXCOORD_0)
with mesh outlines, and PBR with both outlines.</p>
<div class="grid">
{model_figures}
</div>
"""


def _per_sphere_errors(scene, rt, ref):
    """Signed relative luminance error (Y_rt - Y_ref) / Y_ref averaged over the inner
    80% (radius) of each sphere of the grid, as rows (metallic) of columns (roughness)."""
    from ..core.color import luminance

    cam = scene.camera
    rows, cols = np.mgrid[0:cam.height, 0:cam.width] + 0.5
    y_rt = luminance(rt.image)
    y_ref = luminance(ref.image)
    out = []
    n = int(round(len(scene.objects) ** 0.5))
    for k, (r, c, radius) in enumerate(sphere_discs(scene, 0.8)):
        inside = ((rows - r) ** 2 + (cols - c) ** 2 < radius * radius) & rt.mask & ref.mask & (y_ref > 0)
        value = float(np.mean((y_rt[inside] - y_ref[inside]) / y_ref[inside])) if inside.any() else float("nan")
        if k % n == 0:
            out.append([])
        out[-1].append(value)
    return out


_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; padding: 0 1em;
       line-height: 1.45; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px solid #ddd; }
h3 { font-size: 1.05em; margin-top: 1.4em; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; text-align: center; }
figure img { max-width: 100%; border: 1px solid #ccc; image-rendering: auto; }
.grid figure { width: 360px; } .grid img { width: 360px; }
img.crop { width: 112px; image-rendering: auto; border: 1px solid #ccc; }
.crosses figure { width: 176px; margin: 0.3em; } .crosses img { width: 176px; image-rendering: pixelated; }
figure.wide { display: block; margin: 0.6em 0; } figure.wide img { width: 100%; max-width: 1150px; }
figcaption { font-size: 0.85em; color: #444; }
table { border-collapse: collapse; margin: 0.6em 0; } td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; }
th { background: #f3f3f3; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: #f7f7f7; border: 1px solid #ddd; padding: 0.8em; overflow: auto; max-height: 28em; font-size: 0.8em; }
.note { color: #444; font-size: 0.9em; }
.box { background: #f6f8fb; border: 1px solid #d8dee8; padding: 0.5em 1em; margin: 0.8em 0; font-size: 0.92em; }
.box h3 { margin: 0.3em 0; font-size: 1em; } .box ul { margin: 0.3em 0; padding-left: 1.4em; }
"""


def _rows(pairs):
    """Table rows: a header cell and a right-aligned value; a str value is shown as it is
    (the caller formats numbers with units), a number through :func:`_fmt`."""
    return "\n".join(f"<tr><th>{html.escape(str(k))}</th><td class=\"num\">{html.escape(_fmt(v))}</td></tr>"
                     for k, v in pairs)


def _percent(x, digits=1):
    return f"{100.0 * x:.{digits}f}%"


def _includes_box(summary):
    """What the ground truth includes (``summary["reference"]["includes"]``) and what the
    real-time path approximates (``summary["realtime"]["approximations"]``)."""
    ref = summary["reference"]
    includes = ref.get("includes")
    parts = []
    if includes is not None:
        occluded, bounces = bool(includes.get("occlusion", False)), int(includes.get("bounces", 0))
        occ = ("inter-object occlusion: <b>yes</b> (the spheres block one another's environment light)" if occluded
               else "inter-object occlusion: <b>no</b> (each sphere sees the whole environment, as real-time IBL "
                    "assumes)")
        bnc = (f"bounces: <b>{bounces}</b> (direct light only)" if bounces == 0
               else f"bounces: <b>{bounces}</b> (light reflected between the spheres)")
        verdict = ("like for like with the real-time path, so the error below is that of its approximations "
                   "(plus the ground truth's Monte Carlo noise, reported beside it)" if not occluded and bounces == 0
                   else "more than the real-time path computes, so the error below includes what real time leaves "
                        "out, not only its approximations")
        parts.append(f"<h3>What the ground truth includes</h3><ul><li>{occ}</li><li>{bnc}</li>"
                     f"<li>the same BRDF, evaluated exactly, with {html.escape(str(ref['spp']))} Monte Carlo "
                     f"samples per pixel ({html.escape(str(ref['strategy']))})</li></ul>"
                     f"<p>That is {verdict}.</p>")
    approximations = summary["realtime"].get("approximations") or {}
    if approximations:
        items = "".join(f"<li><code>{html.escape(name)}</code>: {html.escape(text)}</li>"
                        for name, text in approximations.items())
        parts.append(f"<h3>What the real-time path approximates</h3><ul>{items}</ul>")
    return f'<div class="box">{"".join(parts)}</div>' if parts else ""


def _split_table(errors):
    """The error split by approximation, ``errors["split"]``: {name: {value key: float,
    "description": str}} (:func:`pbrkit.rendering.run.approximation_split`); empty without it."""
    split = errors.get("split")
    if not split:
        return ""
    keys = [k for k in ("rms_relative_error", "mean_relative_error")
            if all(isinstance(entry.get(k), (int, float)) for entry in split.values())]
    titles = {"rms_relative_error": "RMS relative error", "mean_relative_error": "mean relative error"}
    head = "".join(f"<th>{titles[k]}</th>" for k in keys)
    rows = "\n".join(
        f"<tr><th><code>{html.escape(name)}</code></th>"
        + "".join(f'<td class="num">{entry[k]:.4f}</td>' for k in keys)
        + f"<td>{html.escape(str(entry.get('description', '')))}</td></tr>"
        for name, entry in split.items())
    return f"""<h3>Error split by approximation</h3>
<p class="note">Each approximation of the real-time path swapped, one at a time, for an exact computation; the
value is the relative luminance error that swap removes. Errors of opposite sign partly cancel in the total,
so the shares need not add up to it.</p>
<table><tr><th>approximation</th>{head}<th>what it replaces</th></tr>
{rows}
</table>"""


def _comparison_rows(section):
    """The error and timing rows of a section comparing the two modes (its "errors" and
    "timings")."""
    e = section["errors"]
    t = section["timings"]
    return [("mean relative error", _percent(e["mean_relative_error"])),
            ("RMS relative error, ground-truth noise removed", _percent(e.get("rms_relative_error_noise_removed", 0.0))),
            ("ground-truth noise (mean relative standard error)", _percent(e.get("mean_relative_stderr", 0.0))),
            ("HDR-FLIP", f"{e.get('flip', float('nan')):.4f}"),
            ("real time / ground truth (s)", f"{t['realtime']:.2f} / {t['reference']:.2f}")]


def _area_section(summary):
    """The page's area-light section (summary["area_light"], when present)."""
    area = summary.get("area_light")
    if not area:
        return ""
    rows = _comparison_rows(area)
    light = area["light"]
    return f"""<h2>Area light (Linearly Transformed Cosines)</h2>
<p class="note">Five gold spheres, perceptual roughness 0.1 to 0.9, on a grey glTF floor under a
{light["width"]:g} &times; {light["height"]:g} m {html.escape(light["type"])} light of radiance
{light["radiance"][0]:g} cd/m&sup2;, in a dim constant environment; {area["image"]["width"]} &times;
{area["image"]["height"]} pixels. Real time: pbrkit's LTC table (fitted for the exact horizon clipping) for the
specular lobe and the exact polygon form factor for the diffuse one, no shadows (as engines). Ground truth
({area["spp"]} spp): spherical-rectangle light sampling and BRDF sampling with multiple importance sampling,
without occlusion (like for like).</p>
<div class="grid">
<figure><img src="area_realtime.png" alt="area light, real time"><figcaption>real time (LTC)</figcaption></figure>
<figure><img src="area_reference.png" alt="area light, ground truth"><figcaption>ground truth</figcaption></figure>
<figure><img src="area_error.png" alt="area light, relative luminance error map">
<figcaption>relative luminance error, colour scale 0 to {100.0 * area["error_map"]["scale_max"]:g}%</figcaption>
</figure>
</div>
<table>{_rows(rows)}</table>
"""


def _gltf_section(summary):
    """The page's glTF material extensions section (summary["gltf_extensions"], when present)."""
    g = summary.get("gltf_extensions")
    if not g:
        return ""
    rows = _comparison_rows(g)

    def keys(material):
        return ", ".join(f"<code>{html.escape(k)}</code> = " + html.escape(
            ", ".join(f"{x:g}" for x in v) if isinstance(v, list) else f"{v:g}") for k, v in material.items())

    sheen = "the Charlie-prefiltered chain at the sheen roughness"
    material_rows = "\n".join(
        f"<tr><th>{html.escape(m['name'])}</th>"
        f'<td><img class="crop" src="{html.escape(m["files"]["realtime"])}" alt="{html.escape(m["name"])}, '
        f'real time"></td>'
        f'<td><img class="crop" src="{html.escape(m["files"]["reference"])}" alt="{html.escape(m["name"])}, '
        f'ground truth"></td>'
        f'<td class="num">{_percent(m["errors"]["mean_relative_error"])}</td>'
        f'<td class="num">{_percent(m["errors"].get("rms_relative_error_noise_removed", 0.0))}</td>'
        f'<td class="num">{100.0 * m["errors"]["signed_relative_error"]:+.1f}%</td>'
        f'<td class="num">{_percent(m["errors"].get("mean_relative_stderr", 0.0))}</td>'
        f"<td>{html.escape(m['shows'])}<br><span class=\"note\">{keys(m['material'])}</span></td></tr>"
        for m in g["materials"])
    return f"""<h2>glTF material extensions</h2>
<p class="note">One sphere per KHR_materials extension of the <code>gltf</code> model (the material keys of
<code>pbrkit render</code>'s scene files; <code>pbrkit.io.gltf_materials</code> reads them from glTF files), the
core model first as the reference; {g["image"]["width"]} &times; {g["image"]["height"]} pixels, lit by the same
environment and bake as the sphere grid. Real time, as the Khronos glTF Sample Viewer evaluates the extensions:
the base's split sum (with KHR_materials_specular's and KHR_materials_ior's F0 and F90) scaled by the sheen's and
the coat's albedo terms, the clear coat's own lookup in the prefiltered chain at its roughness and its own DFG
term, and the sheen's albedo table times {sheen}. Ground truth ({g["spp"]} spp): the layered BRDF evaluated and sampled exactly,
without occlusion (like for like).</p>
<div class="grid">
<figure><img src="gltf_realtime.png" alt="glTF extensions, real time"><figcaption>real time</figcaption></figure>
<figure><img src="gltf_reference.png" alt="glTF extensions, ground truth"><figcaption>ground truth</figcaption>
</figure>
<figure><img src="gltf_error.png" alt="glTF extensions, relative luminance error map">
<figcaption>relative luminance error, colour scale 0 to {100.0 * g["error_map"]["scale_max"]:g}%</figcaption>
</figure>
</div>
<table>{_rows(rows)}</table>
<h3>Per material (over the inner 80% of each sphere)</h3>
<table><tr><th>material</th><th>real time</th><th>ground truth</th><th>mean relative error</th>
<th>RMS relative error, noise removed</th><th>mean signed error</th><th>ground-truth noise</th><th>what it shows</th>
</tr>
{material_rows}
</table>
"""


def _page(summary, manifest):
    e = summary["errors"]
    ref = summary["reference"]
    env = summary["environment"]
    bake = summary["bake"]
    emap = summary["error_map"]
    error_rows = []
    if "rms_relative_error_noise_removed" in e:
        error_rows.append(("RMS relative error, ground-truth noise removed (headline)",
                           e["rms_relative_error_noise_removed"]))
    error_rows += [("RMS relative error", e.get("rms_relative_error", float("nan"))),
                   ("mean relative error (luminance)", e["mean_relative_error"]),
                   ("max relative error (luminance)", e["max_relative_error"]),
                   ("HDR-FLIP (mean)", e.get("flip", float("nan"))),
                   ("ground-truth noise: mean relative standard error", e.get("mean_relative_stderr", float("nan"))),
                   ("pixels compared", e["pixels"])]
    sample_rows = [("samples per pixel", ref["spp"]), ("paths (all pixels)", ref["paths"]),
                   ("paths on surfaces", ref["surface_paths"]),
                   ("paths on surfaces per second", f"{float(ref['paths_per_second']):,.0f} /s"),
                   ("strategy", ref["strategy"]), ("bounces", ref["bounces"]),
                   ("inter-object occlusion", "yes" if ref["occlusion"] else "no"), ("engine", ref["engine"])]
    timing_rows = [(k, _seconds(v)) for k, v in summary["timings_s"].items()]
    rt_rows = [(k, _seconds(v)) for k, v in summary["realtime"]["timings"].items()]
    grid = summary["per_sphere_signed_relative_error"]
    grid_rows = "\n".join(
        "<tr><th>metallic " + f"{i / max(len(grid) - 1, 1):.2f}</th>"
        + "".join(f"<td class=\"num\">{100.0 * v:+.1f}%</td>" for v in row) + "</tr>"
        for i, row in enumerate(grid))
    grid_head = "".join(f"<th>r = {j / max(len(grid[0]) - 1, 1):.2f}</th>" for j in range(len(grid[0])))
    fo = summary["furnace_options"]
    furnace_rows = "\n".join(
        f"<tr><th>{html.escape(name)}</th><td class=\"num\">{s['min_albedo']:.4f}</td>"
        f"<td class=\"num\">{s['max_albedo']:.4f}</td><td class=\"num\">{s['max_energy_loss']:.4f}</td>"
        f"<td class=\"num\">{_percent(s['fraction_within_3_stderr'])}</td>"
        f"<td class=\"num\">{s['max_abs_mc_minus_quadrature']:.2e}</td></tr>"
        for name, s in summary["furnace"].items())
    furnace_figs = "\n".join(
        f'<figure class="wide"><img src="{html.escape(p)}" alt="white furnace plot {html.escape(p)}">'
        f"<figcaption>E(mu) against mu = n.v, one curve per roughness "
        f'(<a href="{html.escape(p)}">full size</a>)</figcaption></figure>' for p in fo["figures"])
    levels = bake["levels"]
    crosses = "\n".join(
        f'<figure><img src="{html.escape(p)}" alt="specular level {m}, roughness {r:.2f}">'
        f"<figcaption><b>level {m}: r = {r:.2f}</b><br>{max(bake['size'] >> m, 1)}&sup2; texels per face"
        + (" (the environment itself)" if m == 0 else "") + "</figcaption></figure>"
        for m, (p, r) in enumerate(zip(bake["previews"][:levels], bake["roughness"])))
    irradiance = bake["previews"][levels]
    steps = 1.0 / max(levels - 1, 1)
    size = summary["image"]
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>pbrkit demo</title>
<style>{_CSS}</style>
</head>
<body>
<h1>pbrkit demo: real-time shading against Monte Carlo ground truth</h1>
<p>pbrkit {html.escape(str(summary["pbrkit"]))}. Environment: <b>{html.escape(env["name"])}</b>
(<code>{html.escape(env["source_file"])}</code> by {html.escape(env["author"])},
{html.escape(env["licence"])}: <a href="{html.escape(env["licence_file"])}">licence and source</a>),
bundled as <code>{html.escape(env["file"])}</code>, {env["resolution"][0]} &times; {env["resolution"][1]}
equirectangular. Baked at {bake["size"]}&sup2; with {levels} specular levels (roughness steps of {steps:.2f}).</p>

<h2>Sphere grid</h2>
<p class="note">{size["spheres"]} spheres, {size["width"]} &times; {size["height"]} pixels: perceptual roughness
0 to 1 from left to right, metallic 0 to 1 from top to bottom; model <code>{html.escape(size["model"])}</code>
({html.escape(size["terms"])}). Real time: split-sum image-based lighting from the bake (prefiltered specular
chain, DFG table, {html.escape(str(summary["realtime"]["diffuse"]).upper())} irradiance for the diffuse). Ground
truth: Monte Carlo with environment importance sampling, visible-normal GGX sampling and multiple importance
sampling. Tone mapping: ACES (Hill's fit).</p>
{_includes_box(summary)}
<div class="grid">
<figure><img src="realtime.png" alt="real-time render">
<figcaption>real time (<a href="realtime.exr">EXR</a>)</figcaption></figure>
<figure><img src="reference.png" alt="ground-truth render"><figcaption>ground truth, {ref["spp"]} spp
(<a href="reference.exr">EXR</a>, <a href="reference_stderr.exr">standard error</a>)</figcaption></figure>
<figure><img src="error.png" alt="relative luminance error map with its colour bar">
<figcaption>{html.escape(emap["quantity"])}: colour scale 0 to {100.0 * emap["scale_max"]:g}%
(the 99th percentile of the compared pixels, {_percent(emap["percentile_99"])}, rounded up);
maximum {_percent(emap["max"])}; {emap["pixels_above_scale"]} pixels above the scale show its top colour;
grey: not compared (<a href="relative_error.exr">EXR</a>)</figcaption></figure>
</div>
<h3>Errors (real time against ground truth)</h3>
<table>{_rows(error_rows)}</table>
<!-- error split by approximation: summary["errors"]["split"] (pbrkit.rendering.run.approximation_split);
     the table appears only when the summary has it -->
{_split_table(e)}
<h3>Mean signed error per sphere</h3>
<p class="note">(Y<sub>rt</sub> - Y<sub>ref</sub>) / Y<sub>ref</sub> over the inner 80% of each sphere:
positive where real time is brighter than the ground truth.</p>
<table><tr><th></th>{grid_head}</tr>
{grid_rows}
</table>
<h3>Ground-truth samples</h3>
<table>{_rows(sample_rows)}</table>

{_area_section(summary)}
{_gltf_section(summary)}
{_npr_section(summary)}
<h2>White furnace</h2>
<p class="note">Directional albedo E(mu) with F = 1 of single-scattering specular lobes, by quadrature (the energy
lost to multiple scattering is 1 - E), on {fo["mu"]} values of mu = n.v &times; {fo["roughness"]} roughness values.
Monte Carlo check: {html.escape(str(fo["monte_carlo"]))}; the table gives, per lobe, the fraction of cells where
the Monte Carlo estimate lies within 3 of its standard errors of the quadrature (about 99.7% for an unbiased
estimator with honest error bars) and the largest |MC - quadrature|.
<a href="furnace/furnace.csv">CSV</a>, <a href="furnace/furnace.json">JSON</a>,
<a href="furnace/furnace.png">all lobes in one figure</a>.</p>
{furnace_figs}
<table><tr><th>lobe</th><th>min E</th><th>max E</th><th>max energy loss</th>
<th>MC within 3 std. errors</th><th>max |MC - quadrature|</th></tr>
{furnace_rows}
</table>

<h2>DFG lookup table</h2>
<figure><img src="lut.png" alt="DFG lookup table plot">
<figcaption>DFG1 and DFG2 (texel centres; row 0 = smooth)</figcaption></figure>

<h2>Bake</h2>
<p class="note">Every cube map as a horizontal cross (+Y above, -X +Z +X -Z across, -Y below), tone-mapped with one
exposure. Files in <a href="bake/">bake/</a>; <a href="bake/preview.png">bake/preview.png</a> has the same crosses
in one strip.</p>
<h3>Prefiltered specular chain (GGX): level m of {levels} has roughness r = m / {levels - 1}</h3>
<div class="crosses">
{crosses}
</div>
<h3>Irradiance (diffuse)</h3>
<div class="crosses">
<figure><img src="{html.escape(irradiance)}" alt="irradiance cube map">
<figcaption><b>irradiance E(n) / &pi;</b><br>{bake["irradiance_size"]}&sup2; texels per face</figcaption></figure>
</div>
<p class="note">The manifest:</p>
<pre>{html.escape(json.dumps(manifest, indent=2, default=str))}</pre>

<h2>Timings</h2>
<table>{_rows(timing_rows)}</table>
<h3>Real-time render stages</h3>
<table>{_rows(rt_rows)}</table>
</body>
</html>
"""
