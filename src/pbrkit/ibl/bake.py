"""Image-based-lighting bakes: everything a real-time renderer needs for the
split-sum IBL of an HDR environment (``pbrkit bake``).

:func:`bake` computes, from an environment (:func:`pbrkit.ibl.equirect.
load_environment`: equirect .hdr/.exr/.pfm/.png/.jpg, cube crosses or six
faces):

- the GGX-prefiltered specular mip chain (:mod:`pbrkit.ibl.prefilter`): level 0
  is the environment resampled to ``size`` (exact area-weighted,
  :meth:`pbrkit.io.environment.Environment.to_cube`), level m of M has perceptual
  roughness r_m = m / (M - 1) (:func:`roughness_of_level`; a shader samples
  lod = r (M - 1), :func:`level_of_roughness`) and size ``size`` / 2^m down
  to ``min_size``;
- the irradiance cube map E(n) (:mod:`pbrkit.ibl.irradiance`);
- the 9 radiance SH coefficients (:func:`pbrkit.ibl.sh.project_equirect`: the
  exact integrals of the basis over the input pixels' cells, or
  :func:`pbrkit.ibl.sh.project_cube` for cube input: solid-angle-weighted
  projection; windowing optional, off by default);
- the split-sum DFG table (:func:`pbrkit.albedo.lut.lookup_table` kind ``dfg``:
  Filament's (DFG1, DFG2) with the height-correlated Smith visibility);
- the sheen (``KHR_materials_sheen``) IBL: the Charlie-prefiltered chain
  (:func:`pbrkit.ibl.sheen.prefilter_charlie`: as many levels as the specular chain,
  level m at sheen roughness m / (M - 1), sizes from
  :func:`pbrkit.ibl.sheen.sheen_chain_sizes`) and the sheen table (E_sheen,
  E_ashikhmin) (:func:`pbrkit.albedo.sheen_tables.sheen_lut`), ``lut_size`` square.

Levels 1.. and the irradiance map come from one spherical-harmonic transform
of the environment's bounded part plus exactly summed highlights
(:func:`pbrkit.ibl.prefilter.prefilter_spectral`); ``method="fis"`` uses
filtered importance sampling instead (:func:`pbrkit.ibl.prefilter.
prefilter_fis`).

The files of a bake are written and read by :mod:`pbrkit.io.bake_files`.
"""

from __future__ import annotations

import hashlib
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..choices import BAKE_METHODS
from .. import __version__
from ..core import checks
from ..core.atomic import check_output_directory as check_output_dir
from ..core.color import luminance, tonemap_reinhard
from ..microfacet.roughness import alpha_from_roughness
from .cubemap import FACE_NAMES, cube_texel_solid_angles, cube_to_cross, resample_cube
from .equirect import cube_to_equirect
from .irradiance import irradiance_spectral
from .prefilter import (
    BAND_LIMIT_TOLERANCE,
    HIGHLIGHT_RATIO,
    band_limit,
    chain_roughness,
    cube_highlights,
    default_sample_counts,
    equirect_highlights,
    prefilter_chain,
    prefilter_fis,
    prefilter_spectral,
    roughness_of_level,
)

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "FACE_FILE_NAMES",
    "SPECULAR_FORMATS",
    "EXTRA_CHAINS",
    "Bake",
    "Chain",
    "bake",
    "check_output_dir",
    "tone_map",
    "preview_strip",
]

FORMAT = "pbrkit IBL bake"
FORMAT_VERSION = 1
#: File-name suffixes of the six faces (+X, -X, +Y, -Y, +Z, -Z).
FACE_FILE_NAMES = ("px", "nx", "py", "ny", "pz", "nz")
#: ``specular_format`` -> (KTX2 vkFormat, DDS DXGI format).
SPECULAR_FORMATS = {
    "rgba16f": ("R16G16B16A16_SFLOAT", "R16G16B16A16_FLOAT"),
    "b10g11r11": ("B10G11R11_UFLOAT_PACK32", "R11G11B10_FLOAT"),
}
METHODS = BAKE_METHODS  # pbrkit.choices
MAX_SIZE = 4096
_CHUNK = 1 << 20


