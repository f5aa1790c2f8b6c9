"""Babylon.js (npm ``babylonjs`` / ``@babylonjs/core``):

- level curve: alpha_m = min(1, 2^(m / 0.8) / N), lod = 0.8 log2(N (r^2 + 0.0005))
  (:func:`pbrkit.ibl.prefilter.babylon_level_of_roughness`, with the curve the bake
  prefilters its ``babylon`` chain at);
- IBL shading: :func:`babylon_ibl` (PBRMaterial with its defaults), SH diffuse
  (its spherical polynomial);
- target writer: :func:`write_babylon` (``OUT/babylon/``);
- pinned version: :data:`VERSION` of :data:`NPM`.
"""

from __future__ import annotations

import math

from ..albedo.tables import filament_energy_compensation
from ..brdf.shading.gltf import GLTF_DIELECTRIC_F0
from ..choices import RENDER_ENGINES
from ..core.jit import dual_use
from ..ibl.cubemap import mirror_cube
from ..ibl.prefilter import BABYLON_LOD_GENERATION_SCALE, babylon_alpha_g, babylon_level_of_roughness
from ..ibl.sh import babylon_polynomial, mirror_sh
from ..io.babylon_env import write_babylon_env
from ..io.dds import write_dds
from .common import roughness_list, target_chain
from .engine import Engine

__all__ = ["ENGINE", "NPM", "VERSION", "CHAIN_FILE", "MIRROR", "babylon_ibl", "write_babylon"]

#: The npm package and version the target is written for and checked in (tests/engines/package.json;
#: the same version of ``@babylonjs/core``, whose sources docs/engine-targets.md cites).
NPM = "babylonjs"
VERSION = "9.35.0"
#: The target's file holding the chain Babylon samples, relative to the bake folder.
CHAIN_FILE = "babylon/specular.dds"
#: Babylon negates z for cube lookups in right-handed scenes (its glTF loader flips z in left-handed ones).
MIRROR = "z"

_INV_PI = 1.0 / math.pi


@dual_use
def babylon_ibl(base, metallic, r, nov, a, b, radiance, irradiance):
    """One channel of Babylon.js 9.35's IBL of a metallic-roughness material,
    PBRMaterial with its defaults (``pbrBlockReflection``, ``pbrBlockReflectivity``,
    ``pbrBlockFinalColorComposition``): the radiance mixed towards the Lambertian
    radiance E / pi by alpha_G = r^2 + 0.0005 (``MIX_IBL_RADIANCE_WITH_IRRADIANCE``,
    :func:`pbrkit.ibl.prefilter.babylon_alpha_g`), times F0 A + B and its energy
    conservation 1 + F0 (1 / (A + B) - 1) (Filament's,
    :func:`pbrkit.albedo.tables.filament_energy_compensation`), f0 = mix(0.04, base,
    metallic), and the legacy diffuse base (1 - 0.04) (1 - metallic) E / pi.
    (a, b): Karis' (A, B) of the DFG table."""
    f0 = GLTF_DIELECTRIC_F0 + (base - GLTF_DIELECTRIC_F0) * metallic
    mixed = radiance + (irradiance * _INV_PI - radiance) * babylon_alpha_g(r)
    ec = filament_energy_compensation(f0, max(a + b, 1e-6))
    diffuse = base * (1.0 - GLTF_DIELECTRIC_F0) * (1.0 - metallic)
    return mixed * (f0 * a + b) * ec + diffuse * irradiance * _INV_PI


def _lod(roughness, levels, size):
    """lod = 0.8 log2(N (r^2 + 0.0005)) (:func:`pbrkit.ibl.prefilter.babylon_level_of_roughness`)."""
    return babylon_level_of_roughness(roughness, size)


def write_babylon(folder, b):
    """Babylon.js files into ``folder``: its native ``.env`` (:mod:`pbrkit.io.babylon_env`:
    RGBD PNG faces of the whole chain to 1 x 1, the irradiance spherical polynomial,
    ``lodGenerationScale`` 0.8) and an RGBA16F DDS of the same chain (Babylon's
    DDS reader takes DXGI R16G16B16A16_FLOAT, not R11G11B10; it computes its own
    SH from the DDS's level 0).  Babylon samples lod = 0.8 log2(N (r^2 + 0.0005)):
    level m holds alpha = min(1, 2^(m / 0.8) / N).  Its cube lookups negate z in
    right-handed scenes (and the glTF loader flips z in left-handed ones), so the
    faces hold C(b) = L(b.x, b.y, -b.z) and the SH are mirrored the same way.
    Returns the manifest entry."""
    chain = target_chain(b, "babylon", ENGINE.curve)
    mirrored = [mirror_cube(level, MIRROR) for level in chain.levels]
    polynomial = babylon_polynomial(mirror_sh(b.sh, MIRROR))
    write_babylon_env(folder / "environment.env", mirrored, polynomial, BABYLON_LOD_GENERATION_SCALE)
    write_dds(folder.parent / CHAIN_FILE, mirrored, "R16G16B16A16_FLOAT", cube=True)
    return {
        "files": {"env": "babylon/environment.env", "dds": CHAIN_FILE},
        "engine": f"Babylon.js (npm {NPM} / @babylonjs/core {VERSION})",
        "format": ".env: RGBD 8-bit PNG faces (values above 255 clip); .dds: R16G16B16A16_FLOAT",
        "conventions": {
            "levels": f"{len(chain.levels)} levels to 1 x 1, alpha_m = min(1, 2^(m / 0.8) / N), level 0 a "
                      "mirror; Babylon samples lod = 0.8 log2(N (r^2 + 0.0005)) (lodGenerationScale 0.8)",
            "roughness": roughness_list(chain),
            "orientation": "z mirrored, C(b) = L(b.x, b.y, -b.z): Babylon negates z for cube lookups in "
                           "right-handed scenes (scene.useRightHandedSystem = true), and its glTF loader "
                           "flips z in left-handed ones",
            "sh": "the .env's irradiance polynomial: Babylon's SphericalPolynomial of the z-mirrored SH "
                  "(Condon-Shortley signs, A_l / pi); its default shader path gives E / pi",
            "polynomial": {k: [float(x) for x in v] for k, v in polynomial.items()},
        },
        "load": ("scene.environmentTexture = BABYLON.CubeTexture.CreateFromPrefilteredData("
                 "'babylon/environment.env', scene) (or 'babylon/specular.dds': Babylon then computes the SH "
                 "itself)"),
    }


#: Babylon.js (:class:`~pbrkit.engines.engine.Engine`).
ENGINE = Engine(name="babylon", code=RENDER_ENGINES.index("babylon"), title="Babylon.js", npm=NPM, version=VERSION,
                curve="babylon", lod=_lod, shading=babylon_ibl, diffuse="sh", energy_compensation=False,
                dominant_direction=False, writer=write_babylon, chain_file=CHAIN_FILE, mirror=MIRROR)
