"""pbrkit.io.gltf_writer: material ``extensions`` with ``extensionsUsed`` /
``extensionsRequired`` and the optional perspective camera (glTF 2.0 sec. 3.10, 3.12,
5.12), read back by an independent reader (pygltflib) and by pbrkit's glTF loader."""

from __future__ import annotations

import json
import math
import struct

import numpy as np
import pygltflib
import pytest

from pbrkit.io.gltf_writer import GltfCamera, GltfPrimitive, glb_bytes, write_glb
from pbrkit.render.gltf import load_gltf

QUAD = {"positions": np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]),
        "normals": np.tile([0.0, 0.0, 1.0], (4, 1)), "indices": np.array([[0, 1, 2], [1, 3, 2]])}
COAT = {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5, "clearcoatRoughnessFactor": np.float32(0.25)},
        "KHR_materials_ior": {"ior": 2.0}}
SPECULAR = {"KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": np.array([1.0, 0.5, 2.0])}}


def _json(data):
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A
    return json.loads(data[20:20 + length])


def test_material_extensions_and_extensions_used(tmp_path):
    prims = [GltfPrimitive(**QUAD, name="coat", extensions=COAT, emissive=(0.5, 0.25, 0.0)),
             GltfPrimitive(**QUAD, name="plain"),
             GltfPrimitive(**QUAD, name="spec", extensions=SPECULAR)]
    path = tmp_path / "m.glb"
    write_glb(path, prims, extensions_required=["KHR_materials_ior"])
    gltf = pygltflib.GLTF2().load(str(path))
    assert gltf.extensionsUsed == ["KHR_materials_clearcoat", "KHR_materials_ior", "KHR_materials_specular"]
    assert gltf.extensionsRequired == ["KHR_materials_ior"]
    assert gltf.materials[0].extensions == {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5,
                                                                        "clearcoatRoughnessFactor": 0.25},
                                            "KHR_materials_ior": {"ior": 2.0}}
    assert gltf.materials[0].emissiveFactor == [0.5, 0.25, 0.0]
    assert not gltf.materials[1].extensions and gltf.materials[1].emissiveFactor in (None, [0.0, 0.0, 0.0])
    assert gltf.materials[2].extensions["KHR_materials_specular"]["specularColorFactor"] == [1.0, 0.5, 2.0]
    asset = load_gltf(path)  # pbrkit's reader: the factors become the gltf model's parameters
    coat, plain, spec = (m.spec for m in asset.materials)
    assert (coat.clearcoat, coat.clearcoat_roughness, coat.ior) == (0.5, 0.25, 2.0)
    assert tuple(coat.emissive) == (0.5, 0.25, 0.0)
    assert plain.clearcoat == 0.0 and plain.ior == 1.5
    assert spec.specular == 0.5 and tuple(spec.specular_color) == (1.0, 0.5, 2.0)
    assert path.read_bytes() == glb_bytes(prims, extensions_required=["KHR_materials_ior"])


def test_no_extensions_writes_no_extensions_used():
    doc = _json(glb_bytes([GltfPrimitive(**QUAD)]))
    assert "extensionsUsed" not in doc and "extensionsRequired" not in doc and "cameras" not in doc
    assert "extensions" not in doc["materials"][0] and doc["nodes"] == [{"mesh": 0}]
    assert "emissiveFactor" not in doc["materials"][0]


def test_camera_node():
    camera = GltfCamera(yfov=math.radians(30.0), aspect_ratio=2.0, znear=0.1, zfar=50.0, translation=(0.0, 0.5, 6.0))
    data = glb_bytes([GltfPrimitive(**QUAD)], camera=camera)
    doc = _json(data)
    assert doc["cameras"] == [{"type": "perspective", "perspective": {"yfov": math.radians(30.0), "aspectRatio": 2.0,
                                                                     "znear": 0.1, "zfar": 50.0}}]
    assert doc["nodes"][1] == {"camera": 0, "translation": [0.0, 0.5, 6.0], "rotation": [0.0, 0.0, 0.0, 1.0]}
    assert doc["scenes"] == [{"nodes": [0, 1]}]
    infinite = _json(glb_bytes([GltfPrimitive(**QUAD)], camera=GltfCamera(yfov=1.0)))["cameras"][0]["perspective"]
    assert infinite == {"yfov": 1.0, "znear": 0.01}


@pytest.mark.parametrize("kwargs, message", [
    ({"extensions": {"KHR_materials_ior": {"ior": float("nan")}}}, r"KHR_materials_ior\.ior must be finite"),
    ({"extensions": {"KHR_materials_ior": 1.5}}, "must be an object"),
    ({"extensions": ["KHR_materials_ior"]}, "must be a dict"),
    ({"extensions": {"KHR_materials_ior": {"ior": object()}}}, "must be JSON"),
    ({"extensions": {"KHR_materials_ior": {1: 2.0}}}, "keys must be strings"),
    ({"emissive": (0.5, 2.0, 0.0)}, "emissive"),
    ({"emissive": (0.5, 0.5)}, "emissive"),
])
def test_bad_extensions_are_refused_and_nothing_is_written(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        write_glb(tmp_path / "bad.glb", [GltfPrimitive(**QUAD, **kwargs)])
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("kwargs, message", [
    ({"camera": GltfCamera(yfov=0.0)}, "yfov"),
    ({"camera": GltfCamera(yfov=1.0, znear=0.0)}, "znear"),
    ({"camera": GltfCamera(yfov=1.0, znear=1.0, zfar=0.5)}, "zfar"),
    ({"camera": GltfCamera(yfov=1.0, aspect_ratio=-1.0)}, "aspect_ratio"),
    ({"camera": GltfCamera(yfov=1.0, rotation=(0.0, 0.0, 0.0, 2.0))}, "unit quaternion"),
    ({"camera": GltfCamera(yfov=1.0, translation=(0.0, 1.0))}, "translation"),
    ({"extensions_required": ["KHR_materials_sheen"]}, "not used by any material"),
])
def test_bad_camera_or_required_is_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        glb_bytes([GltfPrimitive(**QUAD)], **kwargs)
