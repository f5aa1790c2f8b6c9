"""Bakes for real engines: the files each engine's own loader takes, baked for
its conventions (``pbrkit bake --target``).

A bake's generic files (:mod:`pbrkit.io.bake_files`) follow pbrkit's contract
(``CONVENTIONS.md``): OpenGL cube layout, lod = r (M - 1), radiance SH, an
irradiance cube holding E, the (DFG1, DFG2) table.  Engines differ in every one
of these (``docs/engine-targets.md`` has the details, read from each engine's
loader and shaders):

============  =========================================  ==========================  ===========  ==============
target        files                                      level curve                 orientation  diffuse
============  =========================================  ==========================  ===========  ==============
``khronos``   ``specular.ktx2``, ``lambertian.ktx2``,    r = m / (M - 1)             as generic   E / pi cube
              ``lut_ggx.ktx2`` (A, B), ``charlie.ktx2``,
              ``lut_charlie.ktx2``, ``lut_sheen_E.ktx2``
``filament``  ``ibl.ktx`` (KTX1 + ``sh`` key),           r = 1 - sqrt(1 - m/(M-1))   as generic   SH, E / pi
              ``skybox.ktx``
``three``     ``specular.ktx2`` + ``pbrkit-three.js``,   r = 1 - sqrt(1 - m/(M-1))   x mirrored   pi x last level
              ``sh.json`` (for ``LightProbe``)                                                    (or the SH)
``babylon``   ``environment.env``, ``specular.dds``      alpha = 2^(m/0.8) / N       z mirrored   SH polynomial
============  =========================================  ==========================  ===========  ==============

Each writer returns the target's manifest entry: its files, its conventions
and how to load it (the engine's API call).  The chains with Filament's and
Babylon's level curves are prefiltered for those curves by
:func:`pbrkit.ibl.prefilter.prefilter_chain` (``Bake.chains``), not
interpolated from the generic chain.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

__all__ = ["TARGETS", "TARGET_CHAINS", "TARGET_CHAIN_FILES", "TARGET_MIRRORS", "parse_targets", "chains_for",
           "write_target"]

#: Engines a bake can be written for: ``generic`` is pbrkit's own files (the
#: directory's top level); every other target writes a subdirectory named after it.
TARGETS = ("generic", "filament", "khronos", "babylon", "three")
#: The extra prefiltered chain (level curve, :data:`pbrkit.ibl.bake.EXTRA_CHAINS`)
#: each target needs.
TARGET_CHAINS = {"filament": "filament", "three": "filament", "babylon": "babylon"}
#: The file of each target that holds its chain, relative to the bake directory.
TARGET_CHAIN_FILES = {"filament": "filament/ibl.ktx", "three": "three/specular.ktx2",
                      "babylon": "babylon/specular.dds"}
#: The coordinate each target's cube content is mirrored in (its engine's lookups
#: mirror it: :func:`pbrkit.ibl.cubemap.mirror_cube`).
TARGET_MIRRORS = {"three": "x", "babylon": "z"}
#: The JavaScript modules pbrkit ships (``pbrkit/js``).
JS_DIR = Path(__file__).resolve().parent.parent / "js"


def parse_targets(values):
    """The targets of ``--target`` values (each a name, ``all``, or a comma-separated
    list of them), in :data:`TARGETS` order without repeats; ``generic`` when none
    is given (and always: the other targets sit beside the generic files).
    ValueError names an unknown one."""
    chosen = {"generic"}
    for value in values or ("generic",):
        for name in str(value).split(","):
            name = name.strip().lower()
            if name == "all":
                chosen.update(TARGETS)
            elif name in TARGETS:
                chosen.add(name)
            else:
                raise ValueError(f"--target: unknown target {name!r}; choose from {', '.join(TARGETS)}, all")
    return tuple(t for t in TARGETS if t in chosen)


def chains_for(targets):
    """The extra chains (level curves) that ``targets`` need, for
    :func:`pbrkit.ibl.bake.bake`'s ``chains``."""
    return tuple(dict.fromkeys(TARGET_CHAINS[t] for t in parse_targets(targets) if t in TARGET_CHAINS))


def _chain(b, target):
    curve = TARGET_CHAINS[target]
    chain = b.chains.get(curve)
    if chain is None:
        raise ValueError(f"target {target!r} needs the bake's {curve!r} chain: bake with "
                         f"chains=chains_for(targets) (pbrkit bake --target does)")
    return chain


def _key(target, **fields):
    return {"pbrkit.bake": json.dumps(dict(target=target, **fields))}


def _roughness(chain):
    return [round(float(r), 12) for r in chain.roughness]


# ------------------------------------------------------------------ khronos


