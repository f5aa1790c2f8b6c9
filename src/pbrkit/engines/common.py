"""What the engines' target writers share: the manifest's key-value entry, the
roughness list, the chain a target needs from the bake, the bake's table spec and
the JavaScript modules pbrkit ships."""

from __future__ import annotations

import json
from pathlib import Path

from ..albedo.lut import TableSpec

__all__ = ["JS_DIR", "bake_key", "roughness_list", "target_chain", "lut_spec"]

#: The JavaScript modules pbrkit ships (``pbrkit/js``), copied into the targets that load through them.
JS_DIR = Path(__file__).resolve().parent.parent / "js"


def bake_key(target, **fields):
    """The ``pbrkit.bake`` key-value entry of a target's texture file: JSON of the
    target's name and ``fields``."""
    return {"pbrkit.bake": json.dumps(dict(target=target, **fields))}


def roughness_list(chain):
    """The perceptual roughness of every level of ``chain``, rounded for the manifest."""
    return [round(float(r), 12) for r in chain.roughness]


def target_chain(b, target, curve):
    """The bake's chain with level curve ``curve`` (:attr:`pbrkit.ibl.bake.Bake.chains`)
    that target ``target`` writes; ValueError when the bake has none."""
    chain = b.chains.get(curve)
    if chain is None:
        raise ValueError(f"target {target!r} needs the bake's {curve!r} chain: bake with "
                         f"chains=chains_for(targets) (pbrkit bake --target does)")
    return chain


def lut_spec(b):
    """The :class:`pbrkit.albedo.lut.TableSpec` of the bake's DFG table, read from
    its manifest (``outputs.brdf_lut.description``)."""
    desc = b.manifest["outputs"]["brdf_lut"]["description"]
    return TableSpec(desc["kind"], int(desc["size"][0]), desc["visibility"], bool(desc["cloth"]),
                     (desc["integration"]["theta_nodes_per_segment"],
                      desc["integration"]["theta_nodes_per_segment_grazing_nv_below_0.0625"],
                      desc["integration"]["phi_nodes"]))
