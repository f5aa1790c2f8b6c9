"""glTF 2.0 scenes as world-space triangle meshes, materials and lights.

glTF 2.0 files (``.gltf`` with external or data-URI buffers, and ``.glb``)
are read with ``pygltflib`` following the glTF 2.0 specification
(Khronos, 2021): the default scene's node hierarchy with matrix or TRS
transforms (normals by the inverse transpose; the determinant's sign flips
the tangent handedness), triangle, strip and fan primitives, accessors with
byte strides, normalised integers and sparse substitution, flat normals
when NORMAL is absent, and the metallic-roughness material with all its
textures: baseColor (sRGB, times baseColorFactor), metallicRoughness
(G = roughness, B = metallic, times the factors), normal (tangent space,
+X right, +Y up, scaled by ``normalTexture.scale``), occlusion (R, applied
as 1 + strength (R - 1)) and emissive (sRGB, times emissiveFactor and
``KHR_materials_emissive_strength``).  ``KHR_lights_punctual`` lights are
read too.  Texture sampling follows the glTF sampler: bilinear (or
nearest) filtering of linear texel values at texel centres (sRGB texels are
decoded before filtering, as GPUs do), REPEAT / CLAMP_TO_EDGE /
MIRRORED_REPEAT wrapping, UV (0, 0) at the first (top-left) texel.  Minification filters and mip
maps are not used (supersample the camera instead).
"""

from __future__ import annotations

import base64
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.color import srgb_to_linear
from ..core.errors import InputError
from .lights import Light
from .scene import MaterialSpec, trs_matrix
from .tangents import mikktspace_tangents
from .textures import _WRAP_REPEAT, SurfaceMaterial, Texture, TextureRef

__all__ = [
    "Mesh",
    "GltfAsset",
    "load_gltf",
]

# ================================================================== glTF


@dataclass
class Mesh:
    """One triangle primitive in world space (float64)."""

    positions: np.ndarray          # (V, 3)
    normals: np.ndarray            # (V, 3) unit
    indices: np.ndarray            # (T, 3) int64
    material: int                  # index into the asset's materials
    texcoords: tuple = ()          # (V, 2) per TEXCOORD_n
    tangents: np.ndarray | None = None  # (V, 4): xyz unit, w = +-1


@dataclass
class GltfAsset:
    meshes: list
    materials: list      # SurfaceMaterial
    lights: list         # pbrkit.render.lights.Light
    notes: list


_COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_SUPPORTED_REQUIRED = {"KHR_lights_punctual", "KHR_materials_emissive_strength"}


