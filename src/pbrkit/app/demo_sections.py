"""The sections of ``pbrkit demo`` that its warm-up (:mod:`pbrkit.app.warmup`) also
runs to compile their kernels: the non-photorealistic gallery (:func:`npr_gallery`),
the area-light comparison (:func:`area_light_comparison`) and the glTF extensions
comparison (:func:`gltf_extensions_comparison`), with the constants both use
(:data:`DEMO_LEVELS`, :data:`FURNACE_LOBES`) and the helpers that write a
section's images and measure its errors.  :mod:`pbrkit.app.demo` assembles them
into the page; this module imports neither it nor the warm-up."""

from __future__ import annotations

import numpy as np

from ..core.color import linear_to_srgb
from ..io.figures import error_scale, plot_error_map
from ..io.png import write_png

__all__ = ["FURNACE_LOBES", "DEMO_LEVELS", "ERROR_QUANTITY", "NPR_STYLES", "NPR_KEY_LIGHT", "NPR_MODEL_CAMERA",
           "GLTF_EXTENSION_MATERIALS", "write_tonemapped_png", "npr_model_styles", "npr_gallery",
           "area_light_comparison", "whole_image_errors", "write_comparison", "gltf_extensions_scene",
           "sphere_discs", "gltf_extensions_comparison"]

#: The furnace lobes the demo plots (the models, and GGX with three masking terms).
FURNACE_LOBES = ("ggx/height-correlated", "ggx/separable", "ggx/schlick-ggx", "ue4", "filament", "urp_mobile")
#: Specular levels of the demo's bake: level m has roughness m / (M - 1), steps of 0.2.
DEMO_LEVELS = 6
#: What the error map shows (its colour bar's label).
ERROR_QUANTITY = "relative luminance error |Y_rt - Y_ref| / Y_ref"
_ERROR_LABEL = r"relative luminance error $|Y_\mathrm{rt} - Y_\mathrm{ref}|\,/\,Y_\mathrm{ref}$"


def write_tonemapped_png(path, linear, tonemap_name="aces", exposure=0.0):
    """``linear`` (HDR linear RGB) tone-mapped (:func:`pbrkit.core.color.tonemap`), sRGB-encoded
    and written as an 8-bit PNG."""
    from ..core.color import tonemap

    write_png(path, linear_to_srgb(tonemap(linear, tonemap_name, exposure)), srgb=False)


#: The styles of the demo's NPR section (pbrkit.npr.style.STYLE_PRESETS) and the key light they add.
NPR_STYLES = ("toon", "mtoon", "hatching")
NPR_KEY_LIGHT = {"type": "directional", "direction": (-0.45, -0.5, -0.74), "intensity": 3.0}


#: The demo model's camera (:mod:`pbrkit.app.demo_model`: the knot on its box).
NPR_MODEL_CAMERA = {"position": (0.0, 4.2, 7.5), "look_at": (0.0, 0.9, 0.0), "fov": 40.0}


def npr_model_styles():
    """The styles the demo model is shown in: the presets with the outlines that
    need a mesh (geometric edges, the inverted hull) and texture-space hatching."""
    from dataclasses import replace

    from ..npr.style import STYLE_PRESETS

    return {"pbr": STYLE_PRESETS["pbr"], "toon": replace(STYLE_PRESETS["toon"], outline="both"),
            "mtoon": replace(STYLE_PRESETS["mtoon"], outline="hull"),
            "hatching": replace(STYLE_PRESETS["hatching"], outline="geometry", hatching_space="texture"),
            "outline": STYLE_PRESETS["outline"]}


