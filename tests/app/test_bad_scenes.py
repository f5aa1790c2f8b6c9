"""Bad scene files and glTF files on the command line: every one is refused with a
single ``pbrkit: error: <file>: <problem>`` line, a non-zero exit status, no
traceback, no warning and no output file; and the up-front memory check.

The corpus is built here: a small valid glTF (a textured quad with a light and a
camera, written as .gltf with a data URI or as .glb) broken one way per case,
and a small valid scene file broken one key at a time.  Every case fails before
rendering, so the tests are fast."""

from __future__ import annotations

import base64
import copy
import json
import math
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest
from gltf_files import glb_bytes
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.rendering.budget import (
    BYTES_PER_RAY,
    FIXED_BYTES,
    available_memory,
    check_render_memory,
    estimate_render_memory,
)
from pbrkit.rendering.scene import Camera, EnvironmentSpec, Scene, Sphere

SMALL = ["--width", "8", "--height", "8"]
#: Warnings a user never sees (Python's default filters hide them outside __main__).
HIDDEN = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)

# ------------------------------------------------------------------ the corpus


def _png_1x1():
    import imageio.v3 as iio

    return iio.imwrite("<bytes>", np.full((1, 1, 3), 200, np.uint8), extension=".png")


def good_gltf():
    """(document, buffer bytes) of a valid glTF 2.0 file: a unit quad facing +Z with
    POSITION, NORMAL, TEXCOORD_0 and uint16 indices, a material with a baseColor
    texture (a 1 x 1 PNG in the buffer) and a sampler, a node with a child, a camera
    and a KHR_lights_punctual light."""
    positions = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3, 0, 0], np.uint16)  # 6 used; padded to 4 bytes
    parts = [positions.tobytes(), normals.tobytes(), uvs.tobytes(), indices.tobytes(), _png_1x1()]
    blob, views = b"", []
    for data in parts:
        blob += b"\0" * (-len(blob) % 4)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob += data
    blob += b"\0" * (-len(blob) % 4)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [{"children": [1], "translation": [0.0, 0.0, -1.0]}, {"mesh": 0, "camera": 0},
                  {"translation": [0.0, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                    "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.5, 1.0, 1.0], "metallicFactor": 0.5,
                                                "roughnessFactor": 0.8, "baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "wrapS": 10497, "wrapT": 33071}],
        "images": [{"bufferView": 4, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0],
             "max": [0.5, 0.5, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 2.0}]}},
    }
    return doc, bytearray(blob)


