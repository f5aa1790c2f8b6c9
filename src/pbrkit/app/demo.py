"""``pbrkit demo``: bake the bundled environment, render the sphere grid in real
time and as Monte Carlo ground truth, and write one self-contained web page
(``index.html``) with every image, the numbers and the bake's manifest.

The page uses relative links only and no script, so it opens from the file
system without a server.  The ground truth of the demo is rendered without
occlusion between the spheres (``render_reference(..., occlusion=False)``):
each sphere sees the whole environment, as real-time IBL assumes, so the
error map shows the shading approximations (split sum, diffuse weight, SH)
rather than the missing inter-object shadows; the page says so.
"""

from __future__ import annotations

import html
import json
import time
from pathlib import Path

import numpy as np

from ..core import checks
from ..core.atomic import write_text
from ..core.color import linear_to_srgb
from ..io.exr import write_exr
from ..io.png import write_png
from .figures import new_figure, save_figure

__all__ = ["run_demo", "FURNACE_LOBES"]

#: The furnace lobes the demo plots (the models, and GGX with three masking terms).
FURNACE_LOBES = ("ggx/height-correlated", "ggx/separable", "ggx/schlick-ggx", "ue4", "filament", "urp_mobile")


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


def _png(path, linear, tonemap_name="aces", exposure=0.0):
    from ..core.color import tonemap

    write_png(path, linear_to_srgb(tonemap(linear, tonemap_name, exposure)), srgb=False)


def _fmt(x, digits=4):
    return f"{x:.{digits}g}" if isinstance(x, float) else str(x)


def run_demo(out_dir, size=384, spp=192, bake_size=128, seed=0, furnace=(32, 11, 128), progress=None):
    """Run the demo into ``out_dir`` and return its summary (also in ``summary.json``).

    ``size``: the sphere grid's image side in pixels; ``spp``: ground-truth samples
    per pixel; ``bake_size``: the specular cube's level-0 size; ``furnace``: the
    furnace report's (n.v values, roughness values, Monte Carlo samples).
    ``progress(step)`` is called with the name of each finished step."""
    from .. import __version__
    from ..albedo.furnace import furnace_lobes
    from ..albedo.tables import lookup_table
    from ..ibl.bake import bake as bake_environment
    from ..io.bake_files import write_bake
    from ..io.environment import load_environment
    from ..render.compare import compare_images, error_heatmap
    from ..render.environment import EnvironmentLight
    from ..render.geometry import Geometry
    from ..render.realtime import render_realtime
    from ..render.reference import render_reference
    from ..render.scene import EnvironmentSpec, builtin_scene, bundled_environment
    from .report import furnace_report

    size = checks.integer(size, "size", 16, 4096)
    spp = checks.integer(spp, "spp", 1, 1 << 16)
    bake_size = checks.power_of_two(bake_size, "bake_size", 16, 2048)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    step = progress or (lambda name: None)
    timings = {}
    t_start = time.perf_counter()

    # 1. bake the bundled environment
    env_path = bundled_environment()
    t = time.perf_counter()
    environment = load_environment(env_path)
    baked = bake_environment(environment, size=bake_size)
    write_bake(baked, out / "bake", force=True)
    timings["bake (incl. writing)"] = time.perf_counter() - t
    step("bake")

    # 2. the sphere grid, real time and ground truth
    scene = builtin_scene("spheres", size, size, EnvironmentSpec(file=str(env_path)))
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    env.bake_data = baked
    rt = render_realtime(scene, geometry, env, bake=baked)
    timings["real-time render"] = rt.stats["timings"]["total"]
    step("realtime")
    ref = render_reference(scene, spp=spp, seed=seed, geometry=geometry, env=env, occlusion=False)
    timings["ground-truth render"] = ref.stats["timings"]["total"]
    step("reference")
    t = time.perf_counter()
    metrics = compare_images(rt.image, ref.image, rt.mask & ref.mask, ref.stderr, flip=True)
    heat = error_heatmap(metrics.pop("relative_error_map"), rt.mask & ref.mask)
    per_sphere = _per_sphere_errors(scene, rt, ref)
    timings["errors (incl. FLIP)"] = time.perf_counter() - t
    _png(out / "realtime.png", rt.image)
    _png(out / "reference.png", ref.image)
    write_png(out / "error.png", heat, srgb=False)
    write_exr(out / "realtime.exr", rt.image.astype(np.float32))
    write_exr(out / "reference.exr", ref.image.astype(np.float32))
    write_exr(out / "reference_stderr.exr", ref.stderr.astype(np.float32))
    step("images")

    # 3. furnace and lookup-table plots
    t = time.perf_counter()
    lobes = [name for name in FURNACE_LOBES if name in furnace_lobes()]
    n_mu, n_rough, samples = furnace
    furnace_summary, _ = furnace_report(out / "furnace", n_mu=n_mu, roughness=np.linspace(0.0, 1.0, n_rough),
                                        samples=samples, seed=seed, lobes=lobes)
    timings["furnace report"] = time.perf_counter() - t
    step("furnace")
    t = time.perf_counter()
    table, spec = lookup_table("dfg", 64)
    _lut_plot(out / "lut.png", table, spec)
    timings["lookup table"] = time.perf_counter() - t
    step("lut")

    manifest_path = out / "bake" / "manifest.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.exists() else dict(baked.manifest)
    previews = sorted(p.relative_to(out).as_posix() for p in (out / "bake").rglob("*.png"))
    timings["total"] = time.perf_counter() - t_start
    summary = {
        "pbrkit": __version__,
        "environment": {"file": env_path.name, "licence": "CC0 (Poly Haven), see LICENSE-environment.md"},
        "image": {"width": size, "height": size, "spheres": len(scene.objects)},
        "bake": {"size": bake_size, "levels": len(baked.specular)},
        "realtime": {"diffuse": rt.stats["diffuse"], "timings": rt.stats["timings"]},
        "reference": {k: ref.stats[k] for k in ("spp", "bounces", "seed", "strategy", "occlusion", "paths",
                                                "surface_paths", "paths_per_second", "engine")},
        "errors": metrics,
        "per_sphere_signed_relative_error": per_sphere,
        "furnace": {name: furnace_summary["per_lobe"][name] for name in lobes},
        "timings_s": timings,
    }
    write_text(out / "summary.json", json.dumps(summary, indent=2, default=float) + "\n")
    _copy_licence(out)
    write_text(out / "index.html", _page(summary, manifest, previews))
    step("page")
    return summary


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
    scale = cam.height / (2.0 * np.tan(np.radians(cam.fov) / 2.0))
    for k, sphere in enumerate(scene.objects):
        r, c = cam.project(np.array([sphere.center]))
        distance = np.linalg.norm(np.subtract(sphere.center, cam.position))
        radius = 0.8 * sphere.radius / distance * scale
        inside = ((rows - r[0]) ** 2 + (cols - c[0]) ** 2 < radius * radius) & rt.mask & ref.mask & (y_ref > 0)
        value = float(np.mean((y_rt[inside] - y_ref[inside]) / y_ref[inside])) if inside.any() else float("nan")
        if k % n == 0:
            out.append([])
        out[-1].append(value)
    return out