def _write_khronos(folder, b):
    """The Khronos glTF Sample Viewer's IBL inputs (KhronosGroup/glTF-Sample-Renderer,
    its IBL from KhronosGroup/glTF-IBL-Sampler).  The viewer uses pbrkit's cube layout
    and lod = r (M - 1), so ``specular.ktx2`` is the generic chain; its diffuse
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
    KHR_materials_sheen's visibility)."""
    from dataclasses import replace

    from ..albedo.tables import splitsum_of_dfg
    from ..ibl.bake import SPECULAR_FORMATS
    from .ktx2 import write_ktx2
    from .lut_files import write_lut

    ktx_format = SPECULAR_FORMATS[b.manifest["options"]["format"]][0]
    # the generic chain, byte for byte (written before the targets)
    shutil.copyfile(folder.parent / "specular.ktx2", folder / "specular.ktx2")
    lambertian = [np.asarray(b.irradiance, dtype=np.float32) / np.float32(np.pi)]
    write_ktx2(folder / "lambertian.ktx2", lambertian, ktx_format, cube=True,
               key_values=_key("khronos", content="Lambertian radiance E(n) / pi: constant radiance 1 gives 1"))
    spec = _lut_spec(b)
    if spec.kind != "dfg" or spec.visibility != "height-correlated":
        raise ValueError(f"the khronos LUT comes from the bake's height-correlated DFG table, not {spec.kind} "
                         f"with {spec.visibility} visibility")
    write_lut(folder / "lut_ggx.ktx2", splitsum_of_dfg(b.lut), replace(spec, kind="splitsum"))
    files = {"specular": "khronos/specular.ktx2", "lambertian": "khronos/lambertian.ktx2",
             "lut": "khronos/lut_ggx.ktx2", "lut_description": "khronos/lut_ggx.ktx2.json"}
    sheen = _write_khronos_sheen(folder, b) if b.sheen else {"files": {}}
    files.update(sheen.pop("files"))
    shutil.copyfile(JS_DIR / "pbrkit-khronos.js", folder / "pbrkit-khronos.js")
    files["module"] = "khronos/pbrkit-khronos.js"
    return {
        "files": files,
        "engine": "Khronos glTF Sample Viewer (npm @khronosgroup/gltf-viewer 1.1.0)",
        "conventions": {
            "levels": f"{len(b.specular)} levels, r = m / (M - 1); the viewer samples lod = r (mipCount - 1)",
            "diffuse": "Lambertian radiance E / pi: diffuse = base_color (1 - metallic) * lambertian(n)",
            "lut": "(A, B): specular albedo F0 A + B, height-correlated Smith-GGX, uv = (n.v, r), texel centres",
            "orientation": "CONVENTIONS cube layout, as the generic bake (the viewer's environmentRotation "
                           "of 90 degrees about +Y is a display setting: set it to 0 to see pbrkit's frame)",
            **sheen,
        },
        "load": ("import { loadPbrkitEnvironment } from './pbrkit-khronos.js'; "
                 "await loadPbrkitEnvironment(state, 'khronos/') (state: the viewer's GltfState; the viewer's "
                 "public ResourceLoader.loadEnvironment takes only .hdr files, so the module builds "
                 "state.environment from these textures, relying on gltf-viewer 1.1.0's layout of that object, "
                 "documented in its header; the sheen textures are bound when the folder has them)"),
    }


def _write_khronos_sheen(folder, b):
    """The Sample Viewer's three sheen inputs (:func:`_write_khronos`) and their
    conventions; ``files`` among them."""
    from ..albedo.sheen_tables import SheenTableSpec
    from .lut_files import write_lut

    shutil.copyfile(folder.parent / "sheen.ktx2", folder / "charlie.ktx2")  # the generic chain, byte for byte
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


def _lut_spec(b):
    """The :class:`pbrkit.albedo.table_spec.TableSpec` of the bake's table (its manifest)."""
    from ..albedo.table_spec import TableSpec

    desc = b.manifest["outputs"]["brdf_lut"]["description"]
    return TableSpec(desc["kind"], int(desc["size"][0]), desc["visibility"], bool(desc["cloth"]),
                     (desc["integration"]["theta_nodes_per_segment"],
                      desc["integration"]["theta_nodes_per_segment_grazing_nv_below_0.0625"],
                      desc["integration"]["phi_nodes"]))


# ----------------------------------------------------------------- filament