class _GltfReader:
    def __init__(self, path):
        import pygltflib

        self.path = Path(path)
        try:
            self.g = pygltflib.GLTF2().load(str(path))
        except Exception as exc:  # pygltflib raises many kinds on corrupt files
            raise InputError(f"cannot read glTF file: {' '.join(str(exc).split()) or type(exc).__name__}",
                             path) from None
        if self.g is None:
            raise InputError("cannot read glTF file", path)
        self._buffers = {}
        self._images = {}
        self.notes = []
        required = set(self.g.extensionsRequired or [])
        unsupported = sorted(required - _SUPPORTED_REQUIRED)
        if unsupported:
            raise InputError(f"requires unsupported glTF extension(s): {', '.join(unsupported)}", path)
        used = sorted(set(self.g.extensionsUsed or []) - _SUPPORTED_REQUIRED)
        if used:
            self.notes.append(f"ignored optional extension(s): {', '.join(used)}")

    def fail(self, problem):
        raise InputError(problem, self.path)

    def _uri_bytes(self, uri):
        if uri.startswith("data:"):
            head, _, data = uri.partition(",")
            if not head.endswith(";base64"):
                self.fail("data URIs must be base64-encoded")
            return base64.b64decode(data)
        from urllib.parse import unquote

        p = self.path.parent / unquote(uri)
        try:
            return p.read_bytes()
        except OSError as exc:
            self.fail(f"cannot read referenced file {uri!r}: {exc.strerror or exc}")

    def buffer(self, index):
        if index not in self._buffers:
            b = self.g.buffers[index]
            if b.uri is None:
                data = self.g.binary_blob()
                if data is None:
                    self.fail(f"buffer {index} has no uri and the file has no binary chunk")
            else:
                data = self._uri_bytes(b.uri)
            if len(data) < b.byteLength:
                self.fail(f"buffer {index} holds {len(data)} bytes, fewer than its byteLength {b.byteLength}")
            self._buffers[index] = data
        return self._buffers[index]

    def view_bytes(self, index):
        v = self.g.bufferViews[index]
        data = self.buffer(v.buffer)
        start = v.byteOffset or 0
        if start + v.byteLength > len(data):
            self.fail(f"bufferView {index} runs past the end of buffer {v.buffer}")
        return data[start:start + v.byteLength], v.byteStride

    def _read_view(self, view, offset, count, dtype, ncomp):
        raw, stride = self.view_bytes(view)
        item = np.dtype(dtype).itemsize * ncomp
        stride = stride or item
        need = offset + (count - 1) * stride + item if count else 0
        if need > len(raw):
            self.fail(f"accessor data runs past the end of bufferView {view}")
        buf = np.frombuffer(raw, dtype=np.uint8, count=need - offset, offset=offset) if count else np.zeros(0,
                                                                                                            np.uint8)
        if stride == item:
            return np.frombuffer(buf.tobytes(), dtype=dtype).reshape(count, ncomp)
        rows = np.lib.stride_tricks.as_strided(buf, shape=(count, item), strides=(stride, 1))
        return np.frombuffer(np.ascontiguousarray(rows).tobytes(), dtype=dtype).reshape(count, ncomp)

    def accessor(self, index, normalize_ints=True):
        """Accessor data as float64 (or int64 for index data with ``normalize_ints=False``),
        shape (count, components); glTF 2.0 sec. 3.6 (normalised integers by sec. 3.11)."""
        a = self.g.accessors[index]
        dtype = _COMPONENT.get(a.componentType)
        if dtype is None or a.type not in _NCOMP:
            self.fail(f"accessor {index} has an unsupported component type {a.componentType} or type {a.type}")
        ncomp = _NCOMP[a.type]
        if a.bufferView is not None:
            data = self._read_view(a.bufferView, a.byteOffset or 0, a.count, dtype, ncomp)
        else:
            data = np.zeros((a.count, ncomp), dtype=dtype)
        if a.sparse is not None:
            s = a.sparse
            idx_type = _COMPONENT[s.indices.componentType]
            idx = self._read_view(s.indices.bufferView, s.indices.byteOffset or 0, s.count, idx_type, 1)[:, 0]
            vals = self._read_view(s.values.bufferView, s.values.byteOffset or 0, s.count, dtype, ncomp)
            data = data.copy()
            if np.any(idx.astype(np.int64) >= a.count):
                self.fail(f"accessor {index} has sparse indices out of range")
            data[idx.astype(np.int64)] = vals
        if not normalize_ints:
            return data.astype(np.int64)
        out = data.astype(np.float64)
        if a.normalized and dtype != np.float32:
            info = np.iinfo(dtype)
            out = out / info.max if info.min == 0 else np.maximum(out / info.max, -1.0)
        return out

    def image(self, index, srgb):
        """Texels (H, W, 4) float32 of image ``index``, sRGB-decoded when ``srgb``."""
        key = (index, srgb)
        if key not in self._images:
            import imageio.v3 as iio

            im = self.g.images[index]
            if im.bufferView is not None:
                data = self.view_bytes(im.bufferView)[0]
            elif im.uri:
                data = self._uri_bytes(im.uri)
            else:
                self.fail(f"image {index} has neither bufferView nor uri")
            try:
                pixels = np.asarray(iio.imread(data))
            except Exception as exc:
                self.fail(f"cannot decode image {index}: {' '.join(str(exc).split()) or type(exc).__name__}")
            if pixels.dtype == np.uint8:
                values = pixels.astype(np.float32) / 255.0
            elif pixels.dtype == np.uint16:
                values = pixels.astype(np.float32) / 65535.0
            else:
                values = pixels.astype(np.float32)
            if values.ndim == 2:
                values = values[..., None]
            c = values.shape[2]
            rgba = np.ones(values.shape[:2] + (4,), dtype=np.float32)
            if c in (1, 2):
                rgba[..., :3] = values[..., :1]
                if c == 2:
                    rgba[..., 3] = values[..., 1]
            else:
                rgba[..., :3] = values[..., :3]
                if c == 4:
                    rgba[..., 3] = values[..., 3]
            if srgb:
                rgba[..., :3] = srgb_to_linear(rgba[..., :3]).astype(np.float32)
            self._images[key] = rgba
        return self._images[key]

    def texture(self, index, srgb, cache):
        key = (index, srgb)
        if key not in cache:
            t = self.g.textures[index]
            if t.source is None:
                self.fail(f"texture {index} has no source image")
            wrap_s = wrap_t = _WRAP_REPEAT
            mag = None
            if t.sampler is not None:
                s = self.g.samplers[t.sampler]
                wrap_s = s.wrapS or _WRAP_REPEAT
                wrap_t = s.wrapT or _WRAP_REPEAT
                mag = s.magFilter
            cache[key] = (len(cache), Texture(self.image(t.source, srgb), wrap_s, wrap_t, mag))
        return cache[key][0]


