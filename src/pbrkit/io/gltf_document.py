"""glTF 2.0 documents: reading the ``.gltf`` / ``.glb`` container and checking the
whole document against the glTF 2.0 specification (Khronos, 2021) before any
of its data is used (:mod:`pbrkit.rendering.gltf` builds meshes, materials and
lights from a checked document).

:func:`read_gltf_document` parses the container (a ``.glb`` is recognised by
its magic: header, JSON chunk, optional BIN chunk; glTF 2.0 sec. 4.4) and the
JSON; :func:`validate_gltf_document` checks every index (an integer, not a
bool or float, within its array), the node hierarchy (a forest), the
enumerations and numeric ranges, each textureInfo's ``KHR_texture_transform``
(:func:`pbrkit.io.gltf_extensions.check_texture_transform`), and that every
accessor and sparse part lies inside its bufferView and every bufferView inside
its buffer; each problem is a ValueError naming its JSON location (the caller
adds the file name).
"""

from __future__ import annotations

import json
import math
import re
import struct
from pathlib import Path

import numpy as np

from ..core.inputs import check_allocation, check_regular, read_bytes, size_text
from ..core.filtering import CLAMP_TO_EDGE as _WRAP_CLAMP
from ..core.filtering import MIRRORED_REPEAT as _WRAP_MIRROR
from ..core.filtering import REPEAT as _WRAP_REPEAT
from ..rendering.lights import LIGHT_TYPES
from .gltf_fields import (
    _UBYTE,
    _USHORT,
    _UINT,
    _COMPONENT,
    _COMPONENT_NAMES,
    _NCOMP,
    COMPONENT_TYPES,
    COMPONENT_NAMES,
    COMPONENT_COUNTS,
    _shown,
    _json_kind,
    _is_int,
    _object,
    _array,
    _integer,
    _number,
    _numbers,
    _choice,
    _boolean,
    _string,
    _Indices,
)
from .gltf_extensions import check_texture_info
from .gltf_materials import check_material_extensions
from .gltf_resources import data_uri_bytes

__all__ = ["MAX_GLTF_BYTES", "read_gltf_document", "validate_gltf_document", "data_uri_bytes", "COMPONENT_TYPES",
           "COMPONENT_NAMES", "COMPONENT_COUNTS"]


# ============================================================ the container

_GLB_MAGIC = b"glTF"
#: Largest .gltf / .glb file read: 2 GiB (a .glb's length field is 32 bits, so at most
#: 4 GiB; real models are well under 1 GiB).
MAX_GLTF_BYTES = 2 << 30
#: Peak memory of reading a glTF file, in multiples of its size: its bytes, the decoded
#: JSON text and the parsed document (JSON strings, such as data: URIs, are held once
#: more as Python str).  A floor: JSON made of many tiny objects or numbers takes more as
#: Python objects (up to about 20 times its text), which only MAX_GLTF_BYTES bounds.
_READ_FACTOR = 3
_CHUNK_JSON = 0x4E4F534A
_CHUNK_BIN = 0x004E4942


def read_gltf_document(path):
    """``(document, binary chunk or None)`` of a ``.gltf`` or ``.glb`` file (a
    ``.glb`` is recognised by its magic; the binary chunk is a ``memoryview``).

    The file must be a regular file of at most :data:`MAX_GLTF_BYTES` (a symbolic
    link to ``/dev/zero`` or a pipe is refused before it is read), and the memory
    it needs (:data:`_READ_FACTOR` times its size: its bytes, the decoded JSON text
    and the parsed document) is checked first.  :class:`pbrkit.core.errors.InputError`
    naming ``path`` for those; ValueError naming the problem for the content."""
    path = Path(path)
    expected = "a glTF 2.0 file (.gltf JSON or .glb binary glTF)"
    size = check_regular(path, expected)
    if size <= MAX_GLTF_BYTES:
        check_allocation(size * _READ_FACTOR, f"reading this {size_text(size)} glTF file", path)
    data = read_bytes(path, MAX_GLTF_BYTES, expected)
    if not data:
        raise ValueError("the file is empty (0 bytes); expected glTF 2.0 JSON or binary glTF")
    if data[:4] == _GLB_MAGIC:
        return _parse_glb(memoryview(data))
    if path.suffix.lower() == ".glb":
        raise ValueError("not a binary glTF file: its first 4 bytes are not the magic b'glTF' (glTF 2.0 sec. 4.4.3.1)")
    return _parse_json(data, "the file"), None


