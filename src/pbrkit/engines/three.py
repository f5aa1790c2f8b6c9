"""three.js (npm ``three``, r187):

- level curve: Filament's, lod = (M - 1) r (2 - r)
  (:func:`pbrkit.ibl.prefilter.filament_level_of_roughness`; ``PMREMGenerator`` and
  ``envmap_common_pars_fragment``): it samples the bake's ``filament`` chain;
- IBL shading: :func:`three_ibl` (``RE_IndirectSpecular_Physical`` with
  :func:`multiple_scattering_fdez_aguera`), pi x the chain's last level as
  irradiance, the lookup in the specular dominant direction, its roughness from
  screen-space derivatives (:func:`pbrkit.rendering.ibl_lookups.three_roughness`);
- target writer: :func:`write_three` (``OUT/three/``);
- pinned version: :data:`VERSION` of :data:`NPM`.
"""

from __future__ import annotations

import json
import math
import shutil

import numpy as np

from ..brdf.shading.gltf import GLTF_DIELECTRIC_F0
from ..choices import RENDER_ENGINES
from ..core.jit import dual_use
from ..ibl.cubemap import mirror_cube
from ..ibl.prefilter import filament_level_of_roughness
from ..io.ktx2 import write_ktx2
from .common import JS_DIR, bake_key, roughness_list, target_chain
from .engine import Engine

__all__ = ["ENGINE", "NPM", "VERSION", "REVISION", "CHAIN_FILE", "MIRROR", "multiple_scattering_fdez_aguera",
           "three_ibl", "write_three"]

#: The npm package and version the target is written for and checked in (tests/engines/package.json).
NPM = "three"
VERSION = "0.187.0"
#: three's ``REVISION`` of that version.
REVISION = 187
#: The target's file holding the chain three samples, relative to the bake folder.
CHAIN_FILE = "three/specular.ktx2"
#: three flips x when it samples a cube texture that is not a render target.
MIRROR = "x"

_INV_PI = 1.0 / math.pi


@dual_use
def multiple_scattering_fdez_aguera(f0, a, b):
    """Single- and multiple-scattering specular albedo of a split-sum lobe (Fdez-Agüera,
    "A Multiple-Scattering Microfacet Model for Real-Time Image-based Lighting",
    JCGT 8(1), 2019, sec. 3-4): with Karis' table (A, B) (E_ss = A + B for F = 1),
    FssEss = f0 A + B (``f0`` may be a roughness-dependent Fresnel), E_ms = 1 - E_ss,
    F_avg = f0 + (1 - f0) / 21 (the cosine-weighted mean of Schlick's F) and
    FmsEms = E_ms FssEss F_avg / (1 - F_avg E_ms).  Returns (FssEss, FmsEms).  What
    three.js (``computeMultiscattering``) uses for IBL; roughness enters only through
    A, B."""
    fss_ess = f0 * a + b
    e_ms = 1.0 - (a + b)
    f_avg = f0 + (1.0 - f0) / 21.0
    return fss_ess, e_ms * fss_ess * f_avg / (1.0 - f_avg * e_ms)


@dual_use
def three_ibl(base, metallic, r, nov, a, b, radiance, irradiance):
    """One channel of three.js r187's IBL of a metallic-roughness material
    (``RE_IndirectSpecular_Physical``): single and multiple scattering
    (:func:`multiple_scattering_fdez_aguera`, f0 = 0.04 and base, f90 = 1) mixed by
    metallic, the multiple-scattering part lit by the irradiance (E / pi), not the
    radiance, and the diffuse base (1 - metallic) (1 - FssEss - FmsEms of the
    dielectric) E / pi.  (a, b): Karis' (A, B) of the DFG table."""
    ss_d, ms_d = multiple_scattering_fdez_aguera(GLTF_DIELECTRIC_F0, a, b)
    ss_m, ms_m = multiple_scattering_fdez_aguera(base, a, b)
    single = ss_d + (ss_m - ss_d) * metallic
    multi = ms_d + (ms_m - ms_d) * metallic
    diffuse = base * (1.0 - metallic) * (1.0 - (ss_d + ms_d))
    return radiance * single + (multi + diffuse) * irradiance * _INV_PI


