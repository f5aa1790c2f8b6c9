"""The files of an image-based-lighting bake (:mod:`pbrkit.ibl.bake`).

:func:`write_bake` writes a directory (into a temporary directory beside it,
renamed into place at the end, so a failure leaves nothing behind)::

    manifest.json                      what is below and every convention
    specular.ktx2, specular.dds        cube map, all levels
    irradiance.ktx2, irradiance.dds    cube map, one level
    brdf_lut.ktx2, .npy, .exr          the DFG table (+ .json descriptions)
    faces/specular_m{m}_{px|nx|py|ny|pz|nz}.exr, faces/irradiance_{face}.exr
    preview.png                        every level as a tone-mapped cross

and :func:`load_bake` reads it back.  Same input and options, same bytes:
nothing time- or machine-dependent is written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_directory
from ..ibl.bake import (
    FACE_FILE_NAMES,
    FORMAT,
    SPECULAR_FORMATS,
    Bake,
    preview_strip,
)

__all__ = [
    "write_bake",
    "load_bake",
]

# ---------------------------------------------------------------------- write


def _face_path(kind, face, level=None):
    name = FACE_FILE_NAMES[face]
    return f"faces/specular_m{level}_{name}.exr" if kind == "specular" else f"faces/irradiance_{name}.exr"


def _write_all(root, b, progress):
    from ..albedo.tables import TableSpec
    from .dds import write_dds
    from .exr import write_exr
    from .ktx2 import write_ktx2
    from .lut_files import write_lut
    from .png import write_png

    manifest = b.manifest
    fmt = manifest["options"]["format"]
    ktx_format, dds_format = SPECULAR_FORMATS[fmt]
    steps = ["specular.ktx2", "specular.dds", "irradiance", "brdf_lut", "faces", "preview", "manifest"]
    count = [0]

    def step(name):
        count[0] += 1
        if progress is not None:
            progress(f"write {name}", count[0], len(steps))

    roughness = [float(r) for r in b.roughness]
    key = {"pbrkit.bake": json.dumps({"roughness": roughness, "roughness_of_level": "r = m / (M - 1)",
                                      "content": "split-sum prefiltered radiance (GGX, n = v = r)"})}
    write_ktx2(root / "specular.ktx2", b.specular, ktx_format, cube=True, key_values=key)
    step("specular.ktx2")
    write_dds(root / "specular.dds", b.specular, dds_format, cube=True)
    step("specular.dds")
    key = {"pbrkit.bake": json.dumps({"content": "irradiance E(n), constant radiance 1 gives pi"})}
    write_ktx2(root / "irradiance.ktx2", [b.irradiance], ktx_format, cube=True, key_values=key)
    write_dds(root / "irradiance.dds", [b.irradiance], dds_format, cube=True)
    step("irradiance")
    desc = manifest["outputs"]["brdf_lut"]["description"]
    spec = TableSpec(desc["kind"], int(desc["size"][0]), desc["visibility"], bool(desc["cloth"]),
                     (desc["integration"]["theta_nodes_per_segment"],
                      desc["integration"]["theta_nodes_per_segment_grazing_nv_below_0.0625"],
                      desc["integration"]["phi_nodes"]))
    for suffix in (".ktx2", ".npy", ".exr"):
        write_lut(root / f"brdf_lut{suffix}", b.lut, spec)
    step("brdf_lut")
    (root / "faces").mkdir()
    for m, level in enumerate(b.specular):
        for f in range(6):
            write_exr(root / _face_path("specular", f, m), level[f])
    for f in range(6):
        write_exr(root / _face_path("irradiance", f), b.irradiance[f])
    step("faces")
    write_png(root / "preview.png", preview_strip(b), bits=8, srgb=True)
    step("preview")
    (root / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    step("manifest")


def write_bake(bake_result, out_dir, force=False, progress=None):
    """Write ``bake_result`` to the directory ``out_dir`` (module doc).

    The files are written into a temporary directory beside ``out_dir``,
    which is renamed to ``out_dir`` only when everything succeeded; any
    failure removes it (and any parent directories this call created), so
    no partial output remains (:func:`pbrkit.core.atomic.atomic_directory`).
    An existing non-empty ``out_dir`` is refused unless ``force``, which
    replaces it.  ``progress(step, done, total)`` after each group of files.
    Returns the output path."""
    with atomic_directory(out_dir, force) as tmp:
        _write_all(tmp, bake_result, progress)
    return Path(out_dir)


# ----------------------------------------------------------------------- load


def load_bake(out_dir, prefer="exr"):
    """Read a directory written by :func:`write_bake` into a :class:`Bake`.

    ``prefer`` ``"exr"`` reads the float32 face files (exactly what was
    baked); ``"ktx2"`` reads specular.ktx2 / irradiance.ktx2 (float16 or
    B10G11R11, as written).  The SH come from the manifest and the table from
    brdf_lut.npy.  Missing or inconsistent files raise ValueError."""
    from ..core.errors import InputError
    from .images import read_image
    from .ktx2 import read_ktx2

    root = Path(out_dir)
    if prefer not in ("exr", "ktx2"):
        raise ValueError(f"prefer must be 'exr' or 'ktx2', got {prefer!r}")
    path = root / "manifest.json"
    try:
        manifest = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(f"cannot read the manifest ({exc.strerror or exc})", path) from None
    except json.JSONDecodeError as exc:
        raise InputError(f"manifest is not valid JSON ({exc.msg} at line {exc.lineno})", path) from None
    if manifest.get("format") != FORMAT:
        raise InputError(f"not a pbrkit bake manifest (format {manifest.get('format')!r})", path)
    spec_out = manifest["outputs"]["specular"]
    levels, size = int(spec_out["levels"]), int(spec_out["size"])
    irr_size = int(manifest["outputs"]["irradiance"]["size"])
    if prefer == "exr":
        specular = [np.stack([read_image(root / _face_path("specular", f, m)) for f in range(6)])
                    for m in range(levels)]
        irradiance = np.stack([read_image(root / _face_path("irradiance", f)) for f in range(6)])
    else:
        _, spec_levels, _ = read_ktx2(root / "specular.ktx2")
        _, irr_levels, _ = read_ktx2(root / "irradiance.ktx2")
        specular = [np.ascontiguousarray(level[..., :3]) for level in spec_levels]
        irradiance = np.ascontiguousarray(irr_levels[0][..., :3])
    if len(specular) != levels:
        raise InputError(f"specular chain has {len(specular)} levels, the manifest says {levels}", root)
    for m, level in enumerate(specular):
        n = size >> m
        if level.shape != (6, n, n, 3):
            raise InputError(f"specular level {m} has shape {level.shape}, expected {(6, n, n, 3)}", root)
    if irradiance.shape != (6, irr_size, irr_size, 3):
        raise InputError(f"irradiance has shape {irradiance.shape}, expected {(6, irr_size, irr_size, 3)}", root)
    try:
        lut = np.load(root / "brdf_lut.npy", allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the table ({exc})", root / "brdf_lut.npy") from None
    sh = np.asarray(manifest["sh"], dtype=np.float64)
    if sh.shape != (9, 3):
        raise InputError(f"'sh' has shape {sh.shape}, expected (9, 3)", path)
    return Bake(specular=[np.asarray(s, dtype=np.float32) for s in specular],
                roughness=np.asarray(spec_out["roughness"], dtype=np.float64),
                irradiance=np.asarray(irradiance, dtype=np.float32), sh=sh, lut=np.asarray(lut, dtype=np.float32),
                manifest=manifest)