def _node_matrix(node):
    if node.matrix is not None:
        return np.asarray(node.matrix, dtype=float).reshape(4, 4).T  # column-major in glTF
    return trs_matrix(node.translation or (0.0, 0.0, 0.0), node.rotation or (0.0, 0.0, 0.0, 1.0),
                      node.scale or (1.0, 1.0, 1.0))


def _triangles(mode, idx):
    if mode in (None, 4):
        if idx.size % 3:
            raise ValueError("TRIANGLES primitive with an index count not divisible by 3")
        return idx.reshape(-1, 3)
    if mode == 5:  # TRIANGLE_STRIP (glTF 2.0 sec. 3.7.2.1): alternate winding
        k = np.arange(max(idx.size - 2, 0))
        a = idx[k]
        b = np.where(k % 2 == 0, idx[k + 1], idx[k + 2])
        c = np.where(k % 2 == 0, idx[k + 2], idx[k + 1])
        return np.stack([a, b, c], axis=1)
    if mode == 6:  # TRIANGLE_FAN
        k = np.arange(1, max(idx.size - 1, 1))
        return np.stack([np.full(k.size, idx[0]), idx[k], idx[k + 1]], axis=1) if idx.size >= 3 else \
            np.zeros((0, 3), np.int64)
    return None


def _gltf_material(reader, index, cache):
    g = reader.g
    if index is None:
        return SurfaceMaterial(MaterialSpec(name="gltf-default", base_color=(1.0, 1.0, 1.0), metallic=1.0,
                                            roughness=1.0))
    m = g.materials[index]
    pbr = m.pbrMetallicRoughness
    bc = (1.0, 1.0, 1.0, 1.0)
    metallic = roughness = 1.0
    bct = mrt = None
    if pbr is not None:
        bc = pbr.baseColorFactor if pbr.baseColorFactor is not None else bc
        metallic = 1.0 if pbr.metallicFactor is None else pbr.metallicFactor
        roughness = 1.0 if pbr.roughnessFactor is None else pbr.roughnessFactor
        if pbr.baseColorTexture is not None:
            bct = TextureRef(reader.texture(pbr.baseColorTexture.index, True, cache),
                             pbr.baseColorTexture.texCoord or 0)
        if pbr.metallicRoughnessTexture is not None:
            mrt = TextureRef(reader.texture(pbr.metallicRoughnessTexture.index, False, cache),
                             pbr.metallicRoughnessTexture.texCoord or 0)
    nt = ot = et = None
    if m.normalTexture is not None:
        nt = TextureRef(reader.texture(m.normalTexture.index, False, cache), m.normalTexture.texCoord or 0,
                        1.0 if m.normalTexture.scale is None else m.normalTexture.scale)
    if m.occlusionTexture is not None:
        ot = TextureRef(reader.texture(m.occlusionTexture.index, False, cache), m.occlusionTexture.texCoord or 0,
                        1.0 if m.occlusionTexture.strength is None else m.occlusionTexture.strength)
    if m.emissiveTexture is not None:
        et = TextureRef(reader.texture(m.emissiveTexture.index, True, cache), m.emissiveTexture.texCoord or 0)
    emissive = np.asarray(m.emissiveFactor if m.emissiveFactor is not None else (0.0, 0.0, 0.0), dtype=float)
    strength = (m.extensions or {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    if (m.alphaMode or "OPAQUE") != "OPAQUE":
        reader.notes.append(f"material {index}: alphaMode {m.alphaMode} rendered as OPAQUE")
    name = m.name or f"gltf-material-{index}"
    try:
        spec = MaterialSpec(name=name, base_color=tuple(bc[:3]), metallic=metallic, roughness=roughness,
                            emissive=tuple(emissive * float(strength)), double_sided=bool(m.doubleSided))
    except ValueError as exc:
        reader.fail(str(exc))
    return SurfaceMaterial(spec, bct, mrt, nt, ot, et)


def load_gltf(path, transform=None):
    """Read a glTF 2.0 file into world-space triangle meshes, materials and lights.

    ``transform`` (4 x 4) is applied on top of the file's node transforms.
    Problems raise :class:`pbrkit.core.errors.InputError` naming the file."""
    reader = _GltfReader(path)
    g = reader.g
    top = np.eye(4) if transform is None else np.asarray(transform, dtype=float)
    texture_cache = {}
    materials = [_gltf_material(reader, i, texture_cache) for i in range(len(g.materials or []))]
    default_material = None
    meshes = []
    lights = []
    light_defs = ((g.extensions or {}).get("KHR_lights_punctual") or {}).get("lights", [])
    if g.scenes:
        roots = g.scenes[g.scene or 0].nodes or []
    else:
        children = {c for n in g.nodes for c in (n.children or [])}
        roots = [i for i in range(len(g.nodes)) if i not in children]
    stack = [(i, top) for i in roots]
    visited = 0
    while stack:
        ni, parent = stack.pop()
        visited += 1
        if visited > 1_000_000:
            reader.fail("node hierarchy has a cycle")
        node = g.nodes[ni]
        world = parent @ _node_matrix(node)
        stack.extend((c, world) for c in (node.children or []))
        ext = (node.extensions or {}).get("KHR_lights_punctual")
        if ext is not None and "light" in ext:
            lights.append(_gltf_light(reader, light_defs, ext["light"], world))
        if node.mesh is None:
            continue
        m3 = world[:3, :3]
        det = float(np.linalg.det(m3))
        if det == 0.0:
            reader.notes.append(f"node {ni}: singular transform, mesh skipped")
            continue
        normal_matrix = np.linalg.inv(m3).T
        for pi, prim in enumerate(g.meshes[node.mesh].primitives):
            attrs = prim.attributes
            if attrs.POSITION is None:
                reader.fail(f"mesh {node.mesh} primitive {pi} has no POSITION")
            pos = reader.accessor(attrs.POSITION)
            if prim.indices is not None:
                idx = reader.accessor(prim.indices, normalize_ints=False)[:, 0]
            else:
                idx = np.arange(pos.shape[0], dtype=np.int64)
            try:
                tri = _triangles(prim.mode, idx)
            except ValueError as exc:
                reader.fail(f"mesh {node.mesh} primitive {pi}: {exc}")
            if tri is None:
                reader.notes.append(f"mesh {node.mesh} primitive {pi}: mode {prim.mode} (points/lines) skipped")
                continue
            if tri.size and (tri.max() >= pos.shape[0] or tri.min() < 0):
                reader.fail(f"mesh {node.mesh} primitive {pi} has indices out of range")
            if prim.targets:
                reader.notes.append(f"mesh {node.mesh}: morph targets ignored (base shape rendered)")
            texcoords = []
            for name in ("TEXCOORD_0", "TEXCOORD_1"):
                acc = getattr(attrs, name, None)
                if acc is None:
                    break
                texcoords.append(reader.accessor(acc)[:, :2])
            normals = reader.accessor(attrs.NORMAL)[:, :3] if attrs.NORMAL is not None else None
            tangents = reader.accessor(attrs.TANGENT)[:, :4] if attrs.TANGENT is not None else None
            if normals is None:
                # glTF 2.0 sec. 3.7.2.1: flat normals when NORMAL is absent -> unshared vertices
                pos = pos[tri.reshape(-1)]
                texcoords = [t[tri.reshape(-1)] for t in texcoords]
                tangents = None if tangents is None else tangents[tri.reshape(-1)]
                tri = np.arange(pos.shape[0], dtype=np.int64).reshape(-1, 3)
                e1 = pos[tri[:, 1]] - pos[tri[:, 0]]
                e2 = pos[tri[:, 2]] - pos[tri[:, 0]]
                fn = np.cross(e1, e2)
                fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
                normals = np.repeat(fn, 3, axis=0)
            mat_index = prim.material
            if mat_index is None:
                if default_material is None:
                    materials.append(_gltf_material(reader, None, texture_cache))
                    default_material = len(materials) - 1
                mat_index = default_material
            material = materials[mat_index]
            if material.normal_texture is not None and tangents is None:
                tc = material.normal_texture.texcoord
                if tc >= len(texcoords):
                    reader.fail(f"mesh {node.mesh} primitive {pi}: normal texture uses TEXCOORD_{tc}, "
                                "which the primitive lacks")
                tangents = mikktspace_tangents(pos, normals, texcoords[tc], tri)
            wpos = pos @ world[:3, :3].T + world[:3, 3]
            wn = normals @ normal_matrix.T
            wn /= np.maximum(np.linalg.norm(wn, axis=1, keepdims=True), 1e-300)
            wt = None
            if tangents is not None:
                t3 = tangents[:, :3] @ m3.T
                t3 /= np.maximum(np.linalg.norm(t3, axis=1, keepdims=True), 1e-300)
                w = np.where(tangents[:, 3] < 0.0, -1.0, 1.0) * (1.0 if det > 0 else -1.0)
                wt = np.concatenate([t3, w[:, None]], axis=1)
            meshes.append(Mesh(wpos, wn, tri.astype(np.int64), mat_index, tuple(texcoords), wt))
    textures = [t for _, t in sorted(texture_cache.values(), key=lambda e: e[0])]
    for m in materials:
        m.textures = textures
    return GltfAsset(meshes, materials, lights, reader.notes)


def _gltf_light(reader, defs, index, world):
    if not isinstance(index, int) or not 0 <= index < len(defs):
        reader.fail(f"KHR_lights_punctual light index {index!r} out of range")
    d = defs[index]
    kind = d.get("type")
    position = world[:3, 3]
    direction = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
    spot = d.get("spot", {}) or {}
    try:
        return Light(type=kind, color=tuple(d.get("color", (1.0, 1.0, 1.0))), intensity=d.get("intensity", 1.0),
                     position=tuple(position), direction=tuple(direction), range=d.get("range"),
                     inner_cone_angle=spot.get("innerConeAngle", 0.0),
                     outer_cone_angle=spot.get("outerConeAngle", np.pi / 4.0))
    except (TypeError, ValueError) as exc:
        reader.fail(f"KHR_lights_punctual light {index}: {exc}")