def _parse_glb(data):
    """Split a binary glTF (glTF 2.0 sec. 4.4: a 12-byte header, then chunks of an
    8-byte header and their data, the JSON chunk first and an optional BIN chunk
    second) into its JSON document and BIN chunk (a view of ``data``, not a copy)."""
    if len(data) < 12:
        raise ValueError(f"truncated binary glTF: {len(data)} bytes, shorter than its 12-byte header")
    _, version, length = struct.unpack_from("<4sII", data)
    if version != 2:
        raise ValueError(f"binary glTF container version {version} is not supported (pbrkit reads version 2)")
    if length > len(data):
        raise ValueError(f"truncated binary glTF: its header says {length} bytes, the file has {len(data)}")
    chunks = []
    offset = 12
    while offset < length:
        if offset + 8 > length:
            raise ValueError(f"truncated binary glTF: chunk {len(chunks)} has an incomplete header")
        size, kind = struct.unpack_from("<II", data, offset)
        start = offset + 8
        if start + size > length:
            raise ValueError(f"truncated binary glTF: chunk {len(chunks)} ({size} bytes) runs past the end "
                             f"of the file ({length} bytes)")
        chunks.append((kind, data[start:start + size]))
        offset = start + size
    if not chunks or chunks[0][0] != _CHUNK_JSON:
        raise ValueError("binary glTF without a JSON chunk first")
    blob = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == _CHUNK_BIN else None
    return _parse_json(bytes(chunks[0][1]), "the JSON chunk"), blob


def _reject_constant(name):
    raise ValueError(f"{name} is not a JSON number")


