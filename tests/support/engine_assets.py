"""Shared test helper: the test assets per glTF material extension of
tests/engines/test_engine_khr_extensions.py (its docstring describes them: grids of UV
spheres, one material per sphere, laid out like the Khronos sample models), written as
``.glb`` by :mod:`pbrkit.io.gltf_writer` with a pbrkit scene file each, their images
(the Khronos glTF Sample Viewer's through the engine pages, pbrkit's through ``pbrkit
render``), the analytic sphere hits under pbrkit's camera, and per-sphere measures.
tests/engines/test_engine_three_khr_extensions.py and bench/khr_extensions.py,
bench/anisotropy_rt.py use them too."""

from __future__ import annotations

import base64
import json
import math
from pathlib import Path

import numpy as np
from engine_compare import gamma22_to_srgb8, run_cli
from engine_pages import run_page

from pbrkit.io.gltf_writer import GltfCamera, GltfPrimitive, write_glb

INTENSITY = 0.25
CELL = 48  # pixels per sphere cell
DISTANCE = 6.0  # the camera's distance to the grid's plane
RADIUS = 0.42
RINGS, SEGMENTS = 32, 64
ENGINE_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--engine", "khronos"]
PBRKIT_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--diffuse", "cube", "--energy-compensation"]


def _material(base, roughness, extensions, metallic=0.0, emissive=(0.0, 0.0, 0.0), normal_texture=None):
    return {"base_color": base, "metallic": metallic, "roughness": roughness, "extensions": extensions,
            "emissive": emissive, "normal_texture": normal_texture}


def _clearcoat():
    red = (0.8, 0.05, 0.05)
    grid = [[_material(red, 0.5, {"KHR_materials_clearcoat": {"clearcoatFactor": c, "clearcoatRoughnessFactor": cr}})
             for c in (0.0, 0.5, 1.0)] for cr in (0.0, 0.3, 0.7)]
    # the coat's F0 follows the material's ior in the viewer (getClearCoatInfo)
    grid.append([_material(red, 0.5, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0,
                                                                  "clearcoatRoughnessFactor": 0.0},
                                      "KHR_materials_ior": {"ior": ior}}) for ior in (1.0, 2.0, 3.0)])
    return grid


#: The bump texture's size (columns along u = phi / 2 pi, rows along v = theta / pi) and
#: its egg-crate pattern: periods across and down, the largest slope of the height field
BUMP_SIZE = (64, 32)
BUMP_PERIODS = (8, 4)
BUMP_SLOPE = 0.6
BUMP_SCALES = (0.0, 0.5, 1.0)