def write_gltf(path, doc, blob):
    """Write ``doc`` as .glb (buffer 0 in the BIN chunk) or .gltf (buffer 0 as a data URI
    unless the document already gives it a uri)."""
    if path.suffix == ".glb":
        path.write_bytes(glb_bytes(doc, blob))
        return path
    doc = copy.deepcopy(doc)
    buffers = doc.get("buffers")
    if isinstance(buffers, list) and buffers and isinstance(buffers[0], dict) and "uri" not in buffers[0]:
        buffers[0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()
    path.write_text(json.dumps(doc))
    return path


def scene_text(model_name):
    """A scene file placing one glTF model in front of a tiny camera."""
    return (f'[camera]\nposition = [0.0, 0.0, 3.0]\nwidth = 8\nheight = 8\n[environment]\ncolor = [1.0, 1.0, 1.0]\n'
            f'[[objects]]\ntype = "gltf"\nfile = "{model_name}"\n')


def render(*args):
    """Run ``pbrkit render`` in-process; returns (result, warnings that a user would see)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = CliRunner().invoke(app, ["render", *map(str, args)])
    return result, [w for w in caught if not issubclass(w.category, HIDDEN)]


def assert_refused(result, caught, out, culprit, *fragments):
    """Exit status 1 from ``user_errors``, one stderr line naming ``culprit``, no traceback,
    no warning, nothing written next to ``out``."""
    assert isinstance(result.exception, SystemExit) and result.exit_code == 1, (result.exception, result.output)
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("pbrkit: error: "), lines[0]
    assert str(culprit) in lines[0], lines[0]
    assert "Traceback" not in result.output and "Warning" not in result.output, result.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert not caught, [str(w.message) for w in caught]
    assert not out.exists() and not out.with_name(out.stem + ".stderr.exr").exists()
    assert not [p for p in out.parent.iterdir() if p.name.startswith(f".{out.stem}")], list(out.parent.iterdir())


def _set(path, value):
    """A corruption: set doc[path...] = value (a list of keys and indices)."""
    def corrupt(doc, blob):
        target = doc
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return corrupt


def _delete(path):
    def corrupt(doc, blob):
        target = doc
        for key in path[:-1]:
            target = target[key]
        del target[path[-1]]
    return corrupt


def _blob(offset, data):
    """A corruption of the buffer's bytes."""
    def corrupt(doc, blob):
        blob[offset:offset + len(data)] = data
    return corrupt


def _both(*corruptions):
    def corrupt(doc, blob):
        for c in corruptions:
            c(doc, blob)
    return corrupt


PRIM = ["meshes", 0, "primitives", 0]
ATTR = PRIM + ["attributes"]
BASE_TEXTURE = ["materials", 0, "pbrMetallicRoughness", "baseColorTexture"]
LIGHT = ["extensions", "KHR_lights_punctual", "lights", 0]
SPARSE = {"count": 1, "indices": {"bufferView": 3, "componentType": 5123}, "values": {"bufferView": 0}}

GLTF_CASES = {
    # 1. indices out of range, negative, not integers; the node hierarchy
    "scene index": (_set(["scene"], 3), "scene is 3, but the file has 1 scenes"),
    "scene root index": (_set(["scenes", 0, "nodes"], [0, 9]), "scenes[0].nodes[1] is 9"),
    "mesh index": (_set(["nodes", 1, "mesh"], 4), "nodes[1].mesh is 4, but the file has 1 meshes"),
    "child index": (_set(["nodes", 0, "children"], [5]), "nodes[0].children[0] is 5"),
    "negative index": (_set(["nodes", 1, "mesh"], -1), "nodes[1].mesh is -1"),
    "float index": (_set(["nodes", 1, "mesh"], 0.0), "nodes[1].mesh must be an integer index into meshes"),
    "string index": (_set(["nodes", 1, "mesh"], "0"), "nodes[1].mesh must be an integer index"),
    "bool index": (_set(["nodes", 1, "mesh"], True), "nodes[1].mesh must be an integer index"),
    "accessor index": (_set(ATTR + ["POSITION"], 17), "attributes.POSITION is 17, but the file has 4 accessors"),
    "indices index": (_set(PRIM + ["indices"], 4), "primitives[0].indices is 4"),
    "material index": (_set(PRIM + ["material"], 1), "primitives[0].material is 1, but the file has 1 materials"),
    "texture index": (_set(BASE_TEXTURE + ["index"], 2), "baseColorTexture.index is 2"),
    "image index": (_set(["textures", 0, "source"], 1), "textures[0].source is 1, but the file has 1 images"),
    "sampler index": (_set(["textures", 0, "sampler"], 3), "textures[0].sampler is 3"),
    "bufferView index": (_set(["accessors", 0, "bufferView"], 5), "accessors[0].bufferView is 5"),
    "image bufferView index": (_set(["images", 0, "bufferView"], 9), "images[0].bufferView is 9"),
    "buffer index": (_set(["bufferViews", 0, "buffer"], 1), "bufferViews[0].buffer is 1, but the file has 1 buffers"),
    "camera index": (_set(["nodes", 1, "camera"], 2), "nodes[1].camera is 2, but the file has 1 cameras"),
    "skin index": (_set(["nodes", 1, "skin"], 0), "nodes[1].skin is 0, but the file has no skins"),
    "light index": (_set(["nodes", 2, "extensions", "KHR_lights_punctual", "light"], 1),
                    "KHR_lights_punctual.light is 1, but the file has 1 KHR_lights_punctual lights"),
    "light index missing": (_set(["nodes", 2, "extensions", "KHR_lights_punctual"], {}), "has no light"),
    "animation node": (_set(["animations"], [{"samplers": [], "channels": [{"sampler": 0, "target": {"node": 0}}]}]),
                       "animations[0].channels[0].sampler is 0"),
    "node cycle": (_set(["nodes", 1, "children"], [0]), "cycle"),
    "node cycle off the scene": (_set(["nodes"], [{"children": [1]}, {"mesh": 0}, {"children": [3]},
                                                  {"children": [2]}]), "cycle"),
    "node is its own child": (_set(["nodes", 1, "children"], [1]), "lists itself as a child"),
    "node with two parents": (_set(["nodes", 2, "children"], [1]), "nodes[1] is a child of both"),
    "child listed twice": (_set(["nodes", 0, "children"], [1, 1]), "lists 1 more than once"),
    "scene root is a child": (_set(["scenes", 0, "nodes"], [0, 1]), "which is a child of nodes[0]"),
    # 2. attribute formats, ranges inside bufferViews and buffers, vertex indices
    "POSITION SCALAR": (_set(["accessors", 0, "type"], "SCALAR"), "must be VEC3 FLOAT; it is SCALAR FLOAT"),
    "POSITION integers": (_both(_set(["accessors", 0, "componentType"], 5123), _set(["accessors", 0, "count"], 2)),
                          "must be VEC3 FLOAT; it is VEC3 UNSIGNED_SHORT"),
    "NORMAL VEC2": (_set(["accessors", 1, "type"], "VEC2"), "attributes.NORMAL (accessors[1]) must be VEC3 FLOAT"),
    "TANGENT VEC3": (_set(ATTR + ["TANGENT"], 1), "attributes.TANGENT (accessors[1]) must be VEC4 FLOAT"),
    "TEXCOORD VEC3": (_both(_set(["accessors", 2, "type"], "VEC3"), _set(["accessors", 2, "count"], 2)),
                      "TEXCOORD_0 (accessors[2]) must be VEC2 FLOAT"),
    "TEXCOORD bytes not normalized": (_both(_set(["accessors", 2, "componentType"], 5121)),
                                      "VEC2 UNSIGNED_BYTE (normalized)"),
    "indices FLOAT": (_both(_set(["accessors", 3, "componentType"], 5126), _set(["accessors", 3, "count"], 4)),
                      "indices (accessors[3]) must be SCALAR"),
    "indices VEC2": (_both(_set(["accessors", 3, "type"], "VEC2"), _set(["accessors", 3, "count"], 2)),
                     "indices (accessors[3]) must be SCALAR"),
    "unknown componentType": (_set(["accessors", 1, "componentType"], 5124), "accessors[1].componentType must be"),
    "unknown accessor type": (_set(["accessors", 1, "type"], "VEC5"), "accessors[1].type must be one of"),
    "accessor count 0": (_set(["accessors", 1, "count"], 0), "accessors[1].count must be an integer >= 1"),
    "accessor count past the bufferView": (_set(["accessors", 0, "count"], 40),
                                           "past the end of bufferViews[0] (48 bytes)"),
    "accessor byteOffset past the bufferView": (_set(["accessors", 1, "byteOffset"], 4),
                                                "past the end of bufferViews[1]"),
    "byteStride smaller than an element": (_set(["bufferViews", 0, "byteStride"], 8), "is smaller than one VEC3"),
    "byteStride not a multiple of 4": (_set(["bufferViews", 0, "byteStride"], 14), "byteStride must be a multiple"),
    "bufferView past the buffer": (_set(["bufferViews", 4, "byteLength"], 10**6), "runs past the end of buffers[0]"),
    "buffer longer than its data": (_set(["buffers", 0, "byteLength"], 10**6), "fewer than its byteLength"),
    "vertex index past the vertex count": (_blob(128 + 4, struct.pack("<H", 9)),
                                           "has index 9, but POSITION has only 4 vertices"),
    "NaN position": (_blob(0, struct.pack("<f", float("nan"))), "POSITION (accessors[0]) has 1 non-finite"),
    "attribute counts differ": (_both(_set(["accessors", 2, "count"], 3)), "TEXCOORD_0 has 3 elements, POSITION has 4"),
    "triangle count not whole": (_set(["accessors", 3, "count"], 5), "not divisible by 3"),
    "unknown mode": (_set(PRIM + ["mode"], 9), "mode must be an integer from 0 to 6"),
    "missing TEXCOORD set": (_set(BASE_TEXTURE + ["texCoord"], 1), "uses TEXCOORD_1, which the primitive lacks"),
    "no POSITION": (_delete(ATTR + ["POSITION"]), "has no POSITION attribute"),
    "no primitives": (_set(["meshes", 0, "primitives"], []), "primitives must be a non-empty array"),
    # 3. sparse accessors
    "sparse componentType unknown": (_set(["accessors", 1, "sparse"], {**SPARSE, "indices": {
        "bufferView": 3, "componentType": 5126}}), "sparse.indices.componentType must be 5121"),
    "sparse index out of range": (_both(_set(["accessors", 0, "sparse"], SPARSE), _blob(128, struct.pack("<H", 7))),
                                  "accessors[0].sparse has index 7, past the accessor's count 4"),
    "sparse count past the accessor": (_set(["accessors", 1, "sparse"], {**SPARSE, "count": 5}),
                                       "sparse.count must be an integer from 1 to 4"),
    "sparse without values": (_set(["accessors", 1, "sparse"], {"count": 1, "indices": SPARSE["indices"]}),
                              "sparse has no values"),
    "sparse indices past their bufferView": (_set(["accessors", 1, "sparse"], {**SPARSE, "count": 4, "indices": {
        "bufferView": 3, "componentType": 5125, "byteOffset": 4}}), "sparse.indices"),
    # 4. not glTF 2.0, nothing to render, buffers and images that cannot be read
    "asset version 1.0": (_set(["asset", "version"], "1.0"), "glTF version 1.0 is not supported"),
    "asset version 3.0": (_set(["asset", "version"], "3.0"), "glTF version 3.0 is not supported"),
    "asset version a number": (_set(["asset", "version"], 2.0), "asset.version must be a string"),
    "minVersion 2.1": (_set(["asset", "minVersion"], "2.1"), "asset.minVersion"),
    "no asset": (_delete(["asset"]), "no 'asset'"),
    "no meshes": (lambda doc, blob: [doc.pop(k) for k in ("meshes", "nodes", "scenes", "scene", "extensions")],
                  "no meshes to render"),
    "scene without meshes": (_set(["scenes", 0, "nodes"], []), "no meshes to render"),
    "missing external buffer": (_set(["buffers", 0, "uri"], "model.bin"),
                                "buffers[0].uri 'model.bin': file not found"),
    "data URI without comma": (_set(["buffers", 0, "uri"], "data:application/octet-stream;base64"),
                               "malformed data URI"),
    "data URI bad base64": (_set(["buffers", 0, "uri"], "data:application/octet-stream;base64,@@@"),
                            "malformed data URI"),
    "data URI not base64": (_set(["buffers", 0, "uri"], "data:text/plain,hello"), "base64"),
    "remote URI": (_set(["buffers", 0, "uri"], "https://example.com/model.bin"), "only relative file paths"),
    "second buffer without uri": (_both(lambda doc, blob: doc["buffers"].append({"byteLength": 4096}),
                                        _set(["bufferViews", 4, "buffer"], 1),
                                        _set(["bufferViews", 4, "byteOffset"], 0)),
                                  "buffers[1] has no uri"),
    "undecodable image": (_set(["images", 0], {"uri": "data:image/png;base64," + base64.b64encode(b"junk").decode()}),
                          "cannot decode images[0]"),
    "image without data": (_set(["images", 0], {"mimeType": "image/png"}), "neither a uri nor a bufferView"),
    "unsupported required extension": (_set(["extensionsRequired"], ["KHR_draco_mesh_compression"]),
                                       "unsupported glTF extension"),
    # wrong values a user would try next
    "roughnessFactor string": (_set(["materials", 0, "pbrMetallicRoughness", "roughnessFactor"], "0.5"),
                               "roughnessFactor must be a finite number in [0.0, 1.0]; got '0.5'"),
    "baseColorFactor of 3": (_set(["materials", 0, "pbrMetallicRoughness", "baseColorFactor"], [1, 1, 1]),
                             "baseColorFactor must be an array of 4"),
    "metallicFactor 2": (_set(["materials", 0, "pbrMetallicRoughness", "metallicFactor"], 2), "metallicFactor"),
    "emissiveStrength negative": (_set(["materials", 0, "extensions"], {"KHR_materials_emissive_strength": {
        "emissiveStrength": -1}}), "emissiveStrength"),
    "doubleSided string": (_set(["materials", 0, "doubleSided"], "yes"), "doubleSided must be true or false"),
    "alphaMode unknown": (_set(["materials", 0, "alphaMode"], "GLASS"), "alphaMode must be one of"),
    "alphaCutoff negative": (_set(["materials", 0, "alphaCutoff"], -0.5), "materials[0].alphaCutoff must be"),
    "alphaCutoff string": (_set(["materials", 0, "alphaCutoff"], "0.5"), "materials[0].alphaCutoff must be"),
    "wrapS unknown": (_set(["samplers", 0, "wrapS"], 1234), "samplers[0].wrapS must be one of"),
    "matrix of 15": (_set(["nodes", 0, "matrix"], [1.0] * 15), "nodes[0].matrix must be an array of 16"),
    "zero rotation": (_set(["nodes", 0, "rotation"], [0, 0, 0, 0]), "unit quaternion"),
    "integer beyond floats": (_set(["nodes", 0, "translation"], [10**400, 0, 0]), "nodes[0].translation must be"),
    "absurd scale": (_set(["nodes", 0, "scale"], [1e300, 1e300, 1e300]), "not finite"),
    "overflowing transforms": (_both(_set(["nodes", 0, "scale"], [1e200] * 3),
                                     _set(["nodes", 1, "scale"], [1e200] * 3)), "is not finite"),
    "light type unknown": (_set(LIGHT + ["type"], "area"), "lights[0].type must be one of"),
    "light intensity string": (_set(LIGHT + ["intensity"], "5"), "lights[0].intensity must be a finite number"),
    "spot cone too wide": (_set(LIGHT, {"type": "spot", "spot": {"outerConeAngle": 3.0}}), "outerConeAngle"),
    "lights not an array": (_set(["extensions", "KHR_lights_punctual", "lights"], {}), "must be a JSON array"),
    "meshes not an array": (_set(["meshes"], {"0": {}}), "meshes must be a JSON array"),
    "accessor not an object": (_set(["accessors", 1], 7), "accessors[1] must be a JSON object"),
}


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
@pytest.mark.parametrize("case", list(GLTF_CASES))
def test_broken_gltf_files_are_refused(tmp_path, case, suffix):
    corrupt, fragment = GLTF_CASES[case]
    doc, blob = good_gltf()
    corrupt(doc, blob)
    model = write_gltf(tmp_path / f"model{suffix}", doc, blob)
    (tmp_path / "scene.toml").write_text(scene_text(model.name))
    out = tmp_path / "out.png"
    result, caught = render(tmp_path / "scene.toml", "-o", out, *SMALL)
    assert_refused(result, caught, out, model, fragment)


def _hello(path):
    path.write_text('{"hello": "world"}')


def _glb_of(doc, blob=None):
    return lambda path: path.write_bytes(glb_bytes(doc, blob))


def _good_glb_cut(n):
    doc, blob = good_gltf()
    return lambda path: path.write_bytes(glb_bytes(doc, blob)[:n])


def _glb_header(magic=b"glTF", version=2):
    def write(path):
        doc, blob = good_gltf()
        data = bytearray(glb_bytes(doc, blob))
        data[:8] = magic + struct.pack("<I", version)
        path.write_bytes(bytes(data))
    return write


FILE_CASES = {
    # 4. files that are not glTF 2.0 at all
    "hello world .gltf": ("model.gltf", _hello, "no 'asset'"),
    "hello world .glb": ("model.glb", _glb_of({"hello": "world"}), "no 'asset'"),
    "asset only": ("model.gltf", lambda p: p.write_text('{"asset": {"version": "2.0"}}'), "no meshes to render"),
    "empty .gltf": ("model.gltf", lambda p: p.write_bytes(b""), "the file is empty"),
    "empty .glb": ("model.glb", lambda p: p.write_bytes(b""), "the file is empty"),
    "glb header only": ("model.glb", lambda p: p.write_bytes(b"glTF\x02\x00"), "truncated binary glTF"),
    "truncated .glb": ("model.glb", _good_glb_cut(200), "truncated binary glTF"),
    "truncated chunk header": ("model.glb", _good_glb_cut(16), "truncated binary glTF"),
    "wrong magic": ("model.glb", _glb_header(magic=b"GLTF"), "not the magic b'glTF'"),
    "glb version 1": ("model.glb", _glb_header(version=1), "container version 1 is not supported"),
    "glb without JSON chunk": ("model.glb", lambda p: p.write_bytes(b"glTF" + struct.pack("<II", 2, 24) +
                                                                    struct.pack("<II", 4, 0x004E4942) + b"\0" * 4),
                               "without a JSON chunk"),
    "JSON array": ("model.gltf", lambda p: p.write_text("[1, 2, 3]"), "the JSON is an array, not an object"),
    "JSON string": ("model.gltf", lambda p: p.write_text('"glTF"'), "the JSON is a string"),
    "invalid JSON": ("model.gltf", lambda p: p.write_text('{"asset": {"version": "2.0"'), "invalid JSON"),
    "JSON NaN": ("model.gltf", lambda p: p.write_text('{"asset": {"version": "2.0"}, "x": NaN}'), "NaN"),
    "not UTF-8": ("model.gltf", lambda p: p.write_bytes(b"\xff\xfe\x00junk"), "not UTF-8"),
    "deep JSON": ("model.gltf", lambda p: p.write_text("[" * 100000 + "]" * 100000), "invalid JSON"),
    "glb JSON not UTF-8": ("model.glb", lambda p: p.write_bytes(b"glTF" + struct.pack("<II", 2, 24) +
                                                                struct.pack("<II", 4, 0x4E4F534A) + b"\xff" * 4 +
                                                                b"\0" * 4), "not UTF-8"),
    "a directory": ("model.gltf", lambda p: p.mkdir(), "is a folder, not a regular file"),
}


@pytest.mark.parametrize("case", list(FILE_CASES))
def test_files_that_are_not_gltf_are_refused(tmp_path, case):
    name, write, fragment = FILE_CASES[case]
    model = tmp_path / name
    write(model)
    (tmp_path / "scene.toml").write_text(scene_text(name))
    out = tmp_path / "out.png"
    result, caught = render(tmp_path / "scene.toml", "-o", out, *SMALL)
    assert_refused(result, caught, out, model, fragment)


def test_the_good_gltf_renders_placed_and_alone(tmp_path):
    """The corpus's base file is valid (so each case tests one break), placed by a scene
    file and given alone (``pbrkit render model.glb``: framed under the bundled
    environment, pbrkit.rendering.sources)."""
    doc, blob = good_gltf()
    for suffix in (".gltf", ".glb"):
        model = write_gltf(tmp_path / f"model{suffix}", doc, blob)
        (tmp_path / "scene.toml").write_text(scene_text(model.name))
        out = tmp_path / f"out{suffix}.png"
        result, caught = render(tmp_path / "scene.toml", "-o", out, *SMALL, "--bake-size", "16", "--quiet")
        assert result.exit_code == 0, result.output
        assert out.exists() and not caught
    out = tmp_path / "direct.png"
    result, caught = render(tmp_path / "model.glb", "-o", out, *SMALL, "--bake-size", "16", "--quiet")
    assert result.exit_code == 0, result.output
    assert out.exists() and not caught


# ------------------------------------------------------------------ scene files

BASE_SCENE = {
    "camera": {"position": [0.0, 0.0, 5.0], "width": 8, "height": 8},
    "environment": {"color": [1.0, 1.0, 1.0]},
    "materials": {"red": {"base_color": [0.8, 0.1, 0.1], "roughness": 0.5}},
    "objects": [{"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0, "material": "red"},
                {"type": "plane", "point": [0.0, -1.0, 0.0], "normal": [0.0, 1.0, 0.0]}],
    "lights": [{"type": "spot", "position": [0.0, 3.0, 0.0], "direction": [0.0, -1.0, 0.0], "intensity": 5.0,
                "range": 10.0, "inner_cone_angle": 0.2, "outer_cone_angle": 0.5}],
}
NAN = float("nan")

#: (section path, key, bad value, message fragment); JSON can hold NaN and null.
SCENE_CASES = [
    (["materials", "red"], "roughness", "0.5", "material 'red': roughness must be a number in [0, 1], got '0.5'"),
    (["materials", "red"], "metallic", True, "material 'red': metallic must be a number in [0, 1], got true"),
    (["materials", "red"], "roughness", None, "roughness must be a number in [0, 1], got null"),
    (["materials", "red"], "roughness", NAN, "roughness must be a number in [0, 1], got nan"),
    (["materials", "red"], "roughness", 1.5, "roughness must be a number in [0, 1], got 1.5"),
    (["materials", "red"], "base_color", [1, 0], "base_color must be a list of 3 numbers in [0, 1], got [1, 0]"),
    (["materials", "red"], "base_color", [1, 0, "0"], "base_color must be a list of 3 numbers"),
    (["materials", "red"], "base_color", "red", "base_color must be a list of 3 numbers"),
    (["materials", "red"], "emissive", [1, 1, float("inf")], "emissive must be a list of 3 numbers"),
    (["materials", "red"], "emissive", [-1, 0, 0], "emissive must be a list of 3 numbers in [0, 1e+12]"),
    (["materials", "red"], "model", 3, "model must be a non-empty string, got 3"),
    (["materials", "red"], "model", "phong", "unknown model 'phong'"),
    (["materials", "red"], "anisotropy", "0.1", "anisotropy must be a number in [-1, 1]"),
    (["materials", "red"], "eta", [1, 1], "eta must be a list of 3 numbers"),
    (["camera"], "width", "8", "camera.width must be an integer in [1, 16384], got '8'"),
    (["camera"], "width", 8.0, "camera.width must be an integer in [1, 16384], got 8.0"),
    (["camera"], "height", True, "camera.height must be an integer in [1, 16384], got true"),
    (["camera"], "width", 100000, "camera.width must be an integer in [1, 16384], got 100000"),
    (["camera"], "supersample", 0, "camera.supersample must be an integer in [1, 16]"),
    (["camera"], "fov", "40", "camera.fov must be a number of degrees in (0, 180), got '40'"),
    (["camera"], "fov", 180, "camera.fov must be a number of degrees in (0, 180), got 180"),
    (["camera"], "position", [0, 0], "camera.position must be a list of 3 numbers"),
    (["camera"], "position", [0, 0, 1e30], "camera.position must be a list of 3 numbers in [-1e+06, 1e+06]"),
    (["camera"], "up", [0, 0, 0], "camera.up must be a list of 3 numbers, not all zero"),
    (["environment"], "intensity", "2", "environment.intensity must be a number in [0, 1e+12], got '2'"),
    (["environment"], "color", [1, 1, 1, 1], "environment.color must be a list of 3 numbers"),
    (["environment"], "rotation", NAN, "environment.rotation must be a number, got nan"),
    (["environment"], "file", 7, "environment.file must be a non-empty string, got 7"),
    (["objects", 0], "radius", "1", "objects[0] (sphere): radius must be a number in (0, 1e+06], got '1'"),
    (["objects", 0], "radius", -1, "objects[0] (sphere): radius must be a number in (0, 1e+06], got -1"),
    (["objects", 0], "radius", 0, "radius must be a number in (0, 1e+06]"),
    (["objects", 0], "radius", 1e30, "radius must be a number in (0, 1e+06]"),
    (["objects", 0], "radius", 10**400, "radius must be a number in (0, 1e+06]"),
    (["lights", 0], "direction", [10**400, 0, 0], "lights[0]: direction must be a list of 3 numbers"),
    (["objects", 0], "center", [0, 0, "0"], "objects[0] (sphere): center must be a list of 3 numbers"),
    (["objects", 0], "material", ["red"], "objects[0] (sphere): material must be a non-empty string"),
    (["objects", 0], "type", 42, "objects[0]: unknown type 42"),
    (["objects", 1], "normal", [0, 0, 0], "objects[1] (plane): normal must be a list of 3 numbers, not all zero"),
    (["lights", 0], "intensity", "5", "lights[0]: intensity must be a number in [0, 1e+12], got '5'"),
    (["lights", 0], "intensity", -1, "lights[0]: intensity must be a number in [0, 1e+12], got -1"),
    (["lights", 0], "color", [1, 1], "lights[0]: color must be a list of 3 numbers"),
    (["lights", 0], "range", 0, "lights[0]: range must be a number in (0, 1e+06]"),
    (["lights", 0], "inner_cone_angle", True, "lights[0]: inner_cone_angle must be a number in [0, 1.5708]"),
    (["lights", 0], "direction", [0, 0, 0], "lights[0]: direction must be a list of 3 numbers, not all zero"),
    (["lights", 0], "type", 3, "lights[0]: type must be a non-empty string, got 3"),
    (["lights", 0], "falloff", "quadratic", "unknown light falloff 'quadratic'"),
]


def _scene_with(section, key, value):
    data = copy.deepcopy(BASE_SCENE)
    target = data
    for part in section:
        target = target[part]
    target[key] = value
    return data


@pytest.mark.parametrize("section, key, value, fragment", SCENE_CASES,
                         ids=[f"{'.'.join(map(str, s))}.{k}={v!r}"[:60] for s, k, v, _ in SCENE_CASES])
def test_scene_values_of_the_wrong_type_or_range_are_refused(tmp_path, section, key, value, fragment):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_scene_with(section, key, value)))
    out = tmp_path / "out.png"
    result, caught = render(path, "-o", out, *SMALL)
    assert_refused(result, caught, out, path, fragment)


