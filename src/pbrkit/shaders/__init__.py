"""Shader code that matches pbrkit's models and bakes: GLSL functions for the
BRDF terms and models (:mod:`pbrkit.brdf`) and for sampling a pbrkit bake
(:mod:`pbrkit.ibl`), written by ``pbrkit shaders --target glsl -o DIR``.

The GLSL sources live in ``pbrkit/shaders/glsl/`` (package data), one file per
group:

- ``pbrkit_brdf.glsl``: D (``D_GGX``, ``D_Beckmann``, ``D_GTR1``,
  ``D_BlinnPhong``), G and V (``Lambda_GGX``, ``G2_Separable``,
  ``G2_HeightCorrelated``, ``V_SmithGGXCorrelated``, ``V_SmithGGX``,
  ``G1_SchlickGGX``, ``V_SchlickGGX`` with UE4's k, ``V_Kelemen``,
  ``V_Neubelt``), F (``F_Schlick``, ``F_SphericalGaussian``,
  ``F_SchlickRoughness``, ``F_Dielectric``), diffuse (``Fd_Lambert``,
  ``Fd_Burley``) and the models ``BRDF_UE4``, ``BRDF_Filament``,
  ``BRDF_glTF``, composed from those terms as :mod:`pbrkit.brdf.shading`
  composes them;
- ``pbrkit_ibl.glsl``: lod = r (M - 1), the DFG table lookup at (n.v, r)
  with texel centres, SH9 irradiance, the split-sum combination;
- ``pbrkit_ltc.glsl``: rectangular area lights with LTC tables as pbrkit
  evaluates them (``pbrkit ltc --clipping exact``: the LTC's integral clipped at
  the true horizon), and the tables' texture coordinate;
- ``pbrkit_npr.glsl``: the non-photorealistic terms of :mod:`pbrkit.npr.toon`
  (toon bands ``pbrkit_smoothStepBand`` and ``pbrkit_toonTone`` with up to 8
  thresholds in a ``float[8]`` and their count, the two-colour shade, the ramp
  image's lookup from ``texelFetch`` or the GPU's filter, the thresholded
  highlight, MToon 1.0's ``linearstep``, shading, parametric rim and GI
  equalisation) and of :func:`pbrkit.npr.hatching.hatch` (the blend of a tonal
  art map's tones, sampled by the engine, for a continuous tone, and the mip
  level log2(footprint) clamped to [0, L - 1]);
- ``pbrkit_khr.glsl``: the terms of the glTF extensions ``KHR_materials_sheen``
  (:mod:`pbrkit.microfacet.charlie`, :mod:`pbrkit.brdf.lobes.sheen`: Charlie
  ``D_Charlie``, the fitted ``Lambda_Charlie`` and ``V_Charlie``,
  ``V_Ashikhmin``, the lobe ``pbrkit_sheenBRDF``, the E_sheen table's lookup
  (grid points) from ``texelFetch`` or the GPU's filter, the albedo scaling
  1 - max3(sheenColor) E, and the split-sum sheen IBL at lod = sheenRoughness
  (M - 1)) and ``KHR_materials_iridescence`` (:func:`pbrkit.brdf.fresnel.
  f_iridescence`: ``F_Iridescence``, ``F_IridescenceDielectric`` and the
  spectral sensitivity); needs ``pbrkit_brdf.glsl`` before it;
- ``pbrkit_khr_material.glsl``: the extended glTF material of
  :mod:`pbrkit.brdf.shading.gltf` (``KHR_materials_ior`` and ``_specular``: the
  dielectric's F0 and F90 and the diffuse's weight; ``KHR_materials_clearcoat``:
  the coat lobe ``pbrkit_clearcoatBRDF``, its Fresnel layering and its own normal
  from a clearcoatNormalTexture, ``pbrkit_clearcoatNormal``; the whole BRDF
  ``BRDF_glTFExtended`` with the sheen, its factors in a ``pbrkit_KHRMaterial``,
  and ``BRDF_glTFExtendedCoatNormal`` with the coat about its own normal)
  and the extensions' real-time IBL, the coat's Fresnel at the view's cosine to
  the coat's normal: pbrkit's own (split sum with F90, the
  diffuse's F* weight, the coat's roughness, the sheen and coat terms and the
  base's scale, ``pbrkit_glTFExtendedIBL``) and the Khronos Sample Viewer's
  (:mod:`pbrkit.rendering.khronos_ibl`), with ``KHR_materials_transmission`` /
  ``_volume``'s transmitted light (:mod:`pbrkit.rendering.transmission_ibl`) and
  ``KHR_materials_dispersion``'s IORs per channel (``pbrkit_dispersionIors``,
  ``pbrkit_sampleViewerDispersionIors``: :mod:`pbrkit.brdf.transmission`) and
  each channel's lookup ``pbrkit_dispersionLookup``; ``KHR_materials_anisotropy``: the frame
  ``pbrkit_anisotropicFrame`` (a ``mat3``) of a glTF tangent and the rotation's
  (cos, sin), alpha_t, the anisotropic GGX ``pbrkit_dGGXAnisotropic`` and
  height-correlated ``pbrkit_vGGXAnisotropic``, the lobe
  ``pbrkit_anisotropicSpecular``, the core material's ``BRDF_glTFAnisotropic``
  and the Sample Viewer's bent-normal lookup ``pbrkit_anisotropicReflection``
  (:func:`pbrkit.rendering.ibl_lookups.khr_anisotropic_reflection`); needs
  ``pbrkit_brdf.glsl`` and ``pbrkit_khr.glsl`` before it.

GLSL ES 3.00 (WebGL2) and GLSL 3.30+: the user adds the version line.  Each
function is preceded by a comment whose ``source:``, ``roughness:`` and
``pbrkit:`` lines give its citation, its roughness remap and the pbrkit
function it transcribes; :func:`functions` reads them back, and the
``manifest.json`` written beside the files lists them.  tests/shaders/test_shaders.py,
tests/shaders/test_shaders_khr.py and tests/shaders/test_shaders_khr_material.py compile every
function in WebGL2 and compare it with pbrkit's own.
"""

