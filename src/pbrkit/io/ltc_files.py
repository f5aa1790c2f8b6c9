"""Files of Linearly Transformed Cosines tables in the published layout (issue 11).

The layout is that of Heitz, Dupuy, Hill and Neubelt's tables ("Real-Time
Polygonal-Light Shading with Linearly Transformed Cosines", SIGGRAPH 2016;
``selfshadow/ltc_code``, ``fit/fitLTC.cpp``), which engines ship (three.js
``RectAreaLightUniformsLib``, Babylon.js, Godot, Bevy): two 64 x 64 RGBA float
textures,

- ``ltc_1``: the inverse matrix M^-1 of each cell's LTC, its four non-trivial
  entries normalised by the middle one, (m00, m20, m02, m22) / m11 in the order
  the shaders read them back into ``mat3(vec3(x, 0, y), vec3(0, 1, 0), vec3(z, 0,
  w))``;
- ``ltc_2``: (norm, fresnel, 0, sphere form factor): the directional albedo of the
  lobe with F = 1, its Fresnel part, unused, and the form-factor term of the
  sphere approximation;

where texel (t, a), row t and column a, is perceptual roughness r = a / 63
(alpha = r^2) and view cos(theta) = 1 - (t / 63)^2 (the row coordinate is
sqrt(1 - cos theta) = t / 63), sampled at texel centres uv = p (N - 1)/N + 0.5/N.
Row 0 is first in memory, as the arrays three.js uploads (its ``LTC_MAT_1``,
``LTC_MAT_2``) and as GL / Vulkan take a 2D texture's first row.

:func:`write_ltc_tables` writes, for ``ltc_1`` and ``ltc_2`` each, ``.npy``
(float32 (64, 64, 4)), ``.rgba32f.dds`` / ``.rgba16f.dds`` (DX10 R32G32B32A32_FLOAT /
R16G16B16A16_FLOAT), ``.rgba32f.ktx2`` / ``.rgba16f.ktx2`` (VK R32G32B32A32_SFLOAT
/ R16G16B16A16_SFLOAT), and one ES module ``ltc_tables.js`` that exports the two
arrays under three.js's names and an ``init(THREE)`` that installs them as
three.js's ``RectAreaLightUniformsLib`` does (float and half-float
``DataTexture``s in ``UniformsLib``; its comments name the BRDF the tables are
fitted for, the rest is the same for every table), all together or none
(:func:`pbrkit.core.atomic.atomic_group`).  :func:`read_ltc_npy` reads a table back.

pbrkit's Fresnel-aware LTC (:func:`pbrkit.ltc.shader.ltc_fresnel_rect`) adds a
third table in ``ltc_1``'s layout, ``fresnel_ltc_1``: the matrices of the f Fc
lobe (Fc = (1 - v.h)^5), written in the same formats (:func:`write_fresnel_table`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_group

__all__ = ["LTC_SIZE", "LTC_FILES", "FRESNEL_FILES", "check_ltc_table", "ltc_module_text", "write_ltc_tables",
           "write_fresnel_table", "read_ltc_npy"]

#: Cells per side of the published layout.
LTC_SIZE = 64
_SUFFIXES = {".npy": None, ".rgba32f.dds": "R32G32B32A32_FLOAT", ".rgba16f.dds": "R16G16B16A16_FLOAT",
             ".rgba32f.ktx2": "R32G32B32A32_SFLOAT", ".rgba16f.ktx2": "R16G16B16A16_SFLOAT"}
#: Every file :func:`write_ltc_tables` writes.
LTC_FILES = tuple(f"{name}{suffix}" for name in ("ltc_1", "ltc_2") for suffix in _SUFFIXES) + ("ltc_tables.js",)
#: Every file :func:`write_fresnel_table` writes.
FRESNEL_FILES = tuple(f"fresnel_ltc_1{suffix}" for suffix in _SUFFIXES)


def check_ltc_table(table, name="table"):
    """``table`` as float32 (N, N, 4), finite; ValueError otherwise."""
    t = np.asarray(table, dtype=np.float32)
    if t.ndim != 3 or t.shape[0] != t.shape[1] or t.shape[2] != 4 or t.shape[0] < 2:
        raise ValueError(f"{name} must have shape (N, N, 4), got {np.shape(table)}")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{name} has NaN or infinite entries")
    return np.ascontiguousarray(t)


def _numbers(table):
    return ", ".join(f"{float(x):.9g}" for x in table.reshape(-1))


def ltc_module_text(ltc1, ltc2, note="", brdf=None):
    """The ES module: ``LTC_MAT_1``, ``LTC_MAT_2`` (row-major, row 0 first, as
    three.js's arrays) and ``init(THREE)``, which builds the float and half-float
    textures (RGBA, linear filtering, clamp to edge, no mipmaps) and installs them
    in ``THREE.UniformsLib`` under ``LTC_FLOAT_1``, ``LTC_FLOAT_2``, ``LTC_HALF_1``,
    ``LTC_HALF_2``, as three.js's ``RectAreaLightUniformsLib.init()`` does; call it
    instead of that one.  ``note`` and ``brdf`` (the lobe the tables are for, e.g.
    "GGX D, height-correlated Smith G2, alpha = r^2") are comment lines only: the
    exports are the same for every table."""
    n = ltc1.shape[0]
    lobe = "" if brdf is None else f"// BRDF: {brdf}\n"
    return f"""// pbrkit LTC tables in the published layout (Heitz et al. 2016): {n} x {n} RGBA,
// row t = sqrt(1 - cos theta_v) * {n - 1}, column a = perceptual roughness * {n - 1}.
// LTC_MAT_1: (m00, m20, m02, m22) / m11 of the inverse matrix; LTC_MAT_2: (norm, fresnel, 0, sphere).
{lobe}// {note}
// Usage with three.js: import * as THREE from "three"; import {{ init }} from "./ltc_tables.js";
// init(THREE);  // instead of RectAreaLightUniformsLib.init()
export const LTC_SIZE = {n};
export const LTC_MAT_1 = [{_numbers(ltc1)}];
export const LTC_MAT_2 = [{_numbers(ltc2)}];

function textures(THREE, type, data1, data2) {{
  const make = (data) => {{
    const t = new THREE.DataTexture(data, LTC_SIZE, LTC_SIZE, THREE.RGBAFormat, type, THREE.UVMapping,
      THREE.ClampToEdgeWrapping, THREE.ClampToEdgeWrapping, THREE.LinearFilter, THREE.NearestFilter, 1);
    t.needsUpdate = true;
    return t;
  }};
  return [make(data1), make(data2)];
}}

export function init(THREE) {{
  const [f1, f2] = textures(THREE, THREE.FloatType, new Float32Array(LTC_MAT_1), new Float32Array(LTC_MAT_2));
  const half = (values) => {{
    const out = new Uint16Array(values.length);
    for (let i = 0; i < values.length; i++) out[i] = THREE.DataUtils.toHalfFloat(values[i]);
    return out;
  }};
  const [h1, h2] = textures(THREE, THREE.HalfFloatType, half(LTC_MAT_1), half(LTC_MAT_2));
  THREE.UniformsLib.LTC_FLOAT_1 = f1;
  THREE.UniformsLib.LTC_FLOAT_2 = f2;
  THREE.UniformsLib.LTC_HALF_1 = h1;
  THREE.UniformsLib.LTC_HALF_2 = h2;
  return {{ LTC_FLOAT_1: f1, LTC_FLOAT_2: f2, LTC_HALF_1: h1, LTC_HALF_2: h2 }};
}}
"""


def write_ltc_tables(out_dir, ltc1, ltc2, note="", brdf=None):
    """Write the drop-in files (module doc) of ``ltc1`` and ``ltc2`` ((N, N, 4)
    float, row t, column a) into ``out_dir``; all of them or none; ``note`` and
    ``brdf`` go into the ES module's comments (:func:`ltc_module_text`).  Returns
    the paths."""
    tables = {"ltc_1": check_ltc_table(ltc1, "ltc_1"), "ltc_2": check_ltc_table(ltc2, "ltc_2")}
    if tables["ltc_1"].shape != tables["ltc_2"].shape:
        raise ValueError(f"ltc_1 and ltc_2 differ in shape: {tables['ltc_1'].shape} vs {tables['ltc_2'].shape}")
    module = ltc_module_text(tables["ltc_1"], tables["ltc_2"], note, brdf)
    return _write_tables(out_dir, LTC_FILES, tables, module)


def write_fresnel_table(out_dir, ltc1):
    """Write the Fresnel-aware LTC's second matrix table ``fresnel_ltc_1`` ((N, N, 4),
    ``ltc_1``'s layout) as ``.npy``, ``.rgba32f/16f.dds`` and ``.rgba32f/16f.ktx2``
    (:data:`FRESNEL_FILES`) into ``out_dir``, all or none.  Returns the paths."""
    return _write_tables(out_dir, FRESNEL_FILES, {"fresnel_ltc_1": check_ltc_table(ltc1, "fresnel_ltc_1")})


def _write_tables(out_dir, names, tables, module=None):
    """The files ``names`` of ``tables`` (stem -> array; ``ltc_tables.js`` from
    ``module``) in ``out_dir``, all of them or none."""
    from .dds import write_dds
    from .ktx2 import write_ktx2

    out = Path(out_dir)
    paths = [out / name for name in names]
    with atomic_group(paths) as temps:
        for path, tmp in zip(paths, temps):
            name = path.name
            if name == "ltc_tables.js":
                tmp.write_text(module, encoding="utf-8")
                continue
            stem, suffix = name.split(".", 1)
            fmt = _SUFFIXES["." + suffix]
            table = tables[stem]
            if fmt is None:
                with open(tmp, "wb") as f:
                    np.save(f, table, allow_pickle=False)
            elif suffix.endswith("dds"):
                write_dds(tmp, [table], fmt)
            else:
                write_ktx2(tmp, [table], fmt)
    return paths


def read_ltc_npy(path):
    """A table written by :func:`write_ltc_tables` (``ltc_1.npy`` / ``ltc_2.npy``)
    as float32 (N, N, 4); :class:`~pbrkit.core.errors.InputError` naming the file
    when it is missing, unreadable or not such a table."""
    from ..core.errors import InputError

    from .npy_files import read_npy

    path = Path(path)
    if not os.path.lexists(path):
        raise InputError("no such LTC table", path)
    table = read_npy(path, "an LTC table (.npy, N x N x 4)")  # a regular file, its length what its header says
    try:
        return check_ltc_table(table, "the LTC table")
    except ValueError as exc:
        raise InputError(str(exc), path) from None