@dataclass
class Bake:
    """A bake in memory (see the module doc).

    ``specular``: level m (6, N_m, N_m, 3) float32, N_m = size >> m;
    ``roughness`` (M,) perceptual roughness per level (0 first, increasing);
    ``irradiance`` (6, K, K, 3) float32 E(n); ``sh`` (9, 3) float64 radiance
    SH (CONVENTIONS order and basis); ``lut`` (L, L, 2) float32 DFG table;
    ``sheen`` the Charlie-prefiltered levels (6, n_m, n_m, 3) float32 (M of them, at
    sheen roughness ``sheen_roughness``); ``sheen_lut`` (L, L, 2) float32 (E_sheen,
    E_ashikhmin); ``manifest`` what ``manifest.json`` holds; ``chains`` the extra chains for
    engine targets, level curve -> :class:`Chain`; ``timings`` seconds per stage
    (never written: they differ from run to run)."""

    specular: list
    roughness: np.ndarray
    irradiance: np.ndarray
    sh: np.ndarray
    lut: np.ndarray
    manifest: dict
    timings: dict = field(default_factory=dict)
    chains: dict = field(default_factory=dict)
    sheen: list = field(default_factory=list)
    sheen_roughness: np.ndarray = None
    sheen_lut: np.ndarray = None

    @property
    def levels(self):
        return len(self.specular)


@dataclass
class Chain:
    """A prefiltered chain with another level curve (:data:`EXTRA_CHAINS`):
    ``levels`` (6, N_m, N_m, 3) float32 (level 0 the bake's level 0),
    ``roughness`` (M,) perceptual roughness, ``info`` per level 1.. as in the
    manifest's ``levels``."""

    curve: str
    levels: list
    roughness: np.ndarray
    info: list


# ------------------------------------------------------------------- checks


def _check_options(size, min_size, irradiance_size, lut_size, specular_format, method, sh_window):
    # named by the command line's flags (pbrkit bake --size / --min-size), as the refusals are printed
    size = checks.power_of_two(size, "--size", 2, MAX_SIZE)
    min_size = checks.power_of_two(min_size, "--min-size", 1, MAX_SIZE)
    if min_size >= size:
        raise ValueError(f"--min-size must be smaller than --size: the specular chain needs 2 levels; "
                         f"got min size {min_size}, size {size}")
    irradiance_size = checks.integer(irradiance_size, "irradiance size", 1, 1024)
    lut_size = checks.integer(lut_size, "LUT size", 2, 1024)
    if specular_format not in SPECULAR_FORMATS:
        raise ValueError(f"unknown format {specular_format!r}; use one of {', '.join(SPECULAR_FORMATS)}")
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    if sh_window not in (None, "hanning", "lanczos"):
        raise ValueError(f"unknown SH window {sh_window!r}; use hanning or lanczos (or none)")
    return size, min_size, irradiance_size, lut_size


def _sha256(path):
    """SHA-256 of the source file ``path``: a regular file only
    (:func:`pbrkit.core.inputs.open_regular`; a device such as /dev/zero would
    never end), read to its length as it was opened."""
    from ..core.inputs import open_regular
    from ..io.image_checks import IMAGE_EXPECTED, MAX_IMAGE_BYTES

    digest = hashlib.sha256()
    with open_regular(path, MAX_IMAGE_BYTES, IMAGE_EXPECTED) as f:
        left = os.fstat(f.fileno()).st_size
        while left > 0:
            block = f.read(min(_CHUNK, left))
            if not block:
                break
            digest.update(block)
            left -= len(block)
    return digest.hexdigest()


# --------------------------------------------------------------------- bake