def _write_filament(folder, b):
    """Filament's IBL and skybox as ``cmgen --format=ktx`` writes them and
    ``Engine.createIblFromKtx1`` / ``createSkyFromKtx1`` (C++: ``ktxreader::
    Ktx1Reader``) load them: KTX1 cube maps (:mod:`pbrkit.io.ktx1`), the IBL
    with every level of the chain prefiltered at Filament's roughness levels r_m =
    1 - sqrt(1 - m / (M - 1)) (its shader's lod = (M - 1) r (2 - r)) and the
    ``sh`` key holding the 9 coefficients Filament's shader takes
    (:func:`pbrkit.ibl.sh.lambertian_sh_prescaled`, E / pi); the skybox level 0
    only.  Orientation: Filament samples the plain world direction with the
    OpenGL cube table, as pbrkit does, so the faces are the generic ones."""
    from ..ibl.sh import lambertian_sh_prescaled
    from .ktx1 import filament_sh_text, write_ktx1

    chain = _chain(b, "filament")
    # what cmgen writes and createIblFromKtx1 expects (it warns for RGBA16F, which loads too)
    fmt = "R11F_G11F_B10F"
    prescaled = lambertian_sh_prescaled(b.sh)
    write_ktx1(folder.parent / TARGET_CHAIN_FILES["filament"], chain.levels, fmt, cube=True, key_values={"sh": filament_sh_text(prescaled)})
    write_ktx1(folder / "skybox.ktx", chain.levels[:1], fmt, cube=True)
    return {
        "files": {"ibl": TARGET_CHAIN_FILES["filament"], "skybox": "filament/skybox.ktx"},
        "engine": "Filament (npm filament 1.53.4; C++ ktxreader)",
        "format": "R11F_G11F_B10F (glType 0x8C3A, as cmgen writes it: Filament aborts on the KTX spec's "
                  "0x8C3B), whatever --format says: createIblFromKtx1 warns for any other format",
        "conventions": {
            "levels": f"{len(chain.levels)} levels, r = 1 - sqrt(1 - m / (M - 1)); Filament samples "
                      "lod = (M - 1) r (2 - r)",
            "roughness": _roughness(chain),
            "sh": "key 'sh': 9 lines 'r g b', L_lm (A_l / pi) K_lm (cmgen --sh-shader form: the shader's "
                  "sum gives E / pi), no window unless the bake's sh_window says so",
            "sh_values": [[float(v) for v in row] for row in np.asarray(prescaled, dtype=np.float32)],
            "orientation": "CONVENTIONS cube layout, no mirror (Filament samples the world direction). "
                           "cmgen puts an equirect's centre column at +Z, pbrkit at +X: to match a cmgen "
                           "bake of the same panorama, rotate the IndirectLight by 90 degrees about +Y",
        },
        "load": ("JS: const ibl = engine.createIblFromKtx1(iblBuffer); scene.setIndirectLight(ibl); "
                 "scene.setSkybox(engine.createSkyFromKtx1(skyBuffer)). Filament 1.53.4's helper reads the "
                 "'sh' key into ibl.shfloats but builds the light from reflections only; for SH diffuse "
                 "build it as IndirectLight.Builder().reflections(ibl.getReflectionsTexture())"
                 ".irradianceSh(3, ibl.shfloats).build(engine). C++: ktxreader::Ktx1Reader::createTexture "
                 "and Ktx1Bundle::getSphericalHarmonics, then IndirectLight::Builder()"
                 ".reflections(texture).irradiance(3, sh)"),
    }


# -------------------------------------------------------------------- three


