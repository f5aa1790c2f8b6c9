"""Writing and reading lookup-table files (``pbrkit lut``).

Every table file ``NAME.ext`` is written atomically together with its
description ``NAME.ext.json`` (both or neither) (:meth:`pbrkit.albedo.table_spec.TableSpec.description`);
KTX2 files also embed it under the key ``pbrkit.lut`` and C headers in a
comment.  Formats by suffix:

- ``.npy``: float32 (N, N, C), exactly the table.
- ``.exr``: float32 OpenEXR, channels R, G (, B = cloth); two-channel tables
  get B = 0 because RGB is what image tools expect.
- ``.png``: 16-bit linear RGB (no sRGB curve), B = 0 for two channels;
  quantised to 1/65535 (a warning says so).
- ``.h``: C/C++ header of IEEE float16 bit patterns, row 0 (smooth) first,
  ready for ``glTexImage2D(..., GL_RG16F, N, N, 0, GL_RG, GL_HALF_FLOAT, data)``
  or a ``VK_FORMAT_R16G16_SFLOAT`` buffer copy: GL and Vulkan both take the first
  row in memory as t = 0, so ``texture(lut, vec2(NoV, roughness))`` reads texel
  centres exactly as CONVENTIONS.md defines them.
- ``.ktx2``: 2D texture, ``R16G16_SFLOAT`` (default) or ``R32G32_SFLOAT``; a
  three-channel (cloth) table is stored as ``R16G16B16A16_SFLOAT`` /
  ``R32G32B32A32_SFLOAT`` with A = 1.
"""

from __future__ import annotations

import io
import json
import re
import warnings
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_group

__all__ = ["LUT_SUFFIXES", "write_lut", "header_text", "parse_header", "QuantisationWarning"]

LUT_SUFFIXES = (".npy", ".exr", ".png", ".h", ".ktx2")


class QuantisationWarning(UserWarning):
    """An output format stores fewer bits than the table has."""


def _rgb(table):
    if table.shape[-1] == 3:
        return table
    return np.concatenate([table, np.zeros(table.shape[:-1] + (1,), table.dtype)], axis=-1)


def _identifier(spec):
    return f"PBRKIT_{spec.kind.upper()}{'_CLOTH' if spec.cloth else ''}_LUT"


def header_text(table, spec):
    """C/C++ header holding the table as float16 bit patterns (row-major, row 0 first)."""
    table = np.asarray(table, dtype=np.float32)
    n_rows, n_cols, channels = table.shape
    bits = table.astype(np.float16).view(np.uint16).reshape(-1)
    name = _identifier(spec)
    gl = {2: ("GL_RG16F", "GL_RG"), 3: ("GL_RGB16F", "GL_RGB")}[channels]
    description = json.dumps(spec.description(), indent=1).replace("*/", "* /")
    lines = [
        f"/* pbrkit lookup table '{spec.kind}', {n_cols} x {n_rows}, {channels} channels, IEEE float16 bits.",
        f" * Element [(j * {n_cols} + i) * {channels} + c]: column i at n.v = (i + 0.5) / {n_cols},",
        f" * row j at perceptual roughness r = (j + 0.5) / {n_rows}; row 0 (smooth) first.",
        f" * OpenGL: glTexImage2D(GL_TEXTURE_2D, 0, {gl[0]}, {n_cols}, {n_rows}, 0, {gl[1]}, GL_HALF_FLOAT, {name});",
        " * Vulkan: copy into an image of VK_FORMAT_R16G16_SFLOAT (two channels) row by row.",
        " * Sample with texture(lut, vec2(NoV, roughness)), linear filtering, clamp to edge.",
        " *",
        " * Description:",
        *(" * " + line for line in description.splitlines()),
        " */",
        "#pragma once",
        "#include <stdint.h>",
        "",
        f"#define {name}_WIDTH {n_cols}",
        f"#define {name}_HEIGHT {n_rows}",
        f"#define {name}_CHANNELS {channels}",
        "",
        f"static const uint16_t {name}[{n_rows} * {n_cols} * {channels}] = {{",
    ]
    per_line = 12
    hexes = [f"0x{b:04x}" for b in bits.tolist()]
    for k in range(0, len(hexes), per_line):
        lines.append("    " + ", ".join(hexes[k:k + per_line]) + ",")
    lines.append("};")
    return "\n".join(lines) + "\n"