#: Level curves other than the generic "linear" one that a bake can add
#: (:data:`pbrkit.ibl.prefilter.LEVEL_CURVES`), for engine targets.
EXTRA_CHAINS = ("filament", "babylon")


def _stage_names(levels, chains=(), sheen=True):
    return (["load", "cube", "sh", "split", "transform"] + [f"specular m={m}" for m in range(1, levels)]
            + [f"specular {c}" for c in chains] + (["sheen"] if sheen else []) + ["irradiance", "lut"]
            + (["sheen lut"] if sheen else []))


def _check_chains(chains):
    chains = tuple(dict.fromkeys(chains or ()))
    for c in chains:
        if c not in EXTRA_CHAINS:
            raise ValueError(f"chains must be among {', '.join(EXTRA_CHAINS)}, got {c!r}")
    return tuple(c for c in EXTRA_CHAINS if c in chains)


def bake(environment, size=256, min_size=16, irradiance_size=32, lut_size=128, *, specular_format="rgba16f",
         method="spectral", sh_window=None, sh_window_width=3.0, fis_samples=None, fis_bias=1.0,
         fix_nonfinite=False, layout=None, chains=(), sheen=True, progress=None, started=None):
    """Bake an environment (module doc) and return a :class:`Bake`.

    ``environment``: a path, a list of six face paths (+X, -X, +Y, -Y, +Z,
    -Z) or a :class:`pbrkit.io.environment.Environment`.  ``size`` (power of two,
    <= 4096) and ``min_size`` (power of two, smaller) set the specular chain
    (M = log2(size / min_size) + 1 levels); ``irradiance_size`` (<= 1024)
    and ``lut_size`` (<= 1024) the other outputs; ``specular_format``
    ``"rgba16f"`` or ``"b10g11r11"`` for the KTX2/DDS files (recorded in the
    manifest); ``method`` ``"spectral"`` (default) or ``"fis"`` (with
    ``fis_samples`` per level and lod ``fis_bias``); ``sh_window`` None,
    ``"hanning"`` or ``"lanczos"`` (:func:`pbrkit.ibl.sh.sh_window`) applied to
    the stored SH; ``fix_nonfinite`` and ``layout`` are passed to
    :func:`pbrkit.io.environment.load_environment`.  ``chains`` adds chains with
    other level curves (:data:`EXTRA_CHAINS`: "filament" for Filament and three.js,
    "babylon" for Babylon.js; :func:`pbrkit.ibl.prefilter.prefilter_chain`) to
    :attr:`Bake.chains`, for :mod:`pbrkit.io.bake_files`' engine targets; they
    need the spectral method.  ``sheen`` false leaves out the sheen chain and
    table (and their manifest entries and files).  ``progress(stage, done,
    total)`` is called after each stage, ``started(stage, number, total)``
    before each (number counts from 1).  Bad input raises ValueError
    (:class:`pbrkit.core.errors.InputError` for files) with a one-line message.
    """
    from ..albedo.sheen_tables import sheen_lut
    from ..albedo.lut import lookup_table
    from ..io.environment import (  # here: io.environment imports pbrkit.ibl
        Environment,
        load_environment,
    )
    from .sh import apply_window, project_cube, project_equirect
    from .sheen import prefilter_charlie
    from .spectral import analyse_equirect

    size, min_size, irradiance_size, lut_size = _check_options(
        size, min_size, irradiance_size, lut_size, specular_format, method, sh_window)
    levels = int(math.log2(size // min_size)) + 1
    chains = _check_chains(chains)
    if chains and method != "spectral":
        raise ValueError(f"engine chains ({', '.join(chains)}) need --method spectral")
    sheen = bool(sheen)
    stages = _stage_names(levels, chains, sheen)
    timings = {}
    clock = [time.perf_counter()]

    def done(stage):
        now = time.perf_counter()
        timings[stage] = now - clock[0]
        clock[0] = now
        if progress is not None:
            progress(stage, len(timings), len(stages))
        if started is not None and len(timings) < len(stages):
            started(stages[len(timings)], len(timings) + 1, len(stages))

    if started is not None:
        started(stages[0], 1, len(stages))

    if isinstance(environment, Environment):
        env = environment
    else:
        env = load_environment(environment if isinstance(environment, (str, Path)) else list(environment),
                               fix_nonfinite=fix_nonfinite, layout=layout)
    files = []
    for p in env.source:
        entry = {"name": Path(p).name}
        if Path(p).is_file():
            entry["sha256"] = _sha256(p)
        files.append(entry)
    done("load")

    level0 = env.to_cube(size).astype(np.float32)
    done("cube")

    if env.equirect is not None:
        sh = project_equirect(_reduce_rows(env.equirect, 1024))
    else:
        sh = project_cube(env.cube)
    if sh_window is not None:
        sh = apply_window(sh, sh_window, sh_window_width)
    done("sh")

    if env.equirect is not None:
        highlights = equirect_highlights(env.equirect)
        resolution = [int(env.equirect.shape[1]), int(env.equirect.shape[0])]
    else:
        highlights = cube_highlights(env.cube)
        resolution = [int(env.cube.shape[1])] * 2
    threshold = highlights.threshold
    if method == "spectral":
        alpha1 = float(alpha_from_roughness(1.0 / (levels - 1)))  # the narrowest lobe, level 1
        # |lambda_l| < 1e-6 from about 7.7 / alpha on; a rough level 1 (chains of 2 or 3 levels) has an
        # algebraic tail instead, cut at 8 / alpha + 64 (and twice the size) where it is below 1e-4
        lmax = band_limit(alpha1, lmax_cap=max(64, min(2 * size, int(8.0 / alpha1) + 64)))
    else:
        lmax = 64  # the transform serves the irradiance map only
    if env.equirect is not None:
        bounded = _analysis_grid(env.equirect, lmax, threshold)
    else:
        bounded = _analysis_grid(cube_to_equirect(np.minimum(env.cube, threshold), 4 * lmax), lmax)
    done("split")
    coeffs = analyse_equirect(bounded, lmax)
    transform = dict(band_limit=lmax, band_limit_tolerance=BAND_LIMIT_TOLERANCE,
                     analysis_grid=[int(bounded.shape[1]), int(bounded.shape[0])])
    del bounded
    done("transform")
    extra = {}
    if method == "spectral":
        chain, info = prefilter_spectral(coeffs, highlights, size, levels,
                                         progress=lambda m: done(f"specular m={m}"))
        shared = {}
        for curve in chains:
            sizes, rough = chain_roughness(curve, size, min_size)
            levels_c, info_c = prefilter_chain(coeffs, highlights, level0, sizes, rough, shared=shared)
            extra[curve] = Chain(curve, [level0] + levels_c, rough,
                                 [{k: _plain(v) for k, v in e.items()} for e in info_c])
            done(f"specular {curve}")
    else:
        from .equirect import equirect_to_cube

        transform["used_for"] = "irradiance only"
        if env.equirect is not None:
            bounded_cube = equirect_to_cube(np.minimum(env.equirect, np.float32(threshold)), size)
        else:
            bounded_cube = resample_cube(np.minimum(env.cube, threshold), size)
        counts = default_sample_counts(levels) if fis_samples is None else [int(k) for k in fis_samples]
        chain, info = prefilter_fis(bounded_cube, levels, counts, fis_bias, highlights,
                                    progress=lambda m: done(f"specular m={m}"))
        del bounded_cube
    sheen_chain, sheen_roughness, sheen_info = prefilter_charlie(level0, levels) if sheen else ([], None, None)
    if sheen:
        done("sheen")
    irradiance, irr_info = irradiance_spectral(coeffs, highlights, irradiance_size)
    del coeffs
    done("irradiance")

    lut, spec = lookup_table("dfg", lut_size)
    done("lut")
    sheen_table, sheen_spec = sheen_lut(lut_size) if sheen else (None, None)
    if sheen:
        done("sheen lut")

    specular = [level0] + chain
    roughness = np.array([roughness_of_level(m, levels) for m in range(levels)])
    options = dict(size=size, min_size=min_size, levels=levels, irradiance_size=irradiance_size,
                   lut_size=lut_size, format=specular_format, method=method, sh_window=sh_window,
                   sh_window_width=float(sh_window_width) if sh_window else None,
                   fix_nonfinite=bool(fix_nonfinite), layout=env.layout)
    if method == "fis":
        options.update(fis_samples=[int(k) for k in counts], fis_bias=float(fis_bias))
    level_info = [dict(level=0, size=size, roughness=0.0, method="the environment resampled (exact area-weighted)")]
    level_info += [{k: _plain(v) for k, v in entry.items()} for entry in info]
    manifest = _manifest(files, env, resolution, options, level_info, transform, highlights, irr_info, sh,
                         spec, levels, size, irradiance_size, lut_size, specular_format, method, sh_window,
                         sh_window_width)
    if sheen:
        manifest["outputs"].update(_sheen_outputs(sheen_chain, sheen_roughness, sheen_info, sheen_spec,
                                                  specular_format))
    return Bake(specular=specular, roughness=roughness, irradiance=irradiance, sh=np.asarray(sh, dtype=np.float64),
                lut=lut, manifest=manifest, timings=timings, chains=extra, sheen=sheen_chain,
                sheen_roughness=sheen_roughness, sheen_lut=sheen_table)


def _reduce_rows(image, rows):
    """``image`` halved (:func:`pbrkit.ibl.spectral.halve_equirect`, integral
    preserving) while it has more than ``rows`` rows (and an even count)."""
    from .spectral import halve_equirect

    while image.shape[0] > rows and image.shape[0] % 2 == 0:
        image = halve_equirect(image)
    return image


def _analysis_grid(image, lmax, clip=None):
    """The equirect image min(image, clip) to analyse to degree ``lmax``:
    halved (:func:`pbrkit.ibl.spectral.halve_equirect`, integral-preserving,
    clamping band by band) while it keeps at least 4 L rows, or its pixels
    repeated 2^k times (the same piecewise-constant function) until it has
    more than 2 L rows."""
    from .spectral import halve_equirect

    if image.shape[0] % 2 == 0 and image.shape[0] // 2 >= 4 * lmax:
        image = halve_equirect(image, clip=clip)
    elif clip is not None:
        image = np.minimum(image, np.asarray(clip, dtype=image.dtype))
    while image.shape[0] % 2 == 0 and image.shape[0] // 2 >= 4 * lmax:
        image = halve_equirect(image)
    if image.shape[0] <= 2 * lmax:
        k = 1 << int(math.ceil(math.log2((2 * lmax + 2) / image.shape[0])))
        image = np.repeat(np.repeat(image, k, axis=0), k, axis=1)
    return image


def _plain(value):
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.floating,)):
        return float(value)
    return value