def npr_gallery(out, scene, env, baked, size):
    """The sphere grid at size^2 with a key light in each of :data:`NPR_STYLES`
    (:func:`pbrkit.npr.render.render_styled`), written as ``npr_<style>.png``; then
    the demo model (:mod:`pbrkit.app.demo_model`, written as ``model.glb``) under the
    same lights in each of :func:`npr_model_styles`, as ``npr_model_<style>.png``."""
    from dataclasses import replace

    from ..io.gltf_writer import write_glb
    from ..npr.render import render_styled
    from ..npr.style import STYLE_PRESETS
    from ..rendering.geometry import Geometry
    from ..rendering.lights import Light
    from ..rendering.scene import Camera, GltfObject, Scene
    from .demo_model import demo_model_primitives

    lit = replace(scene.with_camera(width=size, height=size), lights=(Light(**NPR_KEY_LIGHT),))
    geometry = Geometry(lit)
    entries = {}
    for name in NPR_STYLES:
        result = render_styled(lit, STYLE_PRESETS[name], geometry, env, bake=baked)
        write_tonemapped_png(out / f"npr_{name}.png", result.image)
        entries[name] = {"file": f"npr_{name}.png", "seconds": result.stats["timings"]["total"],
                         "outline": result.stats["outline"]}
    write_glb(out / "model.glb", demo_model_primitives())
    model = Scene(camera=Camera(width=size, height=size, **NPR_MODEL_CAMERA), environment=scene.environment,
                  objects=(GltfObject(file=str(out / "model.glb")),), lights=lit.lights, source="model.glb")
    geometry = Geometry(model)
    model_entries = {}
    for name, style in npr_model_styles().items():
        result = render_styled(model, style, geometry, env, bake=baked)
        write_tonemapped_png(out / f"npr_model_{name}.png", result.image)
        model_entries[name] = {"file": f"npr_model_{name}.png", "seconds": result.stats["timings"]["total"],
                               "shading": style.shading, "outline": style.outline}
    return {"size": size, "key_light": {k: list(v) if isinstance(v, tuple) else v for k, v in NPR_KEY_LIGHT.items()},
            "styles": entries, "model": {"file": "model.glb", "styles": model_entries}}