def _copy_licence(out):
    src = Path(__file__).resolve().parent.parent / "data" / "LICENSE-environment.md"
    if src.exists():
        write_text(out / "LICENSE-environment.md", src.read_text(encoding="utf-8"))


_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; padding: 0 1em; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 1.8em; border-bottom: 1px solid #ddd; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; text-align: center; }
figure img { max-width: 100%; border: 1px solid #ccc; image-rendering: auto; }
.grid img { width: 360px; } figcaption { font-size: 0.85em; color: #555; }
table { border-collapse: collapse; margin: 0.6em 0; } td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; }
th { background: #f3f3f3; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: #f7f7f7; border: 1px solid #ddd; padding: 0.8em; overflow: auto; max-height: 28em; font-size: 0.8em; }
.note { color: #555; font-size: 0.9em; }
"""


def _rows(pairs):
    return "\n".join(f"<tr><th>{html.escape(str(k))}</th><td class=\"num\">{html.escape(_fmt(v))}</td></tr>"
                     for k, v in pairs)


def _page(summary, manifest, previews):
    e = summary["errors"]
    ref = summary["reference"]
    error_rows = [("mean relative error (luminance)", e["mean_relative_error"]),
                  ("max relative error (luminance)", e["max_relative_error"]),
                  ("HDR-FLIP (mean)", e.get("flip", float("nan"))),
                  ("ground-truth noise: mean relative standard error", e.get("mean_relative_stderr", float("nan"))),
                  ("pixels compared", e["pixels"])]
    sample_rows = [("samples per pixel", ref["spp"]), ("paths (all pixels)", ref["paths"]),
                   ("paths on surfaces", ref["surface_paths"]),
                   ("paths per second", float(ref["paths_per_second"])), ("strategy", ref["strategy"]),
                   ("bounces", ref["bounces"]), ("engine", ref["engine"])]
    timing_rows = [(k, float(v)) for k, v in summary["timings_s"].items()]
    rt_rows = [(k, float(v)) for k, v in summary["realtime"]["timings"].items()]
    grid = summary["per_sphere_signed_relative_error"]
    grid_rows = "\n".join(
        "<tr><th>metallic " + f"{i / max(len(grid) - 1, 1):.2f}</th>"
        + "".join(f"<td class=\"num\">{100.0 * v:+.1f}%</td>" for v in row) + "</tr>"
        for i, row in enumerate(grid))
    grid_head = "".join(f"<th>r = {j / max(len(grid[0]) - 1, 1):.2f}</th>" for j in range(len(grid[0])))
    furnace_rows = "\n".join(
        f"<tr><th>{html.escape(name)}</th><td class=\"num\">{s['min_albedo']:.4f}</td>"
        f"<td class=\"num\">{s['max_albedo']:.4f}</td><td class=\"num\">{s['max_energy_loss']:.4f}</td></tr>"
        for name, s in summary["furnace"].items())
    preview_figs = "\n".join(f'<figure><img src="{html.escape(p)}" alt="bake preview {html.escape(p)}">'
                             f"<figcaption>{html.escape(p)}</figcaption></figure>" for p in previews)
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
<p>pbrkit {html.escape(str(summary["pbrkit"]))}. Environment: <code>{html.escape(summary["environment"]["file"])}</code>
(CC0, Poly Haven: <a href="LICENSE-environment.md">licence</a>),
baked at {summary["bake"]["size"]}&sup2; with {summary["bake"]["levels"]} specular levels.</p>

<h2>Sphere grid</h2>
<p class="note">{size["spheres"]} spheres, {size["width"]} &times; {size["height"]} pixels: perceptual roughness
0 to 1 from left to right, metallic 0 to 1 from top to bottom (cook_torrance: GGX, height-correlated Smith,
Schlick Fresnel, Lambert). Real time: split-sum IBL from the bake (prefiltered chain, DFG table, SH diffuse with
k<sub>d</sub> = (1 - F*)(1 - metallic)). Ground truth: Monte Carlo with environment importance sampling, GGX
visible-normal sampling and multiple importance sampling; the spheres do not occlude one another here, so the
error map isolates the shading approximations. Tone mapping: ACES (Hill's fit); the error map shows
|Y<sub>rt</sub> - Y<sub>ref</sub>| / Y<sub>ref</sub> from 0 (black) to 20% or more (yellow), magma colour map.</p>
<div class="grid">
<figure><img src="realtime.png" alt="real-time render">
<figcaption>real time (<a href="realtime.exr">EXR</a>)</figcaption></figure>
<figure><img src="reference.png" alt="ground-truth render"><figcaption>ground truth, {ref["spp"]} spp
(<a href="reference.exr">EXR</a>, <a href="reference_stderr.exr">standard error</a>)</figcaption></figure>
<figure><img src="error.png" alt="relative error heat map"><figcaption>relative error</figcaption></figure>
</div>
<h3>Errors (real time against ground truth)</h3>
<table>{_rows(error_rows)}</table>
<h3>Mean signed error per sphere</h3>
<p class="note">(Y<sub>rt</sub> - Y<sub>ref</sub>) / Y<sub>ref</sub> over the inner 80% of each sphere. The
partly metallic rows are darker in real time: k<sub>d</sub> = (1 - F*)(1 - metallic) takes F* from an F0 that
already mixes in the metal's colour, while the model's Lambert lobe is not weighted by 1 - F.</p>
<table><tr><th></th>{grid_head}</tr>
{grid_rows}
</table>
<h3>Ground-truth samples</h3>
<table>{_rows(sample_rows)}</table>

<h2>White furnace</h2>
<p class="note">Directional albedo E(mu) with F = 1 of single-scattering specular lobes (quadrature; the energy
lost to multiple scattering is 1 - E). <a href="furnace/furnace.csv">CSV</a>,
<a href="furnace/furnace.json">JSON</a>.</p>
<figure><img src="furnace/furnace.png" alt="white furnace plot">
<figcaption>E(mu) per lobe and roughness</figcaption></figure>
<table><tr><th>lobe</th><th>min E</th><th>max E</th><th>max energy loss</th></tr>
{furnace_rows}
</table>

<h2>DFG lookup table</h2>
<figure><img src="lut.png" alt="DFG lookup table plot">
<figcaption>DFG1 and DFG2 (texel centres; row 0 = smooth)</figcaption></figure>

<h2>Bake</h2>
{preview_figs}
<p class="note">Files in <a href="bake/">bake/</a>; the manifest:</p>
<pre>{html.escape(json.dumps(manifest, indent=2, default=str))}</pre>

<h2>Timings</h2>
<table>{_rows(timing_rows)}</table>
<h3>Real-time render stages</h3>
<table>{_rows(rt_rows)}</table>
</body>
</html>
"""