def _parse_json(raw, what):
    """The JSON object of a glTF document (``what`` names where it came from)."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"not a glTF file: {what} is not UTF-8 text (glTF JSON or binary glTF expected)") from None
    try:
        doc = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not a glTF file: invalid JSON in {what}: {exc.msg} (line {exc.lineno}, column "
                         f"{exc.colno})") from None
    except (ValueError, RecursionError) as exc:  # NaN / Infinity, huge integers, deep nesting
        raise ValueError(f"not a glTF file: invalid JSON in {what}: {exc}") from None
    if not isinstance(doc, dict):
        raise ValueError(f"not a glTF file: the JSON is {_json_kind(doc)}, not an object with an 'asset'")
    return doc



# ============================================================ validation
# Every check raises ValueError("<JSON location> <problem>"); the reader adds the file name.

#: The top-level arrays (glTF 2.0 sec. 5.17).
_ARRAYS = ("accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials", "meshes",
           "nodes", "samplers", "scenes", "skins", "textures")
_LIGHTS = "KHR_lights_punctual lights"
_MAG_FILTERS = (9728, 9729)
_MIN_FILTERS = (9728, 9729, 9984, 9985, 9986, 9987)
_WRAPS = (_WRAP_CLAMP, _WRAP_MIRROR, _WRAP_REPEAT)
_ALPHA_MODES = ("OPAQUE", "MASK", "BLEND")


def validate_gltf_document(doc):
    """Check a glTF document (module docstring) before anything is read from it."""
    _check_asset(doc.get("asset"))
    for key in ("extensionsUsed", "extensionsRequired"):
        if doc.get(key) is not None:
            for i, name in enumerate(_array(doc[key], key)):
                _string(name, f"{key}[{i}]")
    if doc.get("extensions") is not None:
        _object(doc["extensions"], "extensions")
    arrays = {name: _array(doc[name], name, of_objects=True) if doc.get(name) is not None else []
              for name in _ARRAYS}
    lights = _light_definitions(doc)
    counts = {name: len(items) for name, items in arrays.items()}
    counts[_LIGHTS] = len(lights)
    index = _Indices(counts)
    if doc.get("scene") is not None:
        index(doc["scene"], "scene", "scenes")
    checks = {"scenes": _check_scene, "nodes": _check_node, "meshes": _check_mesh, "accessors": _check_accessor,
              "bufferViews": _check_buffer_view, "buffers": _check_buffer, "images": _check_image,
              "textures": _check_texture, "samplers": _check_sampler, "materials": _check_material,
              "skins": _check_skin, "animations": _check_animation}
    for name, check in checks.items():
        for i, item in enumerate(arrays[name]):
            check(item, f"{name}[{i}]", index)
    for i, light in enumerate(lights):
        _check_light(light, f"extensions.KHR_lights_punctual.lights[{i}]")
    _check_hierarchy(arrays["nodes"], arrays["scenes"])
    _check_ranges(arrays)


def _check_asset(asset):
    if asset is None:
        raise ValueError("not a glTF 2.0 file: it has no 'asset' object (a glTF file is a JSON object with "
                         "\"asset\": {\"version\": \"2.0\"}, scenes, nodes and meshes)")
    _object(asset, "asset")
    version = asset.get("version")
    if not isinstance(version, str) or not re.fullmatch(r"\d+\.\d+", version):
        raise ValueError(f"asset.version must be a string like \"2.0\"; got {_shown(version)}")
    if version.split(".")[0] != "2":
        raise ValueError(f"glTF version {version} is not supported (pbrkit reads glTF 2.x)")
    minimum = asset.get("minVersion")
    if minimum is not None and minimum != "2.0":
        raise ValueError(f"the file needs glTF {_shown(minimum)} (asset.minVersion); pbrkit reads glTF 2.0")


def _light_definitions(doc):
    """The ``KHR_lights_punctual`` light definitions (validated as objects)."""
    ext = doc.get("extensions")
    if ext is None or ext.get("KHR_lights_punctual") is None:
        return []
    where = "extensions.KHR_lights_punctual"
    lights = _object(ext["KHR_lights_punctual"], where).get("lights")
    return [] if lights is None else _array(lights, f"{where}.lights", of_objects=True)


def _check_light(light, where):
    _choice(light.get("type"), f"{where}.type", LIGHT_TYPES)
    if light.get("color") is not None:
        _numbers(light["color"], f"{where}.color", 3, 0.0)
    if light.get("intensity") is not None:
        _number(light["intensity"], f"{where}.intensity", 0.0)
    if light.get("range") is not None:
        _number(light["range"], f"{where}.range", 0.0)
        if light["range"] <= 0.0:
            raise ValueError(f"{where}.range must be positive; got {_shown(light['range'])}")
    if light.get("spot") is not None:
        spot = _object(light["spot"], f"{where}.spot")
        for key in ("innerConeAngle", "outerConeAngle"):
            if spot.get(key) is not None:
                _number(spot[key], f"{where}.spot.{key}", 0.0, math.pi / 2.0)


def _check_scene(scene, where, index):
    index.many(scene, "nodes", where, "nodes")


def _check_node(node, where, index):
    index.many(node, "children", where, "nodes")
    for key, array in (("mesh", "meshes"), ("camera", "cameras"), ("skin", "skins")):
        index.optional(node, key, where, array)
    for key, n in (("matrix", 16), ("translation", 3), ("rotation", 4), ("scale", 3)):
        if node.get(key) is not None:
            _numbers(node[key], f"{where}.{key}", n)
    if node.get("rotation") is not None and not any(node["rotation"]):
        raise ValueError(f"{where}.rotation must be a unit quaternion (x, y, z, w); got {_shown(node['rotation'])}")
    ext = node.get("extensions")
    if ext is not None and _object(ext, f"{where}.extensions").get("KHR_lights_punctual") is not None:
        light = _object(ext["KHR_lights_punctual"], f"{where}.extensions.KHR_lights_punctual")
        index.required(light, "light", f"{where}.extensions.KHR_lights_punctual", _LIGHTS)


def _check_mesh(mesh, where, index):
    primitives = mesh.get("primitives")
    if primitives is None or not _array(primitives, f"{where}.primitives", of_objects=True):
        raise ValueError(f"{where}.primitives must be a non-empty array of primitives")
    for j, prim in enumerate(primitives):
        _check_primitive(prim, f"{where}.primitives[{j}]", index)


def _check_primitive(prim, where, index):
    attributes = prim.get("attributes")
    if attributes is None:
        raise ValueError(f"{where} has no attributes")
    for name, value in _object(attributes, f"{where}.attributes").items():
        index(value, f"{where}.attributes.{name}", "accessors")
    index.optional(prim, "indices", where, "accessors")
    index.optional(prim, "material", where, "materials")
    if prim.get("mode") is not None:
        _integer(prim["mode"], f"{where}.mode", 0, 6)
    if prim.get("targets") is not None:
        for k, target in enumerate(_array(prim["targets"], f"{where}.targets", of_objects=True)):
            for name, value in target.items():
                index(value, f"{where}.targets[{k}].{name}", "accessors")


def _check_accessor(acc, where, index):
    index.optional(acc, "bufferView", where, "bufferViews")
    if acc.get("byteOffset") is not None:
        _integer(acc["byteOffset"], f"{where}.byteOffset")
    component = acc.get("componentType")
    if not _is_int(component) or component not in _COMPONENT:
        known = ", ".join(f"{k} ({v})" for k, v in _COMPONENT_NAMES.items())
        raise ValueError(f"{where}.componentType must be one of {known}; got {_shown(component)}")
    if acc.get("normalized") is not None:
        _boolean(acc["normalized"], f"{where}.normalized")
    _integer(acc.get("count"), f"{where}.count", 1)
    _choice(acc.get("type"), f"{where}.type", tuple(_NCOMP))
    if acc.get("sparse") is not None:
        _check_sparse(_object(acc["sparse"], f"{where}.sparse"), f"{where}.sparse", acc["count"], index)


def _check_sparse(sparse, where, count, index):
    _integer(sparse.get("count"), f"{where}.count", 1, count)
    for part in ("indices", "values"):
        if sparse.get(part) is None:
            raise ValueError(f"{where} has no {part}")
        obj = _object(sparse[part], f"{where}.{part}")
        index.required(obj, "bufferView", f"{where}.{part}", "bufferViews")
        if obj.get("byteOffset") is not None:
            _integer(obj["byteOffset"], f"{where}.{part}.byteOffset")
    component = sparse["indices"].get("componentType")
    if not _is_int(component) or component not in (_UBYTE, _USHORT, _UINT):
        raise ValueError(f"{where}.indices.componentType must be 5121 (UNSIGNED_BYTE), 5123 (UNSIGNED_SHORT) "
                         f"or 5125 (UNSIGNED_INT); got {_shown(component)}")


def _check_buffer_view(view, where, index):
    index.required(view, "buffer", where, "buffers")
    if view.get("byteOffset") is not None:
        _integer(view["byteOffset"], f"{where}.byteOffset")
    _integer(view.get("byteLength"), f"{where}.byteLength", 1)
    stride = view.get("byteStride")
    if stride is not None and (not _is_int(stride) or not 4 <= stride <= 252 or stride % 4):
        raise ValueError(f"{where}.byteStride must be a multiple of 4 from 4 to 252; got {_shown(stride)}")


def _check_buffer(buffer, where, index):
    _integer(buffer.get("byteLength"), f"{where}.byteLength", 1)
    if buffer.get("uri") is not None:
        _string(buffer["uri"], f"{where}.uri")


def _check_image(image, where, index):
    index.optional(image, "bufferView", where, "bufferViews")
    if image.get("uri") is not None:
        _string(image["uri"], f"{where}.uri")
    if image.get("uri") is None and image.get("bufferView") is None:
        raise ValueError(f"{where} has neither a uri nor a bufferView")


def _check_texture(texture, where, index):
    index.optional(texture, "sampler", where, "samplers")
    index.optional(texture, "source", where, "images")


def _check_sampler(sampler, where, index):
    for key, choices in (("magFilter", _MAG_FILTERS), ("minFilter", _MIN_FILTERS), ("wrapS", _WRAPS),
                         ("wrapT", _WRAPS)):
        if sampler.get(key) is not None:
            _choice(sampler[key], f"{where}.{key}", choices)


def _check_material(material, where, index):
    pbr = material.get("pbrMetallicRoughness")
    if pbr is not None:
        w = f"{where}.pbrMetallicRoughness"
        _object(pbr, w)
        if pbr.get("baseColorFactor") is not None:
            _numbers(pbr["baseColorFactor"], f"{w}.baseColorFactor", 4, 0.0, 1.0)
        for key in ("metallicFactor", "roughnessFactor"):
            if pbr.get(key) is not None:
                _number(pbr[key], f"{w}.{key}", 0.0, 1.0)
        for key in ("baseColorTexture", "metallicRoughnessTexture"):
            if pbr.get(key) is not None:
                check_texture_info(pbr[key], f"{w}.{key}", index)
    for key in ("normalTexture", "occlusionTexture", "emissiveTexture"):
        if material.get(key) is not None:
            check_texture_info(material[key], f"{where}.{key}", index)
    if material.get("normalTexture") is not None and material["normalTexture"].get("scale") is not None:
        _number(material["normalTexture"]["scale"], f"{where}.normalTexture.scale")
    if material.get("occlusionTexture") is not None and material["occlusionTexture"].get("strength") is not None:
        _number(material["occlusionTexture"]["strength"], f"{where}.occlusionTexture.strength", 0.0, 1.0)
    if material.get("emissiveFactor") is not None:
        _numbers(material["emissiveFactor"], f"{where}.emissiveFactor", 3, 0.0, 1.0)
    if material.get("alphaMode") is not None:
        _choice(material["alphaMode"], f"{where}.alphaMode", _ALPHA_MODES)
    if material.get("alphaCutoff") is not None:
        _number(material["alphaCutoff"], f"{where}.alphaCutoff", 0.0)
    if material.get("doubleSided") is not None:
        _boolean(material["doubleSided"], f"{where}.doubleSided")
    ext = material.get("extensions")
    if ext is not None and _object(ext, f"{where}.extensions").get("KHR_materials_emissive_strength") is not None:
        w = f"{where}.extensions.KHR_materials_emissive_strength"
        strength = _object(ext["KHR_materials_emissive_strength"], w).get("emissiveStrength")
        if strength is not None:
            _number(strength, f"{w}.emissiveStrength", 0.0)
    if ext is not None:
        check_material_extensions(ext, f"{where}.extensions", index)


def _check_skin(skin, where, index):
    index.many(skin, "joints", where, "nodes")
    index.optional(skin, "skeleton", where, "nodes")
    index.optional(skin, "inverseBindMatrices", where, "accessors")


def _check_animation(animation, where, index):
    samplers = _array(animation.get("samplers") or [], f"{where}.samplers", of_objects=True)
    for k, sampler in enumerate(samplers):
        index.required(sampler, "input", f"{where}.samplers[{k}]", "accessors")
        index.required(sampler, "output", f"{where}.samplers[{k}]", "accessors")
    local = _Indices({"samplers of this animation": len(samplers), "nodes": index.counts["nodes"]})
    for k, channel in enumerate(_array(animation.get("channels") or [], f"{where}.channels", of_objects=True)):
        local.required(channel, "sampler", f"{where}.channels[{k}]", "samplers of this animation")
        target = channel.get("target")
        if target is not None:
            local.optional(_object(target, f"{where}.channels[{k}].target"), "node", f"{where}.channels[{k}].target",
                           "nodes")


def _check_hierarchy(nodes, scenes):
    """The nodes form a forest: no node is its own ancestor or has two parents, and
    the nodes a scene lists are roots (glTF 2.0 sec. 3.5.1)."""
    parent = {}
    for i, node in enumerate(nodes):
        for child in node.get("children") or []:
            if child == i:
                raise ValueError(f"nodes[{i}] lists itself as a child (the node hierarchy has a cycle)")
            if child in parent:
                raise ValueError(f"nodes[{child}] is a child of both nodes[{parent[child]}] and nodes[{i}] "
                                 "(a node has at most one parent)")
            parent[child] = i
    state = [0] * len(nodes)  # 0: unseen, 1: on the current parent chain, 2: known to reach a root
    for start in range(len(nodes)):
        chain = []
        k = start
        while k is not None and state[k] == 0:
            state[k] = 1
            chain.append(k)
            k = parent.get(k)
        if k is not None and state[k] == 1:
            raise ValueError(f"the node hierarchy has a cycle through nodes[{k}]")
        for c in chain:
            state[c] = 2
    for s, scene in enumerate(scenes):
        for root in scene.get("nodes") or []:
            if root in parent:
                raise ValueError(f"scenes[{s}].nodes lists nodes[{root}], which is a child of nodes[{parent[root]}] "
                                 "(a scene lists root nodes only)")


def _check_ranges(arrays):
    """Every bufferView inside its buffer, every accessor (and sparse part) inside its bufferView."""
    buffers, views = arrays["buffers"], arrays["bufferViews"]
    for i, view in enumerate(views):
        start = view.get("byteOffset") or 0
        size = buffers[view["buffer"]]["byteLength"]
        if start + view["byteLength"] > size:
            raise ValueError(f"bufferViews[{i}] (bytes {start} to {start + view['byteLength']}) runs past the end "
                             f"of buffers[{view['buffer']}] ({size} bytes)")
    for i, acc in enumerate(arrays["accessors"]):
        where = f"accessors[{i}]"
        item = np.dtype(_COMPONENT[acc["componentType"]]).itemsize * _NCOMP[acc["type"]]
        if acc.get("bufferView") is not None:
            view = views[acc["bufferView"]]
            stride = view.get("byteStride") or item
            if stride < item:
                raise ValueError(f"{where}: bufferViews[{acc['bufferView']}].byteStride {stride} is smaller than "
                                 f"one {acc['type']} {_COMPONENT_NAMES[acc['componentType']]} element ({item} bytes)")
            _inside(where, acc, acc["count"], item, stride, acc["bufferView"], view)
        sparse = acc.get("sparse")
        if sparse is not None:
            isize = np.dtype(_COMPONENT[sparse["indices"]["componentType"]]).itemsize
            for part, size in (("indices", isize), ("values", item)):
                obj = sparse[part]
                _inside(f"{where}.sparse.{part}", obj, sparse["count"], size, size, obj["bufferView"],
                        views[obj["bufferView"]])


def _inside(where, obj, count, item, stride, view_index, view):
    start = obj.get("byteOffset") or 0
    end = start + (count - 1) * stride + item
    if end > view["byteLength"]:
        raise ValueError(f"{where} ({count} elements of {item} bytes, byteOffset {start}, stride {stride}) needs "
                         f"{end} bytes, past the end of bufferViews[{view_index}] ({view['byteLength']} bytes)")
