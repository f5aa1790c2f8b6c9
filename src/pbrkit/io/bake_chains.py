"""The KTX2 files of a bake's generic chains: ``specular.ktx2`` (the split-sum
chain, r = m / (M - 1)) and ``sheen.ktx2`` (the Charlie-prefiltered chain), each
with its ``pbrkit.bake`` key.  Written here once for the generic files
(:mod:`pbrkit.io.bake_files`) and for the Khronos target, which loads the same
files (:mod:`pbrkit.engines.khronos`)."""

from __future__ import annotations

import json

from ..ibl.bake import SPECULAR_FORMATS
from .ktx2 import write_ktx2

__all__ = ["bake_formats", "write_specular_ktx2", "write_sheen_ktx2"]


def bake_formats(b):
    """(KTX2 format, DDS format) of the bake's ``--format`` (:data:`pbrkit.ibl.bake.SPECULAR_FORMATS`)."""
    return SPECULAR_FORMATS[b.manifest["options"]["format"]]


def write_specular_ktx2(path, b):
    """The bake's specular chain as a cube KTX2 with every level, in its format, with
    the roughness of each level in its key."""
    roughness = [float(r) for r in b.roughness]
    key = {"pbrkit.bake": json.dumps({"roughness": roughness, "roughness_of_level": "r = m / (M - 1)",
                                      "content": "split-sum prefiltered radiance (GGX, n = v = r)"})}
    write_ktx2(path, b.specular, bake_formats(b)[0], cube=True, key_values=key)


def write_sheen_ktx2(path, b):
    """The bake's sheen chain as a cube KTX2 with every level, in its format, with the
    sheen roughness of each level (its manifest's) in its key."""
    entry = b.manifest["outputs"]["sheen"]
    key = {"pbrkit.bake": json.dumps({"sheen_roughness": entry["sheen_roughness"],
                                      "sheen_roughness_of_level": "r = m / (M - 1)",
                                      "content": "Charlie-prefiltered radiance (n = v = r)"})}
    write_ktx2(path, b.sheen, bake_formats(b)[0], cube=True, key_values=key)
