"""Filament (google/filament; npm ``filament``, its C++ ``ktxreader``):

- level curve: r_m = 1 - sqrt(1 - m / (M - 1)), lod = (M - 1) r (2 - r)
  (:func:`pbrkit.ibl.prefilter.filament_level_of_roughness`, with the curve the
  bake prefilters its ``filament`` chain at);
- IBL shading: pbrkit's split sum with the diffuse weighted by
  :func:`filament_diffuse_weight` (``evaluateIBL``), Filament's energy compensation
  on, the chain looked up in the specular dominant direction, SH diffuse;
- target writer: :func:`write_filament` (``OUT/filament/``);
- pinned version: :data:`VERSION` of :data:`NPM`.
"""

from __future__ import annotations

import math

import numpy as np

from ..choices import RENDER_ENGINES
from ..core.jit import dual_use
from ..ibl.prefilter import filament_level_of_roughness
from ..ibl.sh import lambertian_sh_prescaled
from ..io.ktx1 import filament_sh_text, write_ktx1
from .common import roughness_list, target_chain
from .engine import Engine

__all__ = ["ENGINE", "NPM", "VERSION", "CHAIN_FILE", "filament_diffuse_weight", "write_filament"]

#: The npm package and version the target is written for and checked in (tests/engines/package.json).
NPM = "filament"
VERSION = "1.53.4"
#: The target's file holding the chain Filament samples, relative to the bake folder.
CHAIN_FILE = "filament/ibl.ktx"

_INV_PI = 1.0 / math.pi


@dual_use
def filament_diffuse_weight(albedo):
    """Filament's weight of the Lambertian IBL diffuse, (1 - E) / pi with E the
    split-sum specular albedo DFG1 + F0 (DFG2 - DFG1) of the channel (Filament
    ``light_indirect.fs`` ``evaluateIBL``: Fd = diffuseColor diffuseIrradiance
    (1 - E), the SH holding E / pi)."""
    return (1.0 - albedo) * _INV_PI


def _lod(roughness, levels, size):
    """lod = (M - 1) r (2 - r) (:func:`pbrkit.ibl.prefilter.filament_level_of_roughness`)."""
    return filament_level_of_roughness(roughness, levels)


def write_filament(folder, b):
    """Filament's IBL and skybox as ``cmgen --format=ktx`` writes them and
    ``Engine.createIblFromKtx1`` / ``createSkyFromKtx1`` (C++: ``ktxreader::
    Ktx1Reader``) load them, into ``folder``: KTX1 cube maps (:mod:`pbrkit.io.ktx1`),
    the IBL with every level of the chain prefiltered at Filament's roughness levels
    r_m = 1 - sqrt(1 - m / (M - 1)) (its shader's lod = (M - 1) r (2 - r)) and the
    ``sh`` key holding the 9 coefficients Filament's shader takes
    (:func:`pbrkit.ibl.sh.lambertian_sh_prescaled`, E / pi); the skybox level 0
    only.  Orientation: Filament samples the plain world direction with the
    OpenGL cube table, as pbrkit does, so the faces are the generic ones.  Returns
    the manifest entry."""
    chain = target_chain(b, "filament", ENGINE.curve)
    # what cmgen writes and createIblFromKtx1 expects (it warns for RGBA16F, which loads too)
    fmt = "R11F_G11F_B10F"
    prescaled = lambertian_sh_prescaled(b.sh)
    write_ktx1(folder.parent / CHAIN_FILE, chain.levels, fmt, cube=True, key_values={"sh": filament_sh_text(prescaled)})
    write_ktx1(folder / "skybox.ktx", chain.levels[:1], fmt, cube=True)
    return {
        "files": {"ibl": CHAIN_FILE, "skybox": "filament/skybox.ktx"},
        "engine": f"Filament (npm {NPM} {VERSION}; C++ ktxreader)",
        "format": "R11F_G11F_B10F (glType 0x8C3A, as cmgen writes it: Filament aborts on the KTX spec's "
                  "0x8C3B), whatever --format says: createIblFromKtx1 warns for any other format",
        "conventions": {
            "levels": f"{len(chain.levels)} levels, r = 1 - sqrt(1 - m / (M - 1)); Filament samples "
                      "lod = (M - 1) r (2 - r)",
            "roughness": roughness_list(chain),
            "sh": "key 'sh': 9 lines 'r g b', L_lm (A_l / pi) K_lm (cmgen --sh-shader form: the shader's "
                  "sum gives E / pi), no window unless the bake's sh_window says so",
            "sh_values": [[float(v) for v in row] for row in np.asarray(prescaled, dtype=np.float32)],
            "orientation": "CONVENTIONS cube layout, no mirror (Filament samples the world direction). "
                           "cmgen puts an equirect's centre column at +Z, pbrkit at +X: to match a cmgen "
                           "bake of the same panorama, rotate the IndirectLight by 90 degrees about +Y",
        },
        "load": ("JS: Filament.init(['filament/ibl.ktx', 'filament/skybox.ktx'], () => { ... "
                 "const ibl = engine.createIblFromKtx1('filament/ibl.ktx'); scene.setIndirectLight(ibl); "
                 "scene.setSkybox(engine.createSkyFromKtx1('filament/skybox.ktx')); }) (Filament.init fetches "
                 f"the files; the strings then name them). Filament {VERSION}'s helper reads the "
                 "'sh' key into ibl.shfloats but builds the light from reflections only; for SH diffuse "
                 "build it as IndirectLight.Builder().reflections(ibl.getReflectionsTexture())"
                 ".irradianceSh(3, ibl.shfloats).build(engine). C++: ktxreader::Ktx1Reader::createTexture "
                 "and Ktx1Bundle::getSphericalHarmonics, then IndirectLight::Builder()"
                 ".reflections(texture).irradiance(3, sh)"),
    }


#: Filament (:class:`~pbrkit.engines.engine.Engine`).
ENGINE = Engine(name="filament", code=RENDER_ENGINES.index("filament"), title="Filament", npm=NPM, version=VERSION,
                curve="filament", lod=_lod, shading=filament_diffuse_weight, diffuse=None, energy_compensation=True,
                dominant_direction=True, writer=write_filament, chain_file=CHAIN_FILE)