def test_toml_scene_values_are_checked_too(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text('[materials.red]\nroughness = "0.5"\n[[objects]]\ntype = "sphere"\nmaterial = "red"\n')
    out = tmp_path / "out.exr"
    result, caught = render(path, "-o", out, *SMALL, "--mode", "reference", "--spp", "1")
    assert_refused(result, caught, out, path, "material 'red': roughness must be a number in [0, 1], got '0.5'")
    path.write_text("[camera]\nfov = nan\n[[objects]]\ntype = 'sphere'\n")
    result, caught = render(path, "-o", out, *SMALL)
    assert_refused(result, caught, out, path, "camera.fov must be a number of degrees in (0, 180), got nan")


SCENE_FILE_CASES = {
    "top level array": ("scene.json", "[1, 2]", "scene must be a table/object"),
    "empty JSON": ("scene.json", "", "invalid JSON"),
    "empty TOML": ("scene.toml", "", "scene has no objects"),
    "deep JSON": ("scene.json", "[" * 100000 + "]" * 100000, "invalid JSON"),
    "huge integer": ("scene.json", '{"camera": {"width": ' + "9" * 5000 + "}}", "invalid JSON"),
    "materials not a table": ("scene.json", '{"materials": 3, "objects": [{"type": "sphere"}]}',
                              "materials must be a table"),
    "objects not a list": ("scene.json", '{"objects": {"type": "sphere"}}', "objects must be an array"),
    "material not a table": ("scene.toml", "materials = {red = 3}\n[[objects]]\ntype = 'sphere'\n",
                             "materials.red must be a table/object"),
    "gltf object file not a string": ("scene.json", '{"objects": [{"type": "gltf", "file": 3}]}',
                                      "objects[0] (gltf): file must be a non-empty string, got 3"),
    "gltf object scale zero": ("scene.json", '{"objects": [{"type": "gltf", "file": "m.glb", "scale": 0}]}',
                               "objects[0] (gltf): scale must be a non-zero number"),
    "gltf object scale string": ("scene.json", '{"objects": [{"type": "gltf", "file": "m.glb", "scale": "2"}]}',
                                 "scale must be a non-zero number"),
    "gltf object zero rotation": ("scene.json", '{"objects": [{"type": "gltf", "file": "m.glb", '
                                                '"rotation": [0, 0, 0, 0]}]}', "rotation must be a list of 4"),
    "gltf object missing": ("scene.json", '{"objects": [{"type": "gltf", "file": "absent.glb"}]}',
                            "does not exist"),
}


@pytest.mark.parametrize("case", list(SCENE_FILE_CASES))
def test_broken_scene_files_are_refused(tmp_path, case):
    name, text, fragment = SCENE_FILE_CASES[case]
    path = tmp_path / name
    path.write_text(text)
    out = tmp_path / "out.png"
    result, caught = render(path, "-o", out, *SMALL)
    assert_refused(result, caught, out, path, fragment)


def test_refusals_in_a_real_process_print_one_line_and_nothing_else(tmp_path):
    """Outside pytest's warning capture: the real stderr of ``python -m pbrkit``."""
    (tmp_path / "model.gltf").write_text('{"hello": "world"}')
    (tmp_path / "scene.toml").write_text(scene_text("model.gltf"))
    out = tmp_path / "out.png"
    run = subprocess.run([sys.executable, "-m", "pbrkit", "render", str(tmp_path / "scene.toml"), "-o", str(out),
                          *SMALL], capture_output=True, text=True, timeout=300)
    assert run.returncode == 1
    assert run.stdout == ""
    assert run.stderr.count("\n") == 1 and run.stderr.startswith(f"pbrkit: error: {tmp_path / 'model.gltf'}: ")
    assert not out.exists()


# ------------------------------------------------------------------ memory


def _scene(width, height, supersample=1, source="scene.toml"):
    return Scene(camera=Camera(width=width, height=height, supersample=supersample),
                 environment=EnvironmentSpec(color=(1.0, 1.0, 1.0)), objects=(Sphere(),), source=source)


def test_memory_estimate_is_linear_in_rays_and_bake_texels():
    total, parts = estimate_render_memory(_scene(64, 32, 2), "reference")
    assert parts == {"rays": 64 * 32 * 4 * BYTES_PER_RAY["reference"], "bake": 0, "fixed": FIXED_BYTES}
    assert total == sum(parts.values())
    _, realtime = estimate_render_memory(_scene(64, 32), "realtime", bake_size=128)
    assert realtime["bake"] == 6 * 128 * 128 * 128 and realtime["rays"] == 64 * 32 * BYTES_PER_RAY["realtime"]
    assert estimate_render_memory(_scene(64, 32), "compare", 256)[0] > estimate_render_memory(_scene(64, 32),
                                                                                              "reference", 256)[0]


def test_a_small_render_passes_and_a_huge_one_is_refused_with_the_figure():
    assert check_render_memory(_scene(64, 64), "realtime", 64, available=1 << 30) < 1 << 30
    assert check_render_memory(_scene(64, 64), "compare", 64) > 0  # this machine has room for it
    huge = _scene(16384, 16384, 16)
    with pytest.raises(ValueError) as info:
        check_render_memory(huge, "reference", 64, available=21 << 30)
    message = str(info.value)
    need = 16384 * 16384 * 256 * BYTES_PER_RAY["reference"] + FIXED_BYTES
    assert message == (f"scene.toml: a 16384 x 16384 (supersample 16) reference render needs about "
                       f"{need / 2**30:.0f} GiB of memory; this machine has 21 GiB available; lower "
                       "--width/--height or the camera's supersample")
    with pytest.raises(ValueError, match=r"needs about 3\.\d GiB of memory; this machine has 512 MiB available; "
                                         "lower --width/--height or --bake-size"):
        check_render_memory(_scene(8, 8), "realtime", 1, bake_size=2048, available=512 << 20)


def test_available_memory_is_a_positive_figure_on_linux():
    free = available_memory()
    assert free is None or (isinstance(free, int) and free > 0)
    if sys.platform.startswith("linux"):
        assert free is not None


def test_the_cli_refuses_a_render_that_cannot_fit(tmp_path):
    path = tmp_path / "big.toml"
    path.write_text("[camera]\nwidth = 16384\nheight = 16384\nsupersample = 16\n[[objects]]\ntype = 'sphere'\n")
    out = tmp_path / "out.exr"
    result, caught = render(path, "-o", out, "--mode", "compare", "--spp", "1")
    assert_refused(result, caught, out, path, "a 16384 x 16384 (supersample 16) compare render needs about",
                   "GiB of memory; this machine has", "lower --width/--height or the camera's supersample")
    assert math.isfinite(float(result.stderr.split("needs about ")[1].split()[0]))
