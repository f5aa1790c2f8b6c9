"""KHR_texture_transform and KHR_mesh_quantization in the glTF loader
(pbrkit.io.gltf_extensions, pbrkit.rendering.gltf).

The expected texture coordinates are computed here from an independent
transcription of the extension's transform (T(offset) R(rotation) S(scale), the
rotation counter-clockwise in UV space, v down: u' = cos r u + sin r v,
v' = -sin r u + cos r v, as the Khronos reference viewer and the specification's
example have it), and the quantised meshes from the dequantisation rules of glTF
2.0 sec. 3.11 and the extension's table.  Files are tiny .glb files built here."""

from __future__ import annotations

import json
import math
import struct

import numpy as np
import pytest

from pbrkit.core.errors import InputError
from pbrkit.io.gltf_extensions import TextureTransform
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.gltf import load_gltf
from pbrkit.rendering.scene import Camera, EnvironmentSpec, GltfObject, Scene

BYTE, UBYTE, SHORT, USHORT, UINT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
TT = "KHR_texture_transform"
MQ = "KHR_mesh_quantization"

#: A 2 x 2 texture of four distinct colours: row 0 (v in [0, 0.5), the top) red, green;
#: row 1 blue, white.
CHECKER = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], dtype=np.uint8)


def png_bytes(pixels):
    import imageio.v3 as iio

    return iio.imwrite("<bytes>", np.asarray(pixels, dtype=np.uint8), extension=".png")


def spec_transform(uv, offset=(0.0, 0.0), rotation=0.0, scale=(1.0, 1.0)):
    """The KHR_texture_transform of uv (N, 2), written out component by component."""
    u, v = uv[:, 0] * scale[0], uv[:, 1] * scale[1]
    c, s = math.cos(rotation), math.sin(rotation)
    return np.stack([offset[0] + c * u + s * v, offset[1] - s * u + c * v], axis=1)


class Builder:
    """A glTF document and its binary chunk, built part by part."""

    def __init__(self):
        self.blob = b""
        self.doc = {"asset": {"version": "2.0"}, "bufferViews": [], "accessors": []}

    def view(self, data, stride=None):
        self.blob += b"\0" * (-len(self.blob) % 4)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if stride is not None:
            view["byteStride"] = stride
        self.doc["bufferViews"].append(view)
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, component, kind, normalized=False, stride=None):
        array = np.asarray(array)
        if stride is not None:  # pad every element to the stride (glTF 2.0 sec. 3.6.2.4: 4-byte aligned)
            rows = array.reshape(array.shape[0], -1)
            item = rows.itemsize * rows.shape[1]
            raw = b"".join(r.tobytes() + b"\0" * (stride - item) for r in rows)
        else:
            raw = array.tobytes()
        acc = {"bufferView": self.view(raw, stride), "componentType": component, "count": int(array.shape[0]),
               "type": kind}
        if normalized:
            acc["normalized"] = True
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob) + (-len(self.blob) % 4)}]
        text = json.dumps(self.doc).encode()
        text += b" " * (-len(text) % 4)
        blob = self.blob + b"\0" * (-len(self.blob) % 4)
        chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
        path.write_bytes(b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks)
        return path


# ------------------------------------------------------------------ a textured quad

#: The quad's corners (the XY plane at z = 0, facing +Z) and their glTF UVs: u = x + 1/2,
#: v = 1/2 - y (the image's top row at +Y).
QUAD = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]], dtype=np.float32)
QUAD_UV = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], dtype=np.float32)