def area_light_comparison(out, size, spp, seed, before_reference=None):
    """The built-in ``area`` scene (:func:`pbrkit.rendering.scene.builtin_scene`) at size x
    size / 2 in real time (LTC) and as ground truth with occlusion off (like for
    like), its images and error map written into ``out``; returns its summary.
    ``before_reference()``, if given, is called between the two renders (the demo's
    warm-up waits there for the ground truth's kernel)."""
    from ..rendering.environment import EnvironmentLight
    from ..rendering.geometry import Geometry
    from ..rendering.realtime import render_realtime
    from ..rendering.reference import render_reference
    from ..rendering.scene import builtin_scene

    scene = builtin_scene("area", size, max(8, size // 2))
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    rt = render_realtime(scene, geometry, env, bake_size=32)
    if before_reference is not None:  # the demo's warm-up: the ground truth's kernel is compiled elsewhere
        before_reference()
    ref = render_reference(scene, spp=spp, seed=seed, geometry=geometry, env=env, occlusion=False)
    mask, metrics, rel, valid, (scale, p99, peak) = whole_image_errors(rt, ref)
    write_comparison(out, "area_", rt, ref, rel, valid, scale)
    light = scene.area_lights[0]
    return {"image": {"width": scene.camera.width, "height": scene.camera.height},
            "light": {"type": light.type, "width": light.width, "height": light.height,
                      "radiance": list(light.radiance)},
            "spp": int(spp), "errors": metrics,
            "error_map": {"scale_max": scale, "percentile_99": p99, "max": peak},
            "timings": {"realtime": rt.stats["timings"]["total"], "reference": ref.stats["timings"]["total"]}}


def whole_image_errors(rt, ref):
    """A section's comparison of its real-time and ground-truth renders over the pixels both
    cover: (mask, the errors of :func:`pbrkit.rendering.compare.compare_images` with HDR-FLIP,
    the relative error map, its valid pixels, the map's (scale, 99th percentile, max))."""
    from ..rendering.compare import compare_images, relative_error_pixels

    mask = rt.mask & ref.mask
    metrics = compare_images(rt.image, ref.image, mask, ref.stderr, flip=True)
    rel = metrics.pop("relative_error_map")
    metrics.pop("floored_error_map")
    valid = relative_error_pixels(ref.image, mask)
    return mask, metrics, rel, valid, error_scale(rel[valid])


def write_comparison(out, prefix, rt, ref, rel, valid, scale):
    """``<prefix>realtime.png``, ``<prefix>reference.png`` and ``<prefix>error.png``."""
    write_tonemapped_png(out / f"{prefix}realtime.png", rt.image)
    write_tonemapped_png(out / f"{prefix}reference.png", ref.image)
    plot_error_map(out / f"{prefix}error.png", rel, valid, scale, _ERROR_LABEL)


#: The demo's glTF material extensions section: (name, what it shows, the material's keys)
#: of one sphere per KHR_materials extension of the ``gltf`` model, the core model first as
#: the reference, and sheen, clear coat, specular and ior together last; a 5 x 2 grid, row by row.
#: (No solid volume: the section's ground truth runs without occlusion, like the real time,
#: and a path that refracts into a sphere must meet it again to leave; bench/transmission_rt.py
#: measures KHR_materials_volume.)
GLTF_EXTENSION_MATERIALS = (
    ("core", "core glTF 2.0 (Appendix B), no extension: the clear-coat sphere's red metal-ish base, roughness 0.5, "
             "without its coat; the reference the others differ from",
     dict(base_color=(0.6, 0.06, 0.05), metallic=0.5, roughness=0.5)),
    ("sheen", "KHR_materials_sheen: velvet, a dark base (roughness 0.8) under a white Charlie sheen of roughness "
              "0.5, which brightens towards the silhouette",
     dict(base_color=(0.05, 0.03, 0.12), metallic=0.0, roughness=0.8, sheen_color=(1.0, 1.0, 1.0),
          sheen_roughness=0.5)),
    ("clearcoat", "KHR_materials_clearcoat: car paint, the core sphere under a clear coat of weight 1 and roughness "
                  "0.05: a sharp reflection over the base's blurred one",
     dict(base_color=(0.6, 0.06, 0.05), metallic=0.5, roughness=0.5, clearcoat=1.0, clearcoat_roughness=0.05)),
    ("specular", "KHR_materials_specular: specular 0.3 and an orange specular colour on a blue dielectric: "
                 "weaker, tinted reflections (F0 and F90 scaled by 0.3)",
     dict(base_color=(0.1, 0.25, 0.5), metallic=0.0, roughness=0.3, specular=0.3, specular_color=(1.0, 0.6, 0.2))),
    ("ior", "KHR_materials_ior: ior 2.4, a diamond-like dielectric over a near-black base: F0 0.17 instead of the "
            "core's 0.04",
     dict(base_color=(0.02, 0.02, 0.02), metallic=0.0, roughness=0.1, ior=2.4)),
    ("iridescence", "KHR_materials_iridescence: a thin film of IOR 1.3 and 400 nm over a near-black dielectric: "
                    "interference colours that change with the angle",
     dict(base_color=(0.02, 0.02, 0.02), metallic=0.0, roughness=0.2, iridescence=1.0, iridescence_ior=1.3,
          iridescence_thickness_maximum=400.0)),
    ("transmission", "KHR_materials_transmission: a thin-walled light-blue dielectric that lets 90 % of what "
                     "enters through (roughness 0.15): the sky behind it, slightly blurred",
     dict(base_color=(0.8, 0.9, 1.0), metallic=0.0, roughness=0.15, transmission=0.9)),
    ("anisotropy", "KHR_materials_anisotropy: brushed metal, a grey metal of roughness 0.3 with strength 0.8 "
                   "along the parallels: the reflections stretched around the sphere",
     dict(base_color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.3, anisotropy_strength=0.8)),
    ("combined", "the first four together: a blue dielectric of ior 1.8 with specular 0.8 and a warm specular colour, "
                 "a grey sheen, under a clear coat of weight 0.8 and roughness 0.1",
     dict(base_color=(0.1, 0.25, 0.5), metallic=0.0, roughness=0.4, sheen_color=(0.6, 0.6, 0.6),
          sheen_roughness=0.3, clearcoat=0.8, clearcoat_roughness=0.1, specular=0.8,
          specular_color=(1.0, 0.8, 0.6), ior=1.8)),
)


def gltf_extensions_scene(width, environment):
    """The scene of the demo's glTF extensions section: the spheres of
    :data:`GLTF_EXTENSION_MATERIALS` (model ``gltf``) in a 5 x 2 grid, ``width`` x
    (2 ``width`` / 5) pixels, far camera (as the sphere grid's), lit by ``environment``
    (an :class:`pbrkit.rendering.scene.EnvironmentSpec`)."""
    import math

    from ..rendering.scene import Camera, MaterialSpec, Scene, Sphere

    cols, rows, spacing, distance = 5, 2, 2.4, 60.0
    materials = {"default": MaterialSpec()}
    objects = []
    for k, (name, _, keys) in enumerate(GLTF_EXTENSION_MATERIALS):
        materials[name] = MaterialSpec(name=name, model="gltf", **keys)
        r, c = divmod(k, cols)
        objects.append(Sphere(center=((c - (cols - 1) / 2) * spacing, ((rows - 1) / 2 - r) * spacing, 0.0),
                              radius=1.0, material=name))
    height = max(8, 2 * width // 5)
    half = ((rows - 1) / 2 * spacing + 1.0) * 1.06
    camera = Camera(position=(0.0, 0.0, distance), look_at=(0.0, 0.0, 0.0),
                    fov=2.0 * math.degrees(math.atan(half / (distance - 1.0))), width=width, height=height)
    return Scene(camera=camera, environment=environment, materials=materials, objects=tuple(objects),
                 source="gltf-extensions")


def sphere_discs(scene, fraction=1.0):
    """Per sphere of ``scene``: its centre (row, column) and radius in pixels times ``fraction``."""
    cam = scene.camera
    scale = cam.height / (2.0 * np.tan(np.radians(cam.fov) / 2.0))
    out = []
    for sphere in scene.objects:
        r, c = cam.project(np.array([sphere.center]))
        distance = np.linalg.norm(np.subtract(sphere.center, cam.position))
        out.append((float(r[0]), float(c[0]), fraction * sphere.radius / distance * scale))
    return out


def gltf_extensions_comparison(out, environment, env, baked, size, spp, seed):
    """The glTF extensions section: :func:`gltf_extensions_scene` at size / 2 wide, in
    real time from the demo's bake and as ground truth (``spp``, no occlusion: like for
    like), the whole images and error map written into ``out``, and each sphere cut out
    of both (``gltf_extensions/<name>_realtime.png``, ``..._reference.png``) with its own
    errors over the sphere's inner 80% (radius); returns its summary."""
    from ..core.color import luminance
    from ..rendering.compare import compare_images, relative_error_pixels
    from ..rendering.geometry import Geometry
    from ..rendering.realtime import render_realtime
    from ..rendering.reference import render_reference

    scene = gltf_extensions_scene(max(24, size // 2), environment)
    geometry = Geometry(scene)
    rt = render_realtime(scene, geometry, env, bake=baked)
    ref = render_reference(scene, spp=spp, seed=seed, geometry=geometry, env=env, occlusion=False)
    mask, metrics, rel, valid, (scale, p99, peak) = whole_image_errors(rt, ref)
    write_comparison(out, "gltf_", rt, ref, rel, valid, scale)
    (out / "gltf_extensions").mkdir(exist_ok=True)
    cam = scene.camera
    rows, cols = np.mgrid[0:cam.height, 0:cam.width] + 0.5
    y_rt, y_ref = luminance(rt.image), luminance(ref.image)
    materials = []
    for (name, shows, keys), (r, c, radius) in zip(GLTF_EXTENSION_MATERIALS, sphere_discs(scene)):
        inside = (rows - r) ** 2 + (cols - c) ** 2 < (0.8 * radius) ** 2
        e = compare_images(rt.image, ref.image, mask & inside, ref.stderr, flip=False)
        e.pop("relative_error_map")
        e.pop("floored_error_map")
        ok = relative_error_pixels(ref.image, mask & inside)
        e["signed_relative_error"] = (float(np.mean((y_rt[ok] - y_ref[ok]) / y_ref[ok])) if ok.any()
                                      else float("nan"))
        r0, r1 = max(0, int(np.floor(r - 1.08 * radius))), min(cam.height, int(np.ceil(r + 1.08 * radius)))
        c0, c1 = max(0, int(np.floor(c - 1.08 * radius))), min(cam.width, int(np.ceil(c + 1.08 * radius)))
        files = {}
        for mode, image in (("realtime", rt.image), ("reference", ref.image)):
            files[mode] = f"gltf_extensions/{name}_{mode}.png"
            write_tonemapped_png(out / files[mode], image[r0:r1, c0:c1])
        materials.append({"name": name, "shows": shows,
                          "material": {k: list(v) if isinstance(v, tuple) else v for k, v in keys.items()},
                          "files": files, "errors": e})
    return {"image": {"width": cam.width, "height": cam.height}, "spp": int(spp), "model": "gltf",
            "materials": materials, "errors": metrics,
            "error_map": {"scale_max": scale, "percentile_99": p99, "max": peak},
            "timings": {"realtime": rt.stats["timings"]["total"], "reference": ref.stats["timings"]["total"]}}