def _lod(roughness, levels, size):
    """lod = (M - 1) r (2 - r) (:func:`pbrkit.ibl.prefilter.filament_level_of_roughness`)."""
    return filament_level_of_roughness(roughness, levels)


def write_three(folder, b):
    """three.js (r187) files into ``folder``: an RGBA16F cube KTX2 with every level,
    which the shipped ES module ``pbrkit-three.js`` turns into a
    ``CompressedCubeTexture`` flagged ``isPMREMTexture`` (three's KTX2Loader cannot
    load uncompressed cubes, and PMREM would re-filter and drop the chain).  three
    samples lod = (M - 1) r (2 - r) (Filament's curve: the chain is the Filament one)
    and, for cube textures that are not render targets, mirrors x: the faces hold
    C(b) = L(-b.x, b.y, b.z) (:func:`pbrkit.ibl.cubemap.mirror_cube`).  ``sh.json``
    holds the radiance SH for ``LightProbe`` (three's SphericalHarmonics3 has pbrkit's
    basis, order and frame, and light probes are not mirrored).  Returns the manifest
    entry."""
    chain = target_chain(b, "three", ENGINE.curve)
    mirrored = [mirror_cube(level, MIRROR) for level in chain.levels]
    write_ktx2(folder.parent / CHAIN_FILE, mirrored, "R16G16B16A16_SFLOAT", cube=True,
               key_values=bake_key("three", roughness=roughness_list(chain), lod="(M - 1) r (2 - r)",
                                   orientation="x mirrored: C(b) = L(-b.x, b.y, b.z)"))
    sh = {"coefficients": [float(v) for v in np.asarray(b.sh, dtype=np.float64).reshape(-1)],
          "layout": "9 RGB radiance coefficients, CONVENTIONS order and basis = three.js SphericalHarmonics3"}
    (folder / "sh.json").write_text(json.dumps(sh, indent=1) + "\n", encoding="utf-8")
    shutil.copyfile(JS_DIR / "pbrkit-three.js", folder / "pbrkit-three.js")
    return {
        "files": {"specular": CHAIN_FILE, "module": "three/pbrkit-three.js", "sh": "three/sh.json"},
        "engine": f"three.js (npm {NPM} {VERSION}, r{REVISION})",
        "format": "R16G16B16A16_SFLOAT (three uploads uncompressed cube data only as RGBA)",
        "conventions": {
            "levels": f"{len(chain.levels)} levels, r = 1 - sqrt(1 - m / (M - 1)); three samples "
                      "lod = (M - 1) r (2 - r); its diffuse is pi x the last (r = 1) level",
            "roughness": roughness_list(chain),
            "orientation": "x mirrored, C(b) = L(-b.x, b.y, b.z): three flips x when it samples a cube "
                           "texture that is not a render target",
            "pmrem": f"isPMREMTexture = true: used as is, not re-filtered by PMREMGenerator (MeshStandardMaterial, "
                     f"MeshPhysicalMaterial, scene.background); r{REVISION}'s MeshBasic/Lambert/Phong ignore PMREM "
                     "textures: load a copy with loadPbrkitCubeKTX2(url, { pmrem: false }) for them",
            "sh": "sh.json: radiance SH for new THREE.LightProbe(new THREE.SphericalHarmonics3()"
                  ".fromArray(coefficients)), not mirrored; use it instead of the env map's diffuse, not "
                  "with it",
        },
        "load": ("import { loadPbrkitCubeKTX2 } from './three/pbrkit-three.js'; "
                 "scene.environment = await loadPbrkitCubeKTX2('three/specular.ktx2')"),
    }


#: three.js (:class:`~pbrkit.engines.engine.Engine`).
ENGINE = Engine(name="three", code=RENDER_ENGINES.index("three"), title="three.js", npm=NPM, version=VERSION,
                curve="filament", lod=_lod, shading=three_ibl, diffuse="last-level", energy_compensation=False,
                dominant_direction=True, writer=write_three, chain_file=CHAIN_FILE, mirror=MIRROR)