def quad_glb(path, transform=None, slot="baseColorTexture", tex_coord=None, uv1=None, used=(TT,), required=(),
             sampler=None, image=CHECKER):
    """The quad with ``image`` (CHECKER) as ``slot`` (nearest filtering, REPEAT) and ``transform`` as
    its textureInfo's KHR_texture_transform object (None: no extension)."""
    b = Builder()
    attributes = {"POSITION": b.accessor(QUAD, FLOAT, "VEC3"),
                  "NORMAL": b.accessor(np.tile(np.float32([0, 0, 1]), (4, 1)), FLOAT, "VEC3"),
                  "TEXCOORD_0": b.accessor(QUAD_UV, FLOAT, "VEC2")}
    if uv1 is not None:
        attributes["TEXCOORD_1"] = b.accessor(np.asarray(uv1, np.float32), FLOAT, "VEC2")
    indices = b.accessor(np.uint16([0, 1, 2, 0, 2, 3]), USHORT, "SCALAR")
    image = b.view(png_bytes(image))
    info = {"index": 0}
    if tex_coord is not None:
        info["texCoord"] = tex_coord
    if transform is not None:
        info["extensions"] = {TT: transform}
    material = {"pbrMetallicRoughness": {"metallicFactor": 0.0}}
    if slot in ("baseColorTexture", "metallicRoughnessTexture"):
        material["pbrMetallicRoughness"][slot] = info
    else:
        material[slot] = info
        if slot == "emissiveTexture":
            material["emissiveFactor"] = [1.0, 1.0, 1.0]
            material["pbrMetallicRoughness"]["baseColorFactor"] = [0.0, 0.0, 0.0, 1.0]
    b.doc.update({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "translation": [0.0, 0.0, -1.0]}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}],
        "materials": [material], "images": [{"bufferView": image, "mimeType": "image/png"}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [sampler or {"magFilter": 9728, "wrapS": 10497, "wrapT": 10497}],
    })
    if used:
        b.doc["extensionsUsed"] = list(used)
    if required:
        b.doc["extensionsRequired"] = list(required)
    return b.write(path)


#: Points of the quad (x, y at z = -1) well inside the texels of any transform tested: the
#: centres of a 4 x 4 grid of cells.
POINTS = np.array([[x, y, -1.0] for y in (0.375, 0.125, -0.125, -0.375) for x in (-0.375, -0.125, 0.125, 0.375)])


def surface_at(path, points=POINTS):
    """The renderer's surface (Geometry.surface) where rays from z = 5 meet ``points``."""
    scene = Scene(camera=Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, -1.0), fov=20.0, width=4, height=4),
                  environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)), objects=(GltfObject(str(path)),))
    geometry = Geometry(scene)
    origins = np.tile([0.0, 0.0, 5.0], (len(points), 1))
    dirs = points - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hits = geometry.intersect(origins, dirs)
    assert np.all(hits.hit)
    return geometry.surface(hits, origins, dirs)


def checker_at(uv):
    """The linear colours of CHECKER at uv (nearest texel, REPEAT)."""
    from pbrkit.core.color import srgb_to_linear

    col = np.floor(uv[:, 0] * 2).astype(int) % 2
    row = np.floor(uv[:, 1] * 2).astype(int) % 2
    return srgb_to_linear(CHECKER[row, col] / 255.0)


def quad_uv(points):
    return np.stack([points[:, 0] + 0.5, 0.5 - points[:, 1]], axis=1)


# ------------------------------------------------------------------ KHR_texture_transform

TRANSFORMS = [
    dict(offset=(0.5, 0.0)),
    dict(offset=(0.25, -0.75)),
    dict(rotation=math.pi / 2),
    dict(rotation=0.392699),  # the 22.5 degrees of the sample model TextureTransformTest
    dict(scale=(1.5, 1.5)),
    dict(scale=(-1.0, 2.0)),
    dict(offset=(-0.2, 0.3), rotation=-1.1, scale=(0.5, 3.0)),
    dict(offset=(0.0, 1.0), rotation=math.pi / 2, scale=(0.5, 0.5)),  # the specification's example
]


@pytest.mark.parametrize("params", TRANSFORMS)
def test_the_transform_is_the_specifications_matrix(params):
    rng = np.random.default_rng(1)
    uv = rng.uniform(-2.0, 3.0, (50, 2))
    t = TextureTransform(**params)
    np.testing.assert_allclose(t.apply(uv), spec_transform(uv, **params), rtol=0, atol=1e-12)
    m = t.matrix  # T R S on column vectors (u, v, 1)
    np.testing.assert_allclose(m[2], [0, 0, 1])
    np.testing.assert_allclose(m @ np.array([uv[0, 0], uv[0, 1], 1.0]), [*spec_transform(uv[:1], **params)[0], 1])