def _conventions(levels, sh_window, sh_window_width):
    from .sh import COSINE_LOBE_COEFFICIENTS

    return {
        "frame": "right-handed world space, +Y up (glTF); directions are unit vectors (x, y, z)",
        "colour": "linear Rec.709 / sRGB primaries in every float file; preview.png is tone-mapped and "
                  "sRGB-encoded",
        "cube_map": {
            "face_order": list(FACE_NAMES),
            "face_file_names": list(FACE_FILE_NAMES),
            "texel": "texel (row i, column j) of an N x N face: s = (j + 0.5) / N, t = (i + 0.5) / N, "
                     "sc = 2 s - 1, tc = 2 t - 1",
            "directions": {"+X": "(1, -tc, -sc)", "-X": "(-1, -tc, sc)", "+Y": "(sc, 1, tc)",
                           "-Y": "(sc, -1, -tc)", "+Z": "(sc, -tc, 1)", "-Z": "(-sc, -tc, -1)"},
            "directions_note": "normalised; OpenGL 4.6 core profile table 8.19, as KTX2, DDS and Vulkan sample",
            "row_0": "t = 0: the first row stored in KTX2, DDS and EXR files",
            "mirrored": False,
        },
        "equirect": "H x 2H image, row 0 at +Y; pixel (i, j) centre theta = pi (i + 0.5) / H from +Y, "
                    "phi = 2 pi (j + 0.5) / W - pi, d = (sin theta cos phi, cos theta, sin theta sin phi); "
                    "u = 0.5 + atan2(d.z, d.x) / (2 pi), v = acos(d.y) / pi",
        "sh": {
            "basis": "real spherical harmonics, bands l = 0..2, orthonormal, on world (x, y, z) "
                     "(Ramamoorthi & Hanrahan 2001, eq. 3; no Condon-Shortley phase)",
            "order": ["(0,0)", "(1,-1)", "(1,0)", "(1,1)", "(2,-2)", "(2,-1)", "(2,0)", "(2,1)", "(2,2)"],
            "functions": ["0.282095", "0.488603 y", "0.488603 z", "0.488603 x", "1.092548 x y", "1.092548 y z",
                          "0.315392 (3 z^2 - 1)", "1.092548 x z", "0.546274 (x^2 - y^2)"],
            "coefficients": "radiance L_lm = integral of L(w) Y_lm(w) dw (equirect input: exact integrals over "
                            "the pixels' cells, the image piecewise constant; cube input: sum over the texels "
                            "weighted by their exact solid angles); rows of 'sh' are the 9 coefficients, "
                            "columns R, G, B",
            "irradiance": "E(n) = sum_lm A_l L_lm Y_lm(n) with A_l = (%r, %r, %r)" % COSINE_LOBE_COEFFICIENTS,
            "window": None if sh_window is None else {
                "kind": sh_window, "width": float(sh_window_width),
                "reference": "Sloan 2008, Stupid Spherical Harmonics (SH) Tricks",
                "applied_to_stored_coefficients": True},
        },
        "roughness": "perceptual roughness r in [0, 1]; GGX alpha = max(r^2, 1e-3)",
        "roughness_of_level": "r = m / (M - 1) for level m of M = %d" % levels,
        "level_of_roughness": "lod = r (M - 1), sampled with trilinear filtering",
        "specular": "split-sum prefiltered radiance (Karis 2013) with n = v = r: integral of L(l) D_GGX(h) (n.l) dl "
                    "divided by the integral of D_GGX(h) (n.l) dl over n.l > 0, h = normalize(n + l)",
        "irradiance": "E(n) = integral of L(l) max(0, n.l) dl (not divided by pi): radiance 1 everywhere gives pi; "
                      "Lambertian radiance is albedo / pi * E",
        "split_sum": "specular = prefiltered(n, lod) * (DFG1 + F0 (DFG2 - DFG1)), DFG from brdf_lut at "
                     "(n.v, r) (texel centres, clamp to edge)",
    }