def _write_three(folder, b):
    """three.js (r187): an RGBA16F cube KTX2 with every level, which the shipped ES
    module ``pbrkit-three.js`` turns into a ``CompressedCubeTexture`` flagged
    ``isPMREMTexture`` (three's KTX2Loader cannot load uncompressed cubes, and
    PMREM would re-filter and drop the chain).  three samples lod = (M - 1) r (2 - r)
    (Filament's curve: the chain is the Filament one) and, for cube textures
    that are not render targets, mirrors x: the faces hold C(b) = L(-b.x, b.y,
    b.z) (:func:`pbrkit.ibl.cubemap.mirror_cube`).  ``sh.json`` holds the radiance
    SH for ``LightProbe`` (three's SphericalHarmonics3 has pbrkit's basis, order
    and frame, and light probes are not mirrored)."""
    from ..ibl.cubemap import mirror_cube
    from .ktx2 import write_ktx2

    chain = _chain(b, "three")
    mirrored = [mirror_cube(level, TARGET_MIRRORS["three"]) for level in chain.levels]
    write_ktx2(folder.parent / TARGET_CHAIN_FILES["three"], mirrored, "R16G16B16A16_SFLOAT", cube=True,
               key_values=_key("three", roughness=_roughness(chain), lod="(M - 1) r (2 - r)",
                               orientation="x mirrored: C(b) = L(-b.x, b.y, b.z)"))
    sh = {"coefficients": [float(v) for v in np.asarray(b.sh, dtype=np.float64).reshape(-1)],
          "layout": "9 RGB radiance coefficients, CONVENTIONS order and basis = three.js SphericalHarmonics3"}
    (folder / "sh.json").write_text(json.dumps(sh, indent=1) + "\n", encoding="utf-8")
    shutil.copyfile(JS_DIR / "pbrkit-three.js", folder / "pbrkit-three.js")
    return {
        "files": {"specular": TARGET_CHAIN_FILES["three"], "module": "three/pbrkit-three.js", "sh": "three/sh.json"},
        "engine": "three.js (npm three 0.187.0, r187)",
        "format": "R16G16B16A16_SFLOAT (three uploads uncompressed cube data only as RGBA)",
        "conventions": {
            "levels": f"{len(chain.levels)} levels, r = 1 - sqrt(1 - m / (M - 1)); three samples "
                      "lod = (M - 1) r (2 - r); its diffuse is pi x the last (r = 1) level",
            "roughness": _roughness(chain),
            "orientation": "x mirrored, C(b) = L(-b.x, b.y, b.z): three flips x when it samples a cube "
                           "texture that is not a render target",
            "pmrem": "isPMREMTexture = true: used as is, not re-filtered by PMREMGenerator (MeshStandardMaterial, "
                     "MeshPhysicalMaterial, scene.background); r187's MeshBasic/Lambert/Phong ignore PMREM "
                     "textures: load a copy with loadPbrkitCubeKTX2(url, { pmrem: false }) for them",
            "sh": "sh.json: radiance SH for new THREE.LightProbe(new THREE.SphericalHarmonics3()"
                  ".fromArray(coefficients)), not mirrored; use it instead of the env map's diffuse, not "
                  "with it",
        },
        "load": ("import { loadPbrkitCubeKTX2 } from './pbrkit-three.js'; "
                 "scene.environment = await loadPbrkitCubeKTX2('three/specular.ktx2')"),
    }


# ------------------------------------------------------------------ babylon


def _write_babylon(folder, b):
    """Babylon.js: its native ``.env`` (:mod:`pbrkit.io.babylon_env`: RGBD PNG faces
    of the whole chain to 1 x 1, the irradiance spherical polynomial,
    ``lodGenerationScale`` 0.8) and an RGBA16F DDS of the same chain (Babylon's
    DDS reader takes DXGI R16G16B16A16_FLOAT, not R11G11B10; it computes its own
    SH from the DDS's level 0).  Babylon samples lod = 0.8 log2(N (r^2 + 0.0005)):
    level m holds alpha = min(1, 2^(m / 0.8) / N).  Its cube lookups negate z in
    right-handed scenes (and the glTF loader flips z in left-handed ones), so the
    faces hold C(b) = L(b.x, b.y, -b.z) and the SH are mirrored the same way."""
    from ..ibl.cubemap import mirror_cube
    from ..ibl.prefilter import BABYLON_LOD_GENERATION_SCALE
    from ..ibl.sh import babylon_polynomial, mirror_sh
    from .babylon_env import write_babylon_env
    from .dds import write_dds

    chain = _chain(b, "babylon")
    mirrored = [mirror_cube(level, TARGET_MIRRORS["babylon"]) for level in chain.levels]
    polynomial = babylon_polynomial(mirror_sh(b.sh, TARGET_MIRRORS["babylon"]))
    write_babylon_env(folder / "environment.env", mirrored, polynomial, BABYLON_LOD_GENERATION_SCALE)
    write_dds(folder.parent / TARGET_CHAIN_FILES["babylon"], mirrored, "R16G16B16A16_FLOAT", cube=True)
    return {
        "files": {"env": "babylon/environment.env", "dds": TARGET_CHAIN_FILES["babylon"]},
        "engine": "Babylon.js (npm babylonjs / @babylonjs/core 9.35.0)",
        "format": ".env: RGBD 8-bit PNG faces (values above 255 clip); .dds: R16G16B16A16_FLOAT",
        "conventions": {
            "levels": f"{len(chain.levels)} levels to 1 x 1, alpha_m = min(1, 2^(m / 0.8) / N), level 0 a "
                      "mirror; Babylon samples lod = 0.8 log2(N (r^2 + 0.0005)) (lodGenerationScale 0.8)",
            "roughness": _roughness(chain),
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


_WRITERS = {"khronos": _write_khronos, "filament": _write_filament, "three": _write_three,
            "babylon": _write_babylon}


def write_target(name, root, b):
    """Write target ``name``'s files into ``root/name`` for the bake ``b`` and
    return its manifest entry."""
    folder = Path(root) / name
    folder.mkdir()
    return _WRITERS[name](folder, b)