def bump_texture():
    """The clearcoat_normal asset's tangent-space normal texture, (32, 64, 3) uint8 (row 0
    the image's top, v = 0): the normals of the egg-crate height field h = sin(2 pi 8 u)
    sin(2 pi 4 v) / k, slope at most :data:`BUMP_SLOPE` (31 degrees), at the texel centres,
    n = normalize(-dh/dx, -dh/dy, 1) with x along +u (the TANGENT, eastwards) and y along
    -v (the bitangent, north: glTF's green channel points up the image), each channel
    round(255 (n / 2 + 1 / 2)).  Period 8 texels both ways (5.6 degrees a texel): 4 bumps
    across a sphere's visible half, about 10 pixels each."""
    w, h = BUMP_SIZE
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    a, b = np.meshgrid(2.0 * np.pi * BUMP_PERIODS[0] * u, 2.0 * np.pi * BUMP_PERIODS[1] * v, indexing="xy")
    dx = BUMP_SLOPE * np.cos(a) * np.sin(b)  # dh/du, scaled
    dy = -BUMP_SLOPE * np.sin(a) * np.cos(b)  # dh/d(-v)
    n = np.stack([-dx, -dy, np.ones_like(dx)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.rint(255.0 * (0.5 * n + 0.5)).astype(np.uint8)


def _clearcoat_normal():
    # ClearCoatTest's "clearcoat normal" row: clearcoatNormalTexture (texture 0) at scale 0, 0.5, 1
    # over the red base, coat roughness 0 and 0.3; then the base's normalTexture (the same texture)
    # under a smooth coat (no clearcoatNormalTexture: the coat keeps the unmapped normal), under a
    # coat with both, and without a coat (clearcoat 0)
    red = (0.8, 0.05, 0.05)

    def coat(c, cr, scale=None):
        ext = {"clearcoatFactor": c, "clearcoatRoughnessFactor": cr}
        if scale is not None:
            ext["clearcoatNormalTexture"] = {"index": 0, "scale": scale}
        return {"KHR_materials_clearcoat": ext}
    rows = [[_material(red, 0.5, coat(1.0, cr, scale)) for scale in BUMP_SCALES] for cr in (0.0, 0.3)]
    base_map = {"index": 0, "scale": 1.0}
    rows.append([_material(red, 0.5, coat(1.0, 0.0), normal_texture=base_map),
                 _material(red, 0.5, coat(1.0, 0.0, 1.0), normal_texture=base_map),
                 _material(red, 0.5, coat(0.0, 0.0), normal_texture=base_map)])
    return rows


def _coated_emission():
    return [[_material((0.02, 0.02, 0.02), 0.5, {"KHR_materials_clearcoat": {"clearcoatFactor": c,
                                                                             "clearcoatRoughnessFactor": 0.0}},
                       emissive=(0.6, 0.3, 0.1)) for c in (0.0, 0.5, 1.0)]]


def _specular():
    base = (0.1, 0.1, 0.1)
    first = [_material(base, 0.3, {"KHR_materials_specular": {"specularFactor": s,
                                                              "specularColorFactor": [1.0, 1.0, 1.0]}})
             for s in (0.0, 0.5, 1.0)]
    second = [_material(base, 0.3, {"KHR_materials_specular": {"specularFactor": 1.0, "specularColorFactor": c}})
              for c in ([1.0, 0.3, 0.3], [0.3, 0.6, 1.0], [2.5, 2.5, 2.5])]
    # with KHR_materials_ior: F0(ior) x colour, clamped to 1 (ior 2.5 x 10)
    third = [_material(base, 0.3, {"KHR_materials_specular": {"specularFactor": s, "specularColorFactor": c},
                                   "KHR_materials_ior": {"ior": ior}})
             for s, c, ior in ((1.0, [1.0, 1.0, 1.0], 1.0), (0.5, [0.3, 0.6, 1.0], 2.0), (1.0, [10.0, 10.0, 10.0], 2.5))]
    return [first, second, third]


def _ior():
    # 0: the README's special value (F0 = 1, as ((0 - 1) / (0 + 1))^2 gives)
    return [[_material((0.02, 0.02, 0.02), r, {"KHR_materials_ior": {"ior": ior}})
             for ior in (1.0, 1.5, 2.0, 2.5, 0.0)] for r in (0.2, 0.5)]


def _sheen():
    return [[_material((0.02, 0.02, 0.08), 0.5, {"KHR_materials_sheen": {"sheenColorFactor": c,
                                                                         "sheenRoughnessFactor": sr}})
             for c in ([1.0, 1.0, 1.0], [1.0, 0.3, 0.5], [0.2, 0.5, 1.0])] for sr in (0.3, 0.8)]


def _iridescence():
    # IridescenceTest-like: film thickness across, film IOR down, over a dark dielectric and a gold metal
    def film(k, ior, thickness):
        return {"KHR_materials_iridescence": {"iridescenceFactor": k, "iridescenceIor": ior,
                                              "iridescenceThicknessMaximum": thickness}}
    rows = [[_material((0.05, 0.05, 0.05), 0.2, film(1.0, ior, d)) for d in (150.0, 350.0, 600.0)]
            for ior in (1.3, 1.8)]
    rows.append([_material((1.0, 0.78, 0.34), 0.2, film(k, 1.3, 400.0), metallic=1.0) for k in (0.0, 0.5, 1.0)])
    return rows


ANISOTROPY_ROUGHNESS = (0.0, 0.25, 0.5, 1.0)
ANISOTROPY_STRENGTH = (0.0, 0.5, 1.0)
ANISOTROPY_ROTATION = (0.0, math.pi / 4, math.pi / 2, 3 * math.pi / 4)


def _anisotropy():
    # AnisotropyStrengthTest-like: base roughness across x anisotropyStrength down, and a 4th
    # row turning the direction (anisotropyRotation) at strength 1, roughness 0.25, over a
    # light grey metal (the environment's reflection alone); the spheres carry TANGENT
    grey = (0.8, 0.8, 0.8)

    def aniso(s, rotation=0.0):
        return {"KHR_materials_anisotropy": {"anisotropyStrength": s, "anisotropyRotation": rotation}}
    rows = [[_material(grey, r, aniso(s), metallic=1.0) for r in ANISOTROPY_ROUGHNESS] for s in ANISOTROPY_STRENGTH]
    rows.append([_material(grey, 0.25, aniso(1.0, rot), metallic=1.0) for rot in ANISOTROPY_ROTATION])
    return rows


def _transmission():
    # TransmissionTest-like thin walls (no KHR_materials_volume): transmission 0, 0.5, 1 across,
    # roughness 0 and 0.3 down; then AttenuationTest-like volumes (transmission 1, roughness 0):
    # thickness 0.3 clear, 0.3 with attenuation, 0.8 with attenuation
    light = (0.9, 0.9, 0.9)
    rows = [[_material(light, r, {"KHR_materials_transmission": {"transmissionFactor": t}}) for t in (0.0, 0.5, 1.0)]
            for r in (0.0, 0.3)]
    volumes = ({"thicknessFactor": 0.3},
               {"thicknessFactor": 0.3, "attenuationDistance": 0.3, "attenuationColor": [0.9, 0.5, 0.3]},
               {"thicknessFactor": 0.8, "attenuationDistance": 0.5, "attenuationColor": [0.3, 0.6, 0.9]})
    rows.append([_material(light, 0.0, {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                         "KHR_materials_volume": v}) for v in volumes])
    return rows


#: name -> (extension, rows of materials: base colour, metallic, roughness, glTF extensions)
ASSETS = {"clearcoat": ("KHR_materials_clearcoat", _clearcoat()), "specular": ("KHR_materials_specular", _specular()),
          "ior": ("KHR_materials_ior", _ior()), "sheen": ("KHR_materials_sheen", _sheen()),
          "coated_emission": ("KHR_materials_clearcoat", _coated_emission()),
          "iridescence": ("KHR_materials_iridescence", _iridescence()),
          "anisotropy": ("KHR_materials_anisotropy", _anisotropy()),
          "transmission": ("KHR_materials_transmission", _transmission()),
          "clearcoat_normal": ("KHR_materials_clearcoat", _clearcoat_normal())}
#: The assets whose spheres are written with TANGENT (:func:`_unit_sphere_tangents`); the
#: others' files are as before, without it.
TANGENT_ASSETS = ("anisotropy", "clearcoat_normal")
#: The assets with textures (name -> the images, texture k the k-th, each with LINEAR
#: magnification and minification and REPEAT: no mip maps, as pbrkit samples textures),
#: whose spheres are written with TEXCOORD_0 (:func:`_unit_sphere_uv`)
TEXTURE_ASSETS = {"clearcoat_normal": (bump_texture(),)}
#: The assets the viewer renders with its environment background (the page's background=1),
#: which its transmission framebuffer holds: the others' pages are as before, on black.
BACKGROUND_ASSETS = ("transmission",)


def asset_size(name):
    """(width, height) of the asset's image: CELL pixels a sphere."""
    rows = ASSETS[name][1]
    return CELL * len(rows[0]), CELL * len(rows)


def asset_spheres(name):
    """The asset's spheres, row 0 at the top: centre, radius, material."""
    rows = ASSETS[name][1]
    n_rows, n_cols = len(rows), len(rows[0])
    return [{"center": [j - (n_cols - 1) / 2.0, (n_rows - 1) / 2.0 - i, 0.0], "radius": RADIUS, "material": m}
            for i, row in enumerate(rows) for j, m in enumerate(row)]


def asset_camera(name):
    """pbrkit's camera of the asset: at (0, 0, DISTANCE) looking at the origin, the
    vertical field of view spanning the rows (fov in degrees)."""
    w, h = asset_size(name)
    fov = math.degrees(2.0 * math.atan(0.5 * h / CELL / DISTANCE))
    return {"position": [0.0, 0.0, DISTANCE], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": fov,
            "width": w, "height": h}


def _unit_sphere():
    theta = np.linspace(0.0, np.pi, RINGS + 1)
    phi = np.linspace(0.0, 2 * np.pi, SEGMENTS + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], axis=-1).reshape(-1, 3)
    tris = []
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a, b = i * (SEGMENTS + 1) + j, (i + 1) * (SEGMENTS + 1) + j
            if i > 0:  # no degenerate triangles at the poles
                tris.append((a, b, a + 1))
            if i < RINGS - 1:
                tris.append((a + 1, b, b + 1))
    return pos, np.asarray(tris, np.int64)


def _unit_sphere_tangents():
    """glTF TANGENTs of :func:`_unit_sphere`'s vertices: the direction of dp/dphi,
    T = (cos phi, 0, -sin phi) (along the parallels, eastwards; defined at the poles too,
    one per column), w = +1: B = N x T = -dp/dtheta points north, towards +Y, as glTF's
    tangent space has B along the texture's up (decreasing v) for a (u, v) = (phi / 2 pi,
    theta / pi) parametrisation.  The viewer and pbrkit read the same attribute."""
    theta = np.linspace(0.0, np.pi, RINGS + 1)
    phi = np.linspace(0.0, 2 * np.pi, SEGMENTS + 1)
    _, p = np.meshgrid(theta, phi, indexing="ij")
    p = p.reshape(-1)
    return np.stack([np.cos(p), np.zeros_like(p), -np.sin(p), np.ones_like(p)], axis=-1)


def _unit_sphere_uv():
    """glTF TEXCOORD_0 of :func:`_unit_sphere`'s vertices: (u, v) = (phi / 2 pi, theta / pi),
    u growing along :func:`_unit_sphere_tangents`' T (eastwards), v from the north pole (the
    image's top) down; the seam (u 0 and 1, its own vertices) faces the camera (phi = 0,
    +Z), where a texture periodic in u (:func:`bump_texture`) joins without a break."""
    theta = np.linspace(0.0, np.pi, RINGS + 1)
    phi = np.linspace(0.0, 2 * np.pi, SEGMENTS + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    return np.stack([p / (2 * np.pi), t / np.pi], axis=-1).reshape(-1, 2)


def write_asset(name, folder):
    """The asset as ``folder/<name>.glb`` (:mod:`pbrkit.io.gltf_writer`): one primitive
    and material per sphere (world-space positions, unit normals, TANGENT for the
    :data:`TANGENT_ASSETS`, TEXCOORD_0 and the textures for the :data:`TEXTURE_ASSETS`),
    the camera."""
    from pbrkit.io.gltf_writer import GltfTexture

    unit, tris = _unit_sphere()
    tangents = _unit_sphere_tangents() if name in TANGENT_ASSETS else None
    textures = [GltfTexture(image) for image in TEXTURE_ASSETS.get(name, ())]
    uv = _unit_sphere_uv() if textures else None
    prims = []
    for k, s in enumerate(asset_spheres(name)):
        m = s["material"]
        prims.append(GltfPrimitive(np.asarray(s["center"]) + s["radius"] * unit, unit, tris, texcoords=uv,
                                   base_color=m["base_color"], metallic=m["metallic"], roughness=m["roughness"],
                                   name=f"{name}{k}", extensions=m["extensions"], emissive=m["emissive"],
                                   tangents=tangents, normal_texture=m.get("normal_texture")))
    cam = asset_camera(name)
    camera = GltfCamera(yfov=math.radians(cam["fov"]), aspect_ratio=cam["width"] / cam["height"], znear=0.1,
                        zfar=100.0, translation=tuple(cam["position"]))
    path = Path(folder) / f"{name}.glb"
    write_glb(path, prims, camera=camera, textures=textures)
    return path


def write_asset_scene(name, folder, bake_dir):
    """A pbrkit scene file placing ``<name>.glb`` under the asset's camera and the bake."""
    glb = write_asset(name, folder)
    scene = {"camera": asset_camera(name), "environment": {"bake": str(Path(bake_dir).resolve()),
                                                           "intensity": INTENSITY},
             "objects": [{"type": "gltf", "file": glb.name}]}
    path = Path(folder) / f"{name}.json"
    path.write_text(json.dumps(scene, indent=1))
    return path


def pbrkit_render(scene, options, out):
    """``pbrkit render SCENE -o OUT OPTIONS`` as linear (H, W, 3) float64."""
    from pbrkit.io.exr import read_exr

    run_cli(["render", scene, "-o", out, *options, "-q"])
    return read_exr(out)[..., :3].astype(np.float64)


def viewer_image(name, bake_dir):
    """The Sample Viewer's render of ``bake_dir/<name>.glb`` (written here), 8-bit sRGB."""
    write_asset(name, bake_dir)
    w, h = asset_size(name)
    query = "&".join(["folder=khronos/", f"gltf={name}.glb", f"width={w}", f"height={h}", f"intensity={INTENSITY}"]
                     + (["background=1"] if name in BACKGROUND_ASSETS else []))
    result = run_page("khronos_render.html", data=bake_dir, query=query, timeout=120)["result"]
    assert (result["width"], result["height"]) == (w, h) and result["mipCount"] == 5
    rgba = np.frombuffer(base64.b64decode(result["rgba8"]), np.uint8).reshape(h, w, 4)[::-1]
    return gamma22_to_srgb8(np.ascontiguousarray(rgba[..., :3]))


def asset_hits(name):
    """pbrkit's camera of the asset and, per pixel centre, the index of the analytic
    sphere hit (-1: none), its unit normal and the ray's direction."""
    from pbrkit.rendering.scene import Camera

    cam = asset_camera(name)
    camera = Camera(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in cam.items()})
    h, w = cam["height"], cam["width"]
    d = camera.ray_directions(*np.meshgrid(np.arange(h) + 0.5, np.arange(w) + 0.5, indexing="ij"))
    origin = np.asarray(cam["position"], np.float64)
    index, nearest, normal = np.full((h, w), -1), np.full((h, w), np.inf), np.zeros((h, w, 3))
    for i, s in enumerate(asset_spheres(name)):
        oc = origin - np.asarray(s["center"])
        b = d @ oc
        disc = b * b - (oc @ oc - s["radius"] ** 2)
        t = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
        closer = t < nearest
        nearest[closer], index[closer] = t[closer], i
        normal[closer] = ((origin + t[..., None] * d - s["center"]) / s["radius"])[closer]
    return camera, index, normal, d


def asset_index(name):
    """Per pixel the index of the sphere its centre ray hits (-1: none), from the
    analytic spheres under pbrkit's camera (:func:`asset_hits`)."""
    return asset_hits(name)[1]


def charlie_baked(bake_dir):
    """Whether the Khronos target's bake has a Charlie chain (a ``charlie*`` file)."""
    return any("charlie" in p.name for p in (Path(bake_dir) / "khronos").iterdir())


def per_sphere(a, b, index, mask):
    """Mean |grey| of each sphere, row-major."""
    grey = np.abs(a.astype(np.float64).mean(-1) - b.astype(np.float64).mean(-1))
    return [round(float(grey[mask & (index == i)].mean()), 2) for i in range(index.max() + 1)]


def bumpiness(image, index):
    """Per sphere the mean |grey - grey blurred (Gaussian, sigma 1 pixel)| in 8-bit levels
    over its pixels 4 or more pixels inside its silhouette (the background taken as
    black): the detail a normal texture adds to the reflections, row-major."""
    from scipy.ndimage import binary_erosion, gaussian_filter

    grey = np.where(index >= 0, image.astype(np.float64).mean(-1), 0.0)
    detail = np.abs(grey - gaussian_filter(grey, 1.0))
    return [round(float(detail[binary_erosion(index == i, iterations=4)].mean()), 2)
            for i in range(index.max() + 1)]
