"""The Khronos glTF Sample Viewer (KhronosGroup/glTF-Sample-Renderer, npm
``@khronosgroup/gltf-viewer``; its IBL from KhronosGroup/glTF-IBL-Sampler):

- level curve: pbrkit's own, r = m / (M - 1), lod = r (M - 1)
  (:func:`pbrkit.ibl.prefilter.level_of_roughness`): the viewer samples the generic chain;
- IBL shading: :func:`sample_viewer_ibl` (the pbr shader's ``getIBLGGXFresnel`` and
  mixes, :func:`pbrkit.rendering.khronos_ibl.sample_viewer_base`), the KHR_materials_*
  extensions in :func:`pbrkit.rendering.khronos_ibl.sample_viewer_extensions_ibl`;
  the diffuse from its Lambertian cube (E / pi);
- target writer: :func:`write_khronos` (``OUT/khronos/``);
- pinned version: :data:`VERSION` of :data:`NPM`.
"""

from __future__ import annotations

import shutil

import numpy as np

from ..albedo.sheen_tables import SheenTableSpec
from ..albedo.tables import splitsum_of_dfg
from ..brdf.shading.gltf import GLTF_DIELECTRIC_F0
from ..choices import RENDER_ENGINES
from ..core.jit import dual_use
from ..ibl.prefilter import level_of_roughness
from ..io.bake_chains import bake_formats, write_sheen_ktx2, write_specular_ktx2
from ..io.ktx2 import write_ktx2
from ..io.lut_files import write_lut
from ..rendering.khronos_ibl import sample_viewer_base
from .common import JS_DIR, bake_key, lut_spec
from .engine import Engine

__all__ = ["ENGINE", "NPM", "VERSION", "sample_viewer_ibl", "write_khronos"]

#: The npm package and version the target is written for and checked in (tests/engines/package.json).
NPM = "@khronosgroup/gltf-viewer"
VERSION = "1.1.0"


@dual_use
def sample_viewer_ibl(base, metallic, r, nov, a, b, radiance, irradiance):
    """One channel of the Sample Viewer 1.1's IBL of a metallic-roughness material
    (:func:`pbrkit.rendering.khronos_ibl.sample_viewer_base` with glTF's dielectric
    F0 0.04 and specular weight 1): W(f0) = FssEss + FmsEms with the
    roughness-dependent Fresnel F*(n.v, f0, r) in FssEss and f0 itself in F_avg;
    dielectric = base E / pi (1 - W(0.04)) + radiance W(0.04), metal = radiance
    W(base), mixed by metallic.  (a, b): Karis' (A, B) of the DFG table."""
    return sample_viewer_base(nov, r, base, metallic, GLTF_DIELECTRIC_F0, 1.0, a, b, radiance, irradiance)


def _lod(roughness, levels, size):
    """lod = r (M - 1) (:func:`pbrkit.ibl.prefilter.level_of_roughness`)."""
    return level_of_roughness(roughness, levels)