def _manifest(files, env, resolution, options, level_info, transform, highlights, irr_info, sh, lut_spec,
              levels, size, irradiance_size, lut_size, specular_format, method, sh_window, sh_window_width):
    ktx_format, dds_format = SPECULAR_FORMATS[specular_format]
    method_text = {
        "spectral": "levels >= 1 and irradiance: the bounded part min(L, T) convolved exactly in the spherical-"
                    "harmonic domain (Funk-Hecke), series cut where |lambda_l| < %g, synthesised on an equirect "
                    "grid and interpolated (Keys cubic) at texel centres; pixels above T summed exactly as "
                    "points (energy-weighted centroids per output texel)" % BAND_LIMIT_TOLERANCE,
        "fis": "levels >= 1: filtered importance sampling (Krivanek & Colbert 2008) of the bounded part's "
               "solid-angle-weighted mip pyramid with Hammersley GGX samples, lod = 0.5 log2(Omega_s / Omega_p) "
               "+ bias, weights n.l (Karis 2013); pixels above T summed exactly as points; irradiance as in "
               "the spectral method",
    }[method]
    lut_description = lut_spec.description()
    return {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "pbrkit_version": __version__,
        "input": {"files": files, "layout": env.layout, "resolution": resolution, "notes": list(env.notes)},
        "options": options,
        "conventions": _conventions(levels, sh_window, sh_window_width),
        "method": {
            "name": method,
            "description": method_text,
            "highlight_threshold": float(highlights.threshold),
            "highlight_rule": "T = max(%g x mean radiance, value of the (count + 1)-th brightest pixel), count = "
                              "pixels / 1536 (at least 16)" % HIGHLIGHT_RATIO,
            "highlight_pixels": highlights.count,
            "transform": transform,
        },
        "outputs": {
            "specular": {
                "ktx2": {"path": "specular.ktx2", "format": ktx_format},
                "dds": {"path": "specular.dds", "format": dds_format},
                "faces": {"path": "faces/specular_m{level}_{face}.exr", "format": "OpenEXR float32 RGB, ZIP"},
                "size": size,
                "levels": levels,
                "roughness": [float(roughness_of_level(m, levels)) for m in range(levels)],
                "level_info": level_info,
            },
            "irradiance": {
                "ktx2": {"path": "irradiance.ktx2", "format": ktx_format},
                "dds": {"path": "irradiance.dds", "format": dds_format},
                "faces": {"path": "faces/irradiance_{face}.exr", "format": "OpenEXR float32 RGB, ZIP"},
                "size": irradiance_size,
                "levels": 1,
                "info": {k: _plain(v) for k, v in irr_info.items()},
            },
            "brdf_lut": {
                "ktx2": {"path": "brdf_lut.ktx2", "format": "R16G16_SFLOAT"},
                "npy": {"path": "brdf_lut.npy", "format": "float32 (N, N, 2)"},
                "exr": {"path": "brdf_lut.exr", "format": "OpenEXR float32 RGB (B = 0)"},
                "descriptions": "each file has a .json beside it",
                "size": lut_size,
                "levels": 1,
                "kind": "dfg",
                "description": lut_description,
            },
            "preview": {
                "path": "preview.png",
                "layout": "left to right: specular levels 0..M-1, then irradiance / pi; each a horizontal cross "
                          "(row 1: -X +Z +X -Z, +Y above +Z, -Y below), faces resampled to the preview size",
                "tone_mapping": "exposure 0.18 / log-average luminance of level 0 (Reinhard et al. 2002, eq. 1), "
                                "then x / (1 + x) per channel, sRGB-encoded 8-bit",
            },
        },
        "sh": [[float(v) for v in row] for row in np.asarray(sh, dtype=np.float64)],
    }