def test_the_specifications_example_uses_the_lower_left_quadrant():
    """KHR_texture_transform's example: offset [0, 1], rotation pi/2, scale [0.5, 0.5]
    "utilizes only the lower left quadrant of the source image" (v down: v in [0.5, 1])."""
    corners = TextureTransform((0.0, 1.0), math.pi / 2, (0.5, 0.5)).apply(QUAD_UV.astype(float))
    assert np.all(corners[:, 0] > -1e-12) and np.all(corners[:, 0] < 0.5 + 1e-12)
    assert np.all(corners[:, 1] > 0.5 - 1e-12) and np.all(corners[:, 1] < 1.0 + 1e-12)


@pytest.mark.parametrize("slot", ["baseColorTexture", "metallicRoughnessTexture", "normalTexture",
                                  "occlusionTexture", "emissiveTexture"])
def test_every_texture_of_the_material_reads_its_transform(tmp_path, slot):
    ext = {"offset": [0.5, 0.25], "rotation": 0.5, "scale": [2.0, 3.0]}
    asset = load_gltf(quad_glb(tmp_path / "q.glb", ext, slot=slot))
    ref = {"baseColorTexture": "base_color_texture", "metallicRoughnessTexture": "metallic_roughness_texture",
           "normalTexture": "normal_texture", "occlusionTexture": "occlusion_texture",
           "emissiveTexture": "emissive_texture"}[slot]
    transform = getattr(asset.materials[0], ref).transform
    assert transform == TextureTransform((0.5, 0.25), 0.5, (2.0, 3.0))
    assert not any("ignored" in note for note in asset.notes)


@pytest.mark.parametrize("params", TRANSFORMS[:7])
def test_base_colour_is_looked_up_at_the_transformed_uvs(tmp_path, params):
    ext = {k: list(v) if isinstance(v, tuple) else v for k, v in params.items()}
    surface = surface_at(quad_glb(tmp_path / "q.glb", ext))
    expected = checker_at(spec_transform(quad_uv(POINTS), **params))
    np.testing.assert_allclose(surface.base_color, expected, atol=1e-6)


def test_a_quarter_turn_and_a_half_offset_move_the_checker_as_predicted(tmp_path):
    """The quadrant centres read, top-left, top-right, bottom-left, bottom-right: untransformed
    red, green / blue, white; a rotation of pi/2 turns the image a quarter clockwise (blue,
    red / white, green); an offset of (0.5, 0) swaps the columns (green, red / white, blue)."""
    centres = np.array([[-0.25, 0.25, -1], [0.25, 0.25, -1], [-0.25, -0.25, -1], [0.25, -0.25, -1]])
    red, green, blue, white = [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]
    for ext, expected in ((None, [red, green, blue, white]),
                          ({"rotation": math.pi / 2}, [blue, red, white, green]),
                          ({"offset": [0.5, 0.0]}, [green, red, white, blue]),
                          ({"offset": [0.0, 0.5]}, [blue, white, red, green])):
        surface = surface_at(quad_glb(tmp_path / "q.glb", ext), centres)
        np.testing.assert_allclose(surface.base_color, expected, atol=1e-6, err_msg=str(ext))


def test_a_render_shows_the_turned_checker(tmp_path):
    """A 16 x 16 real-time render of the quad with the checker as its only light (emissive,
    black base colour, black environment): the pixels at the quadrants' centres."""
    from pbrkit.rendering.realtime import render_realtime

    path = quad_glb(tmp_path / "q.glb", {"rotation": math.pi / 2}, slot="emissiveTexture")
    # the quad (1 x 1 at distance 6) fills a field of view of 2 atan(1 / 12)
    fov = math.degrees(2 * math.atan(0.5 / 6.0))
    scene = Scene(camera=Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, -1.0), fov=fov, width=16, height=16),
                  environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)), objects=(GltfObject(str(path)),))
    image = render_realtime(scene, bake_size=8).image
    quadrants = [image[4, 4, :3], image[4, 11, :3], image[11, 4, :3], image[11, 11, :3]]
    np.testing.assert_allclose(quadrants, [[0, 0, 1], [1, 0, 0], [1, 1, 1], [0, 1, 0]], atol=0.02)