def write_khronos(folder, b):
    """The Khronos glTF Sample Viewer's IBL inputs into ``folder``.  The viewer uses
    pbrkit's cube layout and lod = r (M - 1), so ``specular.ktx2`` is the generic chain
    (:func:`pbrkit.io.bake_chains.write_specular_ktx2`, the same bytes); its diffuse
    cube is Lambertian *radiance*, E / pi (``lambertian.ktx2``: the generic
    irradiance divided by pi), and its lookup table is Karis' (A, B) with
    specular = F0 A + B and height-correlated Smith visibility (``lut_ggx.ktx2``,
    R16G16 float; A = DFG2 - DFG1 and B = DFG1 of the same integral).  Its sheen
    (KHR_materials_sheen) IBL: ``charlie.ktx2`` is the generic Charlie-prefiltered
    chain (``sheen.ktx2``: as many levels as the specular chain, which the viewer's
    one ``u_MipCount`` assumes, sheen roughness m / (M - 1)), ``lut_charlie.ktx2`` the
    Charlie DFG in the blue channel that ``getIBLRadianceCharlie`` reads, and
    ``lut_sheen_E.ktx2`` E_sheen in the red channel that ``albedoSheenScalingLUT``
    reads (:mod:`pbrkit.albedo.sheen_tables`; both the generic sheen table's E_sheen,
    KHR_materials_sheen's visibility).  Returns the manifest entry."""
    from dataclasses import replace

    write_specular_ktx2(folder / "specular.ktx2", b)
    lambertian = [np.asarray(b.irradiance, dtype=np.float32) / np.float32(np.pi)]
    write_ktx2(folder / "lambertian.ktx2", lambertian, bake_formats(b)[0], cube=True,
               key_values=bake_key("khronos", content="Lambertian radiance E(n) / pi: constant radiance 1 gives 1"))
    spec = lut_spec(b)
    if spec.kind != "dfg" or spec.visibility != "height-correlated":
        raise ValueError(f"the khronos LUT comes from the bake's height-correlated DFG table, not {spec.kind} "
                         f"with {spec.visibility} visibility")
    write_lut(folder / "lut_ggx.ktx2", splitsum_of_dfg(b.lut), replace(spec, kind="splitsum"))
    files = {"specular": "khronos/specular.ktx2", "lambertian": "khronos/lambertian.ktx2",
             "lut": "khronos/lut_ggx.ktx2", "lut_description": "khronos/lut_ggx.ktx2.json"}
    sheen = _write_sheen(folder, b) if b.sheen else {"files": {}}
    files.update(sheen.pop("files"))
    shutil.copyfile(JS_DIR / "pbrkit-khronos.js", folder / "pbrkit-khronos.js")
    files["module"] = "khronos/pbrkit-khronos.js"
    return {
        "files": files,
        "engine": f"Khronos glTF Sample Viewer (npm {NPM} {VERSION})",
        "conventions": {
            "levels": f"{len(b.specular)} levels, r = m / (M - 1); the viewer samples lod = r (mipCount - 1)",
            "diffuse": "Lambertian radiance E / pi: diffuse = base_color (1 - metallic) * lambertian(n)",
            "lut": "(A, B): specular albedo F0 A + B, height-correlated Smith-GGX, uv = (n.v, r), texel centres",
            "orientation": "CONVENTIONS cube layout, as the generic bake (the viewer's environmentRotation "
                           "of 90 degrees about +Y is a display setting: set it to 0 to see pbrkit's frame)",
            **sheen,
        },
        "load": ("import { loadPbrkitEnvironment } from './khronos/pbrkit-khronos.js'; "
                 "await loadPbrkitEnvironment(state, 'khronos/') (state: the viewer's GltfState; the viewer's "
                 "public ResourceLoader.loadEnvironment takes only .hdr files, so the module builds "
                 f"state.environment from these textures, relying on gltf-viewer {VERSION}'s layout of that object, "
                 "documented in its header; the sheen textures are bound when the folder has them)"),
    }


def _write_sheen(folder, b):
    """The Sample Viewer's three sheen inputs (:func:`write_khronos`) and their
    conventions; ``files`` among them."""
    write_sheen_ktx2(folder / "charlie.ktx2", b)  # the generic chain's file, byte for byte
    e = np.asarray(b.sheen_lut, dtype=np.float32)[..., 0]
    charlie = np.zeros(e.shape + (3,), np.float32)
    charlie[..., 2] = e
    write_lut(folder / "lut_charlie.ktx2", charlie, SheenTableSpec("charlie", e.shape[0], "sheen"))
    sheen_e = np.zeros(e.shape + (2,), np.float32)
    sheen_e[..., 0] = e
    write_lut(folder / "lut_sheen_E.ktx2", sheen_e, SheenTableSpec("sheen_e", e.shape[0], "sheen"))
    levels = len(b.sheen)
    return {
        "files": {"sheen": "khronos/charlie.ktx2", "sheen_lut": "khronos/lut_charlie.ktx2",
                  "sheen_e_lut": "khronos/lut_sheen_E.ktx2"},
        "sheen": (f"charlie.ktx2: {levels} levels (as many as specular.ktx2: the viewer samples both with "
                  f"u_MipCount), base {int(b.sheen[0].shape[1])}, sheen roughness m / (M - 1); the viewer samples "
                  "lod = sheenRoughness (u_MipCount - 1) in the mirror direction (getIBLRadianceCharlie); level 0 "
                  "is the horizon-circle mean (the IBL Sampler's is black)"),
        "sheen_lut": ("lut_charlie.ktx2: RGBA16F, (0, 0, E_sheen, 1), uv = (n.v, sheen roughness), texel centres; "
                      "the viewer reads .b (getIBLRadianceCharlie). E_sheen with KHR_materials_sheen's visibility "
                      "(the IBL Sampler's lut_charlie integrates Ashikhmin's: sheen_lut.npy channel 1)"),
        "sheen_e_lut": ("lut_sheen_E.ktx2: RG16F, (E_sheen, 0), uv = (n.v, sheen roughness), texel centres; the "
                        "viewer reads .r (albedoSheenScalingLUT: base scaled by 1 - max3(sheenColor) E)"),
    }


#: The Khronos glTF Sample Viewer (:class:`~pbrkit.engines.engine.Engine`).
ENGINE = Engine(name="khronos", code=RENDER_ENGINES.index("khronos"), title="Khronos glTF Sample Viewer", npm=NPM,
                version=VERSION, curve="linear", lod=_lod, shading=sample_viewer_ibl, diffuse="cube",
                energy_compensation=False, dominant_direction=False, writer=write_khronos)