def _sheen_outputs(sheen, roughness, info, spec, specular_format):
    """The manifest's ``outputs`` entries of the sheen chain and table."""
    from .sheen import SHEEN_MAX_BASE_SIZE

    ktx_format, dds_format = SPECULAR_FORMATS[specular_format]
    levels = len(sheen)
    return {
        "sheen": {
            "ktx2": {"path": "sheen.ktx2", "format": ktx_format},
            "dds": {"path": "sheen.dds", "format": dds_format},
            "content": "Charlie-prefiltered radiance (KHR_materials_sheen IBL, as the Khronos glTF IBL Sampler's "
                       "charlie filter) with n = v = r: integral of L(l) D_Charlie(h) (n.l) dl divided by the "
                       "integral of D_Charlie(h) (n.l) dl over n.l > 0, h = normalize(n + l); Estevez & Kulla 2017, "
                       "alpha = sheenRoughness^2; level 0 (sheen roughness 0) is that ratio's limit, the mean over "
                       "the horizon circle of n",
            "size": int(sheen[0].shape[1]),
            "size_rule": "min(size, max(%d, 2^(M - 1))), halving per level" % SHEEN_MAX_BASE_SIZE,
            "levels": levels,
            "level_curve": "linear",
            "sheen_roughness_of_level": "r = m / (M - 1) for level m of M = %d (the specular chain's curve and "
                                        "level count)" % levels,
            "level_of_sheen_roughness": "lod = r (M - 1), sampled with trilinear filtering",
            "sheen_roughness": [float(r) for r in roughness],
            "level_info": [{k: _plain(v) for k, v in e.items()} for e in info],
            "shading": "sheen = sheenColor * sheen(n, lod) * E_sheen(n.v, sheenRoughness) from sheen_lut, and the "
                       "layer below scaled by 1 - max3(sheenColor) E_sheen (KHR_materials_sheen albedo scaling)",
        },
        "sheen_lut": {
            "ktx2": {"path": "sheen_lut.ktx2", "format": "R16G16_SFLOAT"},
            "npy": {"path": "sheen_lut.npy", "format": "float32 (N, N, 2)"},
            "descriptions": "each file has a .json beside it",
            "size": int(spec.size),
            "levels": 1,
            "kind": spec.kind,
            "description": spec.description(),
        },
    }