@pytest.mark.parametrize("ext, tangent, bitangent", [
    (None, [1, 0, 0], [0, 1, 0]),
    ({"rotation": math.pi / 2}, [0, -1, 0], [1, 0, 0]),
    ({"scale": [-1.0, 1.0]}, [-1, 0, 0], [0, 1, 0]),
])
def test_generated_tangents_follow_the_transformed_uvs(tmp_path, ext, tangent, bitangent):
    """Without TANGENT, the normal map's tangent frame is MikkTSpace's of the UVs the normal
    texture is read at: tangent-space +X along increasing u', +Y along decreasing v' (the
    image's up).  A quarter turn (u' = v, v' = -u) sends +X to world -y and +Y to +x."""
    texel = np.array([[[220, 100, 200]]], dtype=np.uint8)
    ts = texel[0, 0] / 255.0 * 2.0 - 1.0
    surface = surface_at(quad_glb(tmp_path / "n.glb", ext, slot="normalTexture", image=texel),
                         np.array([[0.1, 0.2, -1.0]]))
    expected = ts[0] * np.array(tangent) + ts[1] * np.array(bitangent) + ts[2] * np.array([0, 0, 1])
    np.testing.assert_allclose(surface.n[0], expected / np.linalg.norm(expected), atol=3e-3)


def test_tex_coord_override_uses_the_second_set(tmp_path):
    uv1 = 1.0 - QUAD_UV  # the image turned half a turn
    path = quad_glb(tmp_path / "q.glb", {"texCoord": 1, "scale": [1.0, 1.0]}, tex_coord=0, uv1=uv1)
    asset = load_gltf(path)
    ref = asset.materials[0].base_color_texture
    assert ref.texcoord == 1 and ref.transform is None  # the identity: only the set changes
    surface = surface_at(path)
    np.testing.assert_allclose(surface.base_color, checker_at(1.0 - quad_uv(POINTS)), atol=1e-6)
    path = quad_glb(tmp_path / "t.glb", {"texCoord": 1, "offset": [0.5, 0.0]}, uv1=uv1)
    surface = surface_at(path)
    np.testing.assert_allclose(surface.base_color, checker_at(spec_transform(1.0 - quad_uv(POINTS), (0.5, 0.0))),
                               atol=1e-6)
    with pytest.raises(InputError, match=r"uses TEXCOORD_1, which the primitive lacks"):
        load_gltf(quad_glb(tmp_path / "m.glb", {"texCoord": 1}))


def test_without_the_extension_the_uvs_are_used_as_they_are(tmp_path):
    """No KHR_texture_transform (or the identity one): no transform, and the lookup is given
    the very array of interpolated UVs, so such files render exactly as before."""
    for ext in (None, {}, {"offset": [0, 0], "rotation": 0, "scale": [1, 1]}):
        asset = load_gltf(quad_glb(tmp_path / "q.glb", ext))
        ref = asset.materials[0].base_color_texture
        assert ref.transform is None and ref.texcoord == 0
        uv = np.random.default_rng(0).uniform(size=(8, 2))
        assert ref.lookup_uv(uv) is uv
    surface = surface_at(quad_glb(tmp_path / "q.glb", None, used=()))
    np.testing.assert_allclose(surface.base_color, checker_at(quad_uv(POINTS)), atol=1e-6)


def test_both_extensions_may_be_required(tmp_path):
    asset = load_gltf(quad_glb(tmp_path / "q.glb", {"rotation": 1.0}, used=(TT, MQ), required=(TT, MQ)))
    assert asset.notes == []


W = "materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform"