_ARRAY_RE = re.compile(r"static const uint16_t (\w+)\[(\d+) \* (\d+) \* (\d+)\] = \{(.*?)\};", re.S)


def parse_header(text):
    """Read back a header written by :func:`header_text`: returns the float16 array (N, N, C)."""
    match = _ARRAY_RE.search(text)
    if match is None:
        raise ValueError("no pbrkit lookup-table array found in the header")
    _, rows, cols, channels, body = match.groups()
    values = [int(tok, 16) for tok in re.findall(r"0x[0-9a-fA-F]{4}", body)]
    rows, cols, channels = int(rows), int(cols), int(channels)
    if len(values) != rows * cols * channels:
        raise ValueError(f"header array holds {len(values)} values, expected {rows * cols * channels}")
    return np.array(values, dtype=np.uint16).view(np.float16).reshape(rows, cols, channels)


def write_lut(path, table, spec, ktx2_format="float16"):
    """Write ``table`` (N, N, C) by the suffix of ``path`` and its ``.json`` description.

    ``ktx2_format``: ``float16`` or ``float32`` for KTX2 output.  The two
    files are committed together (:func:`pbrkit.core.atomic.atomic_group`):
    if either cannot be written, neither is (an existing pair is left as it
    was).  Returns the list of paths written.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in LUT_SUFFIXES:
        raise ValueError(f"{path}: unsupported table format {suffix!r}; use one of {', '.join(LUT_SUFFIXES)}")
    if ktx2_format not in ("float16", "float32"):
        raise ValueError(f"ktx2 format must be float16 or float32; got {ktx2_format!r}")
    table = np.ascontiguousarray(table, dtype=np.float32)
    if table.ndim != 3 or table.shape[2] not in (2, 3) or not np.all(np.isfinite(table)):
        raise ValueError("a lookup table is a finite float array (N, N, 2 or 3)")
    description = spec.description()
    description["file_format"] = suffix[1:]
    if suffix == ".npy":
        buffer = io.BytesIO()
        np.save(buffer, table)
        data = buffer.getvalue()
    elif suffix == ".exr":
        from .exr import exr_bytes

        try:
            data = exr_bytes(_rgb(table))
        except TypeError:  # an OpenEXR without stream output: written to the file below
            data = None
        description["exr_channels"] = "R, G" + (", B" if table.shape[2] == 3 else " (B = 0)")
    elif suffix == ".png":
        from .png import png_bytes16

        warnings.warn(f"{path}: 16-bit PNG quantises the table to steps of 1/65535 "
                      "(use .exr, .npy or .ktx2 for float data)", QuantisationWarning, stacklevel=2)
        data = png_bytes16(_rgb(table), srgb=False)
        description["png"] = "16-bit, linear (no sRGB curve), value = code / 65535"
    elif suffix == ".h":
        data = header_text(table, spec).encode("utf-8")
    else:
        from .ktx2 import ktx2_bytes

        if table.shape[2] == 2:
            vk_format = "R16G16_SFLOAT" if ktx2_format == "float16" else "R32G32_SFLOAT"
        else:
            vk_format = "R16G16B16A16_SFLOAT" if ktx2_format == "float16" else "R32G32B32A32_SFLOAT"
        description["vk_format"] = vk_format
        data = ktx2_bytes([table], vk_format, key_values={"pbrkit.lut": json.dumps(description)})
    sidecar = path.with_name(path.name + ".json")
    with atomic_group([path, sidecar]) as (table_tmp, sidecar_tmp):
        if data is None:
            from .exr import write_exr

            write_exr(table_tmp, _rgb(table))
        else:
            table_tmp.write_bytes(data)
        sidecar_tmp.write_text(json.dumps(description, indent=2) + "\n", encoding="utf-8")
    return [path, sidecar]