# -------------------------------------------------------------------- preview


def tone_map(image, exposure):
    """Reinhard et al. 2002 ("Photographic Tone Reproduction for Digital
    Images", eq. 3 simple operator) per channel: x / (1 + x) with
    x = exposure * L (exposure > 0), by :func:`pbrkit.core.color.tonemap_reinhard`;
    linear output in [0, 1) (encode with sRGB)."""
    return tonemap_reinhard(np.asarray(image, dtype=np.float64) * exposure)


def _log_average_luminance(cube):
    """exp(solid-angle-weighted mean of log(1e-4 + Y)), Y = Rec.709 luminance
    (:func:`pbrkit.core.color.luminance`; Reinhard et al. 2002, eq. 1)."""
    c = np.asarray(cube, dtype=np.float64)
    y = luminance(c)
    omega = cube_texel_solid_angles(c.shape[1])
    return float(np.exp(np.sum(omega * np.log(1e-4 + np.maximum(y, 0.0))) / np.sum(omega)))


def _resize_cube(cube, size):
    n = cube.shape[1]
    if n == size:
        return np.asarray(cube, dtype=np.float64)
    if n > size:
        return resample_cube(cube, size)
    k = size // n
    return np.repeat(np.repeat(np.asarray(cube, dtype=np.float64), k, axis=1), k, axis=2)


def preview_strip(bake_result, face_size=64, gap=4):
    """The preview image (3 F, (M + 1) (4 F + gap) - gap, 3) in [0, 1)
    linear (module doc): each specular level and the irradiance / pi as a
    horizontal cross of faces resampled to F = ``face_size`` (a power of
    two), tone-mapped with one exposure."""
    exposure = 0.18 / max(_log_average_luminance(bake_result.specular[0]), 1e-12)
    panels = [_resize_cube(level, face_size) for level in bake_result.specular]
    panels.append(_resize_cube(np.asarray(bake_result.irradiance, dtype=np.float64) / math.pi, face_size))
    crosses = [tone_map(cube_to_cross(p, "hcross"), exposure) for p in panels]
    height, width = crosses[0].shape[:2]
    out = np.zeros((height, len(crosses) * (width + gap) - gap, 3))
    for k, c in enumerate(crosses):
        out[:, k * (width + gap):k * (width + gap) + width] = c
    return out