@pytest.mark.parametrize("ext, field", [
    ({"rotation": "1"}, "rotation"),
    ({"rotation": True}, "rotation"),
    ({"rotation": [1.0]}, "rotation"),
    ({"offset": [1.0]}, "offset"),
    ({"offset": [0, 0, 0]}, "offset"),
    ({"offset": 0.5}, "offset"),
    ({"offset": [0, "1"]}, "offset"),
    ({"scale": [1.0, 1e300]}, "scale"),
    ({"scale": [1.0, None]}, "scale"),
    ({"texCoord": -1}, "texCoord"),
    ({"texCoord": 1.5}, "texCoord"),
    ({"texCoord": True}, "texCoord"),
    ([0.5], None),
])
def test_bad_fields_are_refused_naming_the_field(tmp_path, ext, field):
    path = quad_glb(tmp_path / "bad.glb", ext)
    with pytest.raises(InputError) as info:
        load_gltf(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    assert f"{W}.{field} must be" in message if field else f"{W} must be a JSON object" in message


def test_bad_fields_of_other_textures_are_named_too(tmp_path):
    path = quad_glb(tmp_path / "bad.glb", {"scale": [1]}, slot="normalTexture")
    with pytest.raises(InputError, match=r"materials\[0\]\.normalTexture\.extensions\.KHR_texture_transform\.scale "
                                         r"must be an array of 2 finite numbers"):
        load_gltf(path)


# ------------------------------------------------------------------ KHR_mesh_quantization

#: A 3 x 3 grid of vertices of a gently curved patch, its normals and UVs (the float version).
_G = np.linspace(0.0, 1.0, 3)
GRID = np.array([[3.0 + 2.0 * x, -1.0 + 2.0 * y, 0.3 * x * y] for y in _G for x in _G])
GRID_N = np.array([[-0.3 * y, -0.3 * x, 1.0] for y in _G for x in _G])
GRID_N /= np.linalg.norm(GRID_N, axis=1, keepdims=True)
GRID_UV = np.array([[0.1 + 0.8 * x, 0.9 - 0.7 * y] for y in _G for x in _G])
GRID_T = np.array([[0, 1, 4, 0, 4, 3], [1, 2, 5, 1, 5, 4], [3, 4, 7, 3, 7, 6], [4, 5, 8, 4, 8, 7]]).ravel()

_TYPES = {BYTE: np.int8, UBYTE: np.uint8, SHORT: np.int16, USHORT: np.uint16}


def quantize(values, component, normalized, lo, size):
    """Integers c of ``component`` with values = lo + size * f(c), f the glTF 2.0 sec. 3.11
    decoding (normalised) or the integer value: (c, the largest decoding error)."""
    info = np.iinfo(_TYPES[component])
    signed = info.min < 0
    f = (values - lo) / size  # in [0, 1]
    if signed:
        f = 2.0 * f - 1.0  # in [-1, 1]
    c = np.round(f * info.max).astype(_TYPES[component])
    return c, size / info.max


def aligned(array):
    """The byteStride that aligns each element of ``array`` (N, k) to 4 bytes (glTF 2.0
    sec. 3.6.2.4; the extension: "a BYTE normal is expected to have a stride of 4"), or
    None when the elements are aligned as they are."""
    item = array.itemsize * array.shape[1]
    return None if item % 4 == 0 else item + (-item % 4)


def grid_glb(path, position=(SHORT, True), normal=(BYTE, True), texcoord=(USHORT, False), used=(MQ,),
             required=(MQ,), tangent=None, quantized=True):
    """The grid with quantised attributes (``quantized``) or floats; the node's translation and
    uniform scale and the texture transform's offset and scale undo the quantisation."""
    b = Builder()
    node = {"mesh": 0}
    tex_info = {"index": 0}
    if not quantized:
        attributes = {"POSITION": b.accessor(GRID.astype(np.float32), FLOAT, "VEC3"),
                      "NORMAL": b.accessor(GRID_N.astype(np.float32), FLOAT, "VEC3"),
                      "TEXCOORD_0": b.accessor(GRID_UV.astype(np.float32), FLOAT, "VEC2")}
    else:
        lo, hi = GRID.min(axis=0), GRID.max(axis=0)
        size = float((hi - lo).max())  # uniform: normals keep their directions
        signed = np.iinfo(_TYPES[position[0]]).min < 0
        centre = (lo + hi) / 2.0
        lo = centre - size / 2.0
        cp, _ = quantize(GRID, position[0], True, lo, size)
        k = 1.0 if position[1] else float(np.iinfo(_TYPES[position[0]]).max)
        # decoded d = c / max (normalised) or c: positions = origin + scale * d
        node["translation"] = list(centre if signed else lo)
        node["scale"] = [size / 2.0 / k if signed else size / k] * 3
        attributes = {"POSITION": b.accessor(cp, position[0], "VEC3", position[1], stride=aligned(cp))}
        cn = np.round(GRID_N * np.iinfo(_TYPES[normal[0]]).max).astype(_TYPES[normal[0]])
        attributes["NORMAL"] = b.accessor(cn, normal[0], "VEC3", normal[1], stride=aligned(cn))
        # UVs in [0, 1]: c = round(uv max), decoded c / max (normalised) or c (scaled back below)
        ct = np.round(GRID_UV * np.iinfo(_TYPES[texcoord[0]]).max).astype(_TYPES[texcoord[0]])
        attributes["TEXCOORD_0"] = b.accessor(ct, texcoord[0], "VEC2", texcoord[1], stride=aligned(ct))
        if not texcoord[1]:  # integer UVs: the texture transform scales them back
            tmax = float(np.iinfo(_TYPES[texcoord[0]]).max)
            tex_info["extensions"] = {TT: {"scale": [1.0 / tmax, 1.0 / tmax]}}
        if tangent is not None:
            attributes["TANGENT"] = b.accessor(np.tile(np.int8([127, 0, 0, 127]), (9, 1)), tangent[0], tangent[2],
                                               tangent[1])
    indices = b.accessor(GRID_T.astype(np.uint16), USHORT, "SCALAR")
    b.doc.update({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [node],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": tex_info}}],
        "images": [{"bufferView": b.view(png_bytes(CHECKER)), "mimeType": "image/png"}],
        "textures": [{"source": 0}],
        "extensionsUsed": list(used) + [TT], "extensionsRequired": list(required),
    })
    return b.write(path)


@pytest.mark.parametrize("position, normal, texcoord", [
    ((SHORT, True), (BYTE, True), (USHORT, False)),
    ((SHORT, False), (SHORT, True), (SHORT, True)),
    ((BYTE, True), (BYTE, True), (UBYTE, False)),
    ((BYTE, False), (SHORT, True), (BYTE, True)),
    ((UBYTE, True), (BYTE, True), (UBYTE, True)),
    ((UBYTE, False), (BYTE, True), (SHORT, False)),
    ((USHORT, True), (SHORT, True), (BYTE, False)),
    ((USHORT, False), (BYTE, True), (USHORT, True)),
])
def test_quantized_meshes_load_to_the_float_geometry(tmp_path, position, normal, texcoord):
    (ref,) = load_gltf(grid_glb(tmp_path / "f.glb", quantized=False)).meshes
    asset = load_gltf(grid_glb(tmp_path / "q.glb", position, normal, texcoord))
    (mesh,) = asset.meshes
    assert asset.notes == []
    size = float((GRID.max(axis=0) - GRID.min(axis=0)).max())
    step = size / np.iinfo(_TYPES[position[0]]).max
    np.testing.assert_allclose(ref.positions, GRID, atol=1e-6)
    np.testing.assert_allclose(mesh.positions, ref.positions, rtol=0, atol=step)
    np.testing.assert_array_equal(mesh.indices, ref.indices)
    # unit normals again, within the quantisation of their components
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(mesh.normals, ref.normals, atol=2.0 / np.iinfo(_TYPES[normal[0]]).max)
    # the UVs at which the texture is looked up
    looked_up = asset.materials[0].base_color_texture.lookup_uv(mesh.texcoords[0])
    np.testing.assert_allclose(looked_up, ref.texcoords[0], atol=2.0 / np.iinfo(_TYPES[texcoord[0]]).max)


def test_quantized_values_are_decoded_by_the_specification(tmp_path):
    """glTF 2.0 sec. 3.11: BYTE normalised f = max(c / 127, -1) (so -128 and -127 both
    give -1); non-normalised integers keep their value."""
    b = Builder()
    positions = np.int16([[-32768, 0, 32767], [100, -100, 7], [0, 0, 0]])
    normals = np.int8([[-128, 0, 0], [0, 127, 0], [0, 0, -127]])
    attributes = {"POSITION": b.accessor(positions, SHORT, "VEC3", False, stride=8),
                  "NORMAL": b.accessor(normals, BYTE, "VEC3", True, stride=4)}
    b.doc.update({"nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": attributes}]}],
                  "extensionsUsed": [MQ], "extensionsRequired": [MQ]})
    (mesh,) = load_gltf(b.write(tmp_path / "d.glb")).meshes
    np.testing.assert_array_equal(mesh.positions, positions.astype(float))
    np.testing.assert_array_equal(mesh.normals, [[-1, 0, 0], [0, 1, 0], [0, 0, -1]])