from __future__ import annotations

import json
import re
from importlib import resources

from ..choices import SHADER_TARGETS

__all__ = ["TARGETS", "GLSL_FILES", "glsl_sources", "functions", "shader_manifest", "write_shaders"]

#: Shader languages ``pbrkit shaders --target`` writes.
TARGETS = SHADER_TARGETS  # pbrkit.choices
#: The GLSL files, in the order they may be concatenated.
GLSL_FILES = ("pbrkit_brdf.glsl", "pbrkit_ibl.glsl", "pbrkit_ltc.glsl", "pbrkit_npr.glsl", "pbrkit_khr.glsl",
              "pbrkit_khr_material.glsl")
#: Version of the manifest's layout.
MANIFEST_VERSION = 1

_TYPES = r"(?:float|vec[234]|mat[234]|bool|int|ivec[234]|pbrkit_Cosines)"
_DEFINITION = re.compile(rf"^({_TYPES})\s+([A-Za-z_][A-Za-z0-9_]*)\s*\(([^)]*)\)?", re.M)


def glsl_sources(target="glsl"):
    """{file name: GLSL text} of ``target`` (only ``glsl``), in :data:`GLSL_FILES` order."""
    _check_target(target)
    folder = resources.files(__name__).joinpath("glsl")
    return {name: folder.joinpath(name).read_text(encoding="utf-8") for name in GLSL_FILES}


def _check_target(target):
    if target not in TARGETS:
        raise ValueError(f"unknown shader target {target!r}; choose one of {', '.join(TARGETS)}")


def _comment_block(lines, index):
    """The ``//`` comment lines directly above line ``index`` (without the slashes)."""
    block = []
    k = index - 1
    while k >= 0 and lines[k].lstrip().startswith("//"):
        block.append(lines[k].lstrip()[2:].strip())
        k -= 1
    return block[::-1]


