"""pbrkit.io.gltf_writer: material ``extensions`` with ``extensionsUsed`` /
``extensionsRequired`` and the optional perspective camera (glTF 2.0 sec. 3.10, 3.12,
5.12), and embedded PNG textures with their samplers (sec. 3.8), read back by an independent
reader (pygltflib, Pillow) and by pbrkit's glTF loader."""

from __future__ import annotations

import json
import math
import struct

import numpy as np
import pygltflib
import pytest

from pbrkit.io.gltf_writer import GltfCamera, GltfPrimitive, GltfTexture, glb_bytes, write_glb
from pbrkit.rendering.gltf import load_gltf

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


# ------------------------------------------------------------------ textures

UV = np.array([[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]])


def _normal_image():
    """A 4 x 8 RGB tangent-space normal texture of distinct texels (rows top to bottom)."""
    rng = np.random.default_rng(7)
    return rng.integers(0, 256, (4, 8, 3)).astype(np.uint8)


def test_textures_are_embedded_pngs_that_both_readers_load(tmp_path):
    """normalTexture and an extension's textureInfo (clearcoatNormalTexture) name textures
    embedded as PNGs with their samplers: pygltflib reads the document, Pillow decodes the
    PNG to the same texels, pbrkit's loader gives the linear texels (value / 255), the
    sampler's wraps and the scales."""
    import io

    from PIL import Image

    image = _normal_image()
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4) * 20
    coat = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 1, "scale": 0.5}}}
    prim = GltfPrimitive(**QUAD, texcoords=UV, normal_texture={"index": 0, "scale": 0.25}, extensions=coat,
                         tangents=np.tile([1.0, 0.0, 0.0, 1.0], (4, 1)))
    textures = [GltfTexture(image), GltfTexture(grey[..., None].repeat(3, axis=2), wrap_s=33071, mag_filter=9728)]
    path = tmp_path / "t.glb"
    write_glb(path, [prim], textures=textures)
    gltf = pygltflib.GLTF2().load(str(path))
    assert [t.source for t in gltf.textures] == [0, 1] and [t.sampler for t in gltf.textures] == [0, 1]
    assert (gltf.samplers[0].magFilter, gltf.samplers[0].minFilter, gltf.samplers[0].wrapS) == (9729, 9729, 10497)
    assert (gltf.samplers[1].magFilter, gltf.samplers[1].wrapS, gltf.samplers[1].wrapT) == (9728, 33071, 10497)
    assert gltf.materials[0].normalTexture.index == 0 and gltf.materials[0].normalTexture.scale == 0.25
    blob = gltf.binary_blob()
    for im, expected in zip(gltf.images, (image, grey[..., None].repeat(3, axis=2))):
        assert im.mimeType == "image/png"
        bv = gltf.bufferViews[im.bufferView]
        png = Image.open(io.BytesIO(blob[bv.byteOffset:bv.byteOffset + bv.byteLength]))
        np.testing.assert_array_equal(np.asarray(png), expected)
    asset = load_gltf(path)
    m = asset.materials[0]
    assert m.normal_texture.scale == 0.25 and not asset.notes
    (use, ref), = m.extension_textures
    assert use[1] == "clearcoatNormalTexture" and ref.scale == 0.5
    np.testing.assert_allclose(m.textures[m.normal_texture.texture].texels[..., :3], image / 255.0, atol=1e-7)
    coat_texture = m.textures[ref.texture]
    assert (coat_texture.wrap_s, coat_texture.mag_filter) == (33071, 9728)
    np.testing.assert_allclose(coat_texture.texels[..., 0], grey / 255.0, atol=1e-7)
    assert path.read_bytes() == glb_bytes([prim], textures=textures)  # deterministic


def test_no_textures_writes_none():
    doc = _json(glb_bytes([GltfPrimitive(**QUAD, texcoords=UV)]))
    assert not {"images", "samplers", "textures"} & set(doc) and "normalTexture" not in doc["materials"][0]


@pytest.mark.parametrize("kwargs, textures, message", [
    ({"normal_texture": {"index": 1}}, 1, r"normalTexture must be a textureInfo whose index"),
    ({"normal_texture": {"scale": 1.0}}, 1, r"normalTexture must be a textureInfo"),
    ({"normal_texture": {"index": True}}, 1, r"normalTexture must be a textureInfo"),
    ({"normal_texture": {"index": 0, "texCoord": 1}}, 1, "texCoord must be 0"),
    ({"extensions": {"KHR_materials_clearcoat": {"clearcoatNormalTexture": {"index": 0}}}}, 0,
     r"KHR_materials_clearcoat\.clearcoatNormalTexture must be a textureInfo"),
    ({"normal_texture": {"index": 0}, "texcoords": None}, 1, "needs texcoords"),
])
def test_bad_texture_references_are_refused(kwargs, textures, message):
    prim = GltfPrimitive(**QUAD, **({"texcoords": UV} | kwargs))
    with pytest.raises(ValueError, match=message):
        glb_bytes([prim], textures=[GltfTexture(_normal_image())] * textures)


@pytest.mark.parametrize("texture, message", [
    (GltfTexture(np.zeros((2, 2, 5), np.uint8)), "shape"),
    (GltfTexture(np.zeros((2, 2, 3))), "integers in"),
    (GltfTexture(np.full((2, 2, 3), 256)), "integers in"),
    (GltfTexture(np.zeros((2, 2, 3), np.uint8), min_filter=1), "min_filter"),
    (GltfTexture(np.zeros((2, 2, 3), np.uint8), wrap_t=0), "wrap_t"),
])
def test_bad_textures_are_refused(texture, message):
    with pytest.raises(ValueError, match=f"texture 0: .*{message}"):
        glb_bytes([GltfPrimitive(**QUAD, texcoords=UV)], textures=[texture])