def test_quantized_formats_without_the_extension_are_refused(tmp_path):
    path = grid_glb(tmp_path / "q.glb", used=(), required=())
    with pytest.raises(InputError) as info:
        load_gltf(path)
    message = str(info.value)
    assert "meshes[0].primitives[0].attributes.POSITION (accessors[0]) must be VEC3 FLOAT; it is VEC3 SHORT " \
           "(normalized)" in message and MQ in message and "\n" not in message


@pytest.mark.parametrize("change, field, fragment", [
    (dict(normal=(BYTE, False)), "NORMAL", "it is VEC3 BYTE"),
    (dict(normal=(UBYTE, True)), "NORMAL", "it is VEC3 UNSIGNED_BYTE (normalized)"),
    (dict(normal=(USHORT, True)), "NORMAL", "it is VEC3 UNSIGNED_SHORT (normalized)"),
    (dict(tangent=(BYTE, False, "VEC4")), "TANGENT", "it is VEC4 BYTE"),
    (dict(tangent=(BYTE, True, "VEC3")), "TANGENT", "it is VEC3 BYTE (normalized)"),
    (dict(tangent=(UBYTE, True, "VEC4")), "TANGENT", "it is VEC4 UNSIGNED_BYTE (normalized)"),
    (dict(texcoord=(USHORT, False), position=(SHORT, True)), None, None),  # valid: the control
])
def test_formats_outside_the_extensions_table_are_refused(tmp_path, change, field, fragment):
    path = grid_glb(tmp_path / "bad.glb", **change)
    if field is None:
        load_gltf(path)
        return
    with pytest.raises(InputError) as info:
        load_gltf(path)
    message = str(info.value)
    assert f"attributes.{field} (accessors[" in message and fragment in message, message
    assert "\n" not in message


def test_integer_types_the_extension_does_not_list_are_refused(tmp_path):
    b = Builder()
    attributes = {"POSITION": b.accessor(np.uint32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), UINT, "VEC3"),
                  "TEXCOORD_0": b.accessor(np.uint32([[0, 0], [1, 0], [0, 1]]), UINT, "VEC2")}
    b.doc.update({"nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": attributes}]}],
                  "extensionsUsed": [MQ], "extensionsRequired": [MQ]})
    with pytest.raises(InputError, match=r"attributes\.POSITION \(accessors\[0\]\) must be VEC3 FLOAT or VEC3 BYTE "
                                         r".*; it is VEC3 UNSIGNED_INT$"):
        load_gltf(b.write(tmp_path / "u.glb"))
    b.doc["accessors"][0]["componentType"] = FLOAT
    b.doc["accessors"][0]["bufferView"] = b.view(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]).tobytes())
    with pytest.raises(InputError, match=r"attributes\.TEXCOORD_0 \(accessors\[1\]\) must be VEC2 FLOAT or .*; "
                                         r"it is VEC2 UNSIGNED_INT$"):
        load_gltf(b.write(tmp_path / "t.glb"))