def functions(sources=None):
    """The documented functions of the GLSL sources, in file order: a list of
    {name, file, signatures, summary, source, roughness, pbrkit}.  ``summary``
    is the comment's first line (after ``name:``); overloads (``F_Schlick`` for
    float and vec3) share one entry with several signatures.  A function
    without a ``source:``, ``roughness:`` or ``pbrkit:`` line raises
    ValueError (the sources are the package's own: that is a bug)."""
    sources = glsl_sources() if sources is None else sources
    entries = {}
    for file, text in sources.items():
        lines = text.splitlines()
        for number, line in enumerate(lines):
            match = _DEFINITION.match(line)
            if match is None or line.rstrip().endswith(";"):
                continue
            return_type, name = match.group(1), match.group(2)
            signature = line.rstrip().rstrip("{").strip()
            if not signature.endswith(")"):  # parameters continue on the next lines
                k = number + 1
                while not signature.endswith(")") and k < len(lines):
                    signature += " " + lines[k].strip().rstrip("{").strip()
                    k += 1
            if name in entries:
                entries[name]["signatures"].append(signature)
                continue
            block = _comment_block(lines, number)
            fields = {"summary": [], "source": None, "roughness": None, "pbrkit": None}
            current = "summary"
            for text_line in block:
                key = text_line.split(":", 1)[0]
                if key in ("source", "roughness", "pbrkit"):
                    current = key
                    fields[key] = text_line.split(":", 1)[1].strip()
                elif current == "summary":
                    fields["summary"].append(text_line)
                else:
                    fields[current] += " " + text_line
            missing = [k for k in ("source", "roughness", "pbrkit") if not fields[k]]
            if missing or not fields["summary"]:
                raise ValueError(f"{file}: {name} lacks its comment line(s): {', '.join(missing) or 'summary'}")
            summary = " ".join(fields["summary"])
            if summary.startswith(name + ":"):
                summary = summary[len(name) + 1:].strip()
            entries[name] = {
                "name": name,
                "file": file,
                "returns": return_type,
                "signatures": [signature],
                "summary": " ".join(summary.split()),
                "source": fields["source"],
                "roughness": fields["roughness"],
                "pbrkit": [p.strip() for p in fields["pbrkit"].split(",")],
            }
    return list(entries.values())


def shader_manifest(target="glsl", sources=None):
    """The ``manifest.json`` content of :func:`write_shaders`: the files, every
    function (:func:`functions`) and the bake conventions built into them."""
    _check_target(target)
    sources = glsl_sources(target) if sources is None else sources
    from .. import __version__

    return {
        "format": "pbrkit shaders",
        "format_version": MANIFEST_VERSION,
        "pbrkit_version": __version__,
        "target": target,
        "language": "GLSL ES 3.00 (WebGL2) and GLSL 3.30+ (desktop OpenGL); add the version line "
                    "('#version 300 es' or '#version 330 core') before the files",
        "files": list(sources),
        "conventions": {
            "roughness": "perceptual roughness r in [0, 1]; GGX alpha = max(r^2, 1e-3) (pbrkit_alphaFromRoughness); "
                         "UE4 direct-light k = (r + 1)^2 / 8, IBL k = r^2 / 2",
            "brdf": "f (not f cos); l toward the light, v toward the eye, h = normalize(l + v); 0 unless n.l > 0 "
                    "and n.v > 0",
            "level_of_roughness": "lod = r (M - 1) (level m of M holds r = m / (M - 1)), trilinear filtering",
            "brdf_lut": "(DFG1, DFG2) table indexed [j, i]: column i at n.v = (i + 0.5) / N, row j at r = "
                        "(j + 0.5) / N, row 0 first; texture coordinates (n.v, r); albedo DFG1 + F0 (DFG2 - DFG1)",
            "sh": "9 radiance coefficients, order (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) (2,1) (2,2), real "
                  "orthonormal SH on world (x, y, z), no Condon-Shortley phase; E = sum A_l L_lm Y_lm(n), "
                  "A = (pi, 2 pi / 3, pi / 4)",
            "irradiance": "E, not E / pi: Lambertian radiance is diffuse colour / pi * E",
            "sheen_albedo": "E_sheen table (pbrkit/data/sheen_albedo.npy) indexed [i, j]: row i at sheenRoughness = "
                            "i / (M - 1), column j at n.v = j / (N - 1) (grid points, not texel centres), row 0 "
                            "first; Charlie alpha = sheenRoughness^2",
            "cube_map": "faces +X -X +Y -Y +Z -Z in OpenGL orientation (table 8.19), row 0 first, not mirrored",
        },
        "functions": functions(sources),
    }


def write_shaders(out_dir, target="glsl", force=False):
    """Write the shader files of ``target`` and their ``manifest.json`` into
    ``out_dir``, atomically (:func:`pbrkit.core.atomic.atomic_directory`: all
    or nothing; an existing non-empty ``out_dir`` is refused unless ``force``,
    which replaces it).  Same bytes every time.  Returns the file names written."""
    from pathlib import Path

    from ..core.atomic import atomic_directory

    _check_target(target)
    sources = glsl_sources(target)
    manifest = shader_manifest(target, sources)
    names = list(sources) + ["manifest.json"]
    with atomic_directory(out_dir, force) as tmp:
        for name, text in sources.items():
            (Path(tmp) / name).write_bytes(text.encode("utf-8"))
        (Path(tmp) / "manifest.json").write_bytes((json.dumps(manifest, indent=2) + "\n").encode("utf-8"))
    return names
