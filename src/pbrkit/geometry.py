"""Scene geometry for the renderer: analytic spheres and planes, glTF 2.0
triangle meshes, ray casting and the surface data at hit points.

- Spheres and infinite planes are intersected analytically in compiled
  kernels (spheres through a bounding-volume hierarchy stored with skip
  pointers, so traversal needs no stack), with the numerically careful
  ray/sphere solution of Haines, Günther and Akenine-Möller, "Precision
  Improvements for Ray/Sphere Intersection", Ray Tracing Gems (2019), ch. 7.
- Triangles are cast against with Embree (Intel's ray-tracing kernels,
  through the ``embreex`` bindings), closest hit and any hit (occlusion).
- glTF 2.0 files (``.gltf`` with external or data-URI buffers, and ``.glb``)
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
- Tangents, when a primitive has a normal texture but no TANGENT attribute,
  are generated the way MikkTSpace does (Mikkelsen, "Simulation of Wrinkled
  Surfaces Revisited", MSc thesis, 2008; the reference implementation
  ``mikktspace.c``): per face corner the texture-space derivative dp/du is
  projected into the tangent plane of the vertex normal and normalised,
  weighted by the corner's angle and averaged over the corners that share a
  vertex *and* the orientation (handedness) of their texture mapping; the
  sign w makes B = w (N x T) point along dp/dv' with v' = 1 - v, the
  convention glTF normal maps use (+Y is up in the image, and glTF's v
  grows downward).  The bitangent is rebuilt per pixel from the
  interpolated N and T, as MikkTSpace requires.
"""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from numba.extending import register_jitable

from ._jit import parallel_kernel
from .errors import InputError
from .imageio import srgb_to_linear
from .lights import Light
from .scene import GltfObject, MaterialSpec, Plane, Sphere, trs_matrix

__all__ = [
    "KIND_NONE",
    "KIND_SPHERE",
    "KIND_PLANE",
    "KIND_TRIANGLE",
    "Hits",
    "Surface",
    "Texture",
    "TextureRef",
    "SurfaceMaterial",
    "Mesh",
    "GltfAsset",
    "load_gltf",
    "mikktspace_tangents",
    "Geometry",
    "build_sphere_bvh",
]

KIND_NONE, KIND_SPHERE, KIND_PLANE, KIND_TRIANGLE = 0, 1, 2, 3
_INF = np.inf


# ============================================================ analytic primitives


def build_sphere_bvh(centers, radii, leaf_size=2):
    """Bounding-volume hierarchy over spheres, flattened in depth-first order with
    skip pointers (the "threaded" layout: a hit on node i continues at i + 1, a
    miss or a finished leaf at ``skip[i]``).  Median split on the longest axis
    of the centres' bounds.  Returns ``(box_min (K, 3), box_max (K, 3), skip (K,),
    first (K,), count (K,), order (S,))``; a leaf holds spheres
    ``order[first:first + count]`` (count 0 for inner nodes)."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    radii = np.asarray(radii, dtype=float).reshape(-1)
    lo_all = centers - radii[:, None]
    hi_all = centers + radii[:, None]
    nodes = []  # [lo, hi, skip, first, count]
    order = []

    def build(index):
        node = len(nodes)
        nodes.append([lo_all[index].min(axis=0), hi_all[index].max(axis=0), 0, 0, 0])
        if index.size <= leaf_size:
            nodes[node][3] = len(order)
            nodes[node][4] = index.size
            order.extend(index.tolist())
        else:
            c = centers[index]
            axis = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
            sorted_index = index[np.argsort(c[:, axis], kind="stable")]
            half = sorted_index.size // 2
            build(sorted_index[:half])
            build(sorted_index[half:])
        nodes[node][2] = len(nodes)

    if centers.shape[0]:
        # iterative depth would be log2(S); recursion is fine for any realistic count
        build(np.arange(centers.shape[0]))
    k = len(nodes)
    box_min = np.array([n[0] for n in nodes]).reshape(k, 3)
    box_max = np.array([n[1] for n in nodes]).reshape(k, 3)
    skip = np.array([n[2] for n in nodes], dtype=np.int64)
    first = np.array([n[3] for n in nodes], dtype=np.int64)
    count = np.array([n[4] for n in nodes], dtype=np.int64)
    return box_min, box_max, skip, first, count, np.array(order, dtype=np.int64)


@register_jitable
def _ray_sphere(ox, oy, oz, dx, dy, dz, cx, cy, cz, r, tmin):
    """Smallest t > tmin of the unit-direction ray o + t d on the sphere, or inf
    (Haines et al. 2019, Ray Tracing Gems ch. 7: the discriminant as
    r^2 - |f - (f.d) d|^2 with f = o - c, and the root pair q, c / q)."""
    fx = ox - cx
    fy = oy - cy
    fz = oz - cz
    b = fx * dx + fy * dy + fz * dz
    px = fx - b * dx
    py = fy - b * dy
    pz = fz - b * dz
    disc = r * r - (px * px + py * py + pz * pz)
    if disc < 0.0:
        return _INF
    c = fx * fx + fy * fy + fz * fz - r * r
    q = -b - math.copysign(math.sqrt(disc), b)
    if q == 0.0:
        return _INF
    t0 = c / q
    t1 = q
    if t0 > t1:
        t0, t1 = t1, t0
    if t0 > tmin:
        return t0
    if t1 > tmin:
        return t1
    return _INF


@register_jitable
def _slab(o, i, lo, hi, t0, t1):
    """The ray parameter interval [t0, t1] narrowed to the slab lo <= o + t d <= hi
    of one axis (i = 1 / d)."""
    a = (lo - o) * i
    b = (hi - o) * i
    if a > b:
        a, b = b, a
    return max(t0, a), min(t1, b)


@register_jitable
def _ray_box(ox, oy, oz, ix, iy, iz, lo, hi, node, tmax):
    """Slab test (Kay & Kajiya 1986): does the ray (inverse direction i) enter the box before tmax?"""
    t0, t1 = _slab(ox, ix, lo[node, 0], hi[node, 0], 0.0, tmax)
    t0, t1 = _slab(oy, iy, lo[node, 1], hi[node, 1], t0, t1)
    t0, t1 = _slab(oz, iz, lo[node, 2], hi[node, 2], t0, t1)
    return t0 <= t1


@register_jitable
def _inv(d):
    if d == 0.0:
        return 1e300
    return 1.0 / d


@register_jitable
def trace_analytic(ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, spheres, bvh_lo, bvh_hi, bvh_skip, bvh_first,
                   bvh_count, bvh_order, planes):
    """Closest (or, with ``any_hit``, any) analytic hit with tmin < t < tmax.
    ``spheres`` (S, 4) rows (cx, cy, cz, r); ``planes`` (P, 6) rows (point, unit normal).
    Returns (t, kind, index) with t = inf, kind = KIND_NONE when nothing is hit."""
    best = tmax
    kind = 0
    index = -1
    for p in range(planes.shape[0]):
        den = dx * planes[p, 3] + dy * planes[p, 4] + dz * planes[p, 5]
        if den != 0.0:
            t = ((planes[p, 0] - ox) * planes[p, 3] + (planes[p, 1] - oy) * planes[p, 4]
                 + (planes[p, 2] - oz) * planes[p, 5]) / den
            if tmin < t < best:
                best = t
                kind = 2
                index = p
                if any_hit:
                    return best, kind, index
    n_nodes = bvh_skip.shape[0]
    if n_nodes:
        ix = _inv(dx)
        iy = _inv(dy)
        iz = _inv(dz)
        node = 0
        while node < n_nodes:
            if _ray_box(ox, oy, oz, ix, iy, iz, bvh_lo, bvh_hi, node, best):
                cnt = bvh_count[node]
                if cnt > 0:
                    for q in range(bvh_first[node], bvh_first[node] + cnt):
                        s = bvh_order[q]
                        t = _ray_sphere(ox, oy, oz, dx, dy, dz, spheres[s, 0], spheres[s, 1], spheres[s, 2],
                                        spheres[s, 3], tmin)
                        if t < best:
                            best = t
                            kind = 1
                            index = s
                            if any_hit:
                                return best, kind, index
                    node = bvh_skip[node]
                else:
                    node += 1
            else:
                node = bvh_skip[node]
    if kind == 0:
        return _INF, 0, -1
    return best, kind, index


@parallel_kernel
def _trace_batch(origins, dirs, tmin, tmax, any_hit, spheres, lo, hi, skip, first, count, order, planes,
                 out_t, out_kind, out_index):
    for i in numba.prange(origins.shape[0]):
        t, k, idx = trace_analytic(origins[i, 0], origins[i, 1], origins[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2],
                                   tmin, tmax[i], any_hit, spheres, lo, hi, skip, first, count, order, planes)
        out_t[i] = t
        out_kind[i] = k
        out_index[i] = idx


# ================================================================ textures


_WRAP_REPEAT, _WRAP_CLAMP, _WRAP_MIRROR = 10497, 33071, 33648
_FILTER_NEAREST = 9728


def _wrap(i, n, mode):
    if mode == _WRAP_CLAMP:
        return np.clip(i, 0, n - 1)
    if mode == _WRAP_MIRROR:
        m = np.mod(i, 2 * n)
        return np.where(m < n, m, 2 * n - 1 - m)
    return np.mod(i, n)


@dataclass
class Texture:
    """Texels (H, W, 4) float32, already linear (sRGB images decoded), with the
    glTF sampler's wrap modes and magnification filter."""

    texels: np.ndarray
    wrap_s: int = _WRAP_REPEAT
    wrap_t: int = _WRAP_REPEAT
    mag_filter: int | None = None

    def sample(self, uv):
        """Filtered texels at texture coordinates uv (N, 2) -> (N, 4).  Texel (row i,
        column j) has its centre at u = (j + 0.5) / W, v = (i + 0.5) / H (glTF: the
        first texel is the upper left corner of the image)."""
        h, w = self.texels.shape[:2]
        x = uv[:, 0] * w
        y = uv[:, 1] * h
        if self.mag_filter == _FILTER_NEAREST:
            j = _wrap(np.floor(x).astype(np.int64), w, self.wrap_s)
            i = _wrap(np.floor(y).astype(np.int64), h, self.wrap_t)
            return self.texels[i, j].astype(np.float64)
        x -= 0.5
        y -= 0.5
        x0 = np.floor(x)
        y0 = np.floor(y)
        fx = (x - x0)[:, None]
        fy = (y - y0)[:, None]
        x0 = x0.astype(np.int64)
        y0 = y0.astype(np.int64)
        j0 = _wrap(x0, w, self.wrap_s)
        j1 = _wrap(x0 + 1, w, self.wrap_s)
        i0 = _wrap(y0, h, self.wrap_t)
        i1 = _wrap(y0 + 1, h, self.wrap_t)
        t = self.texels
        return ((t[i0, j0] * (1 - fx) + t[i0, j1] * fx) * (1 - fy)
                + (t[i1, j0] * (1 - fx) + t[i1, j1] * fx) * fy).astype(np.float64)


@dataclass(frozen=True)
class TextureRef:
    """A material's use of a texture: which one, which TEXCOORD set, and the
    scale (normal) or strength (occlusion)."""

    texture: int
    texcoord: int = 0
    scale: float = 1.0


@dataclass
class SurfaceMaterial:
    """A material as the renderer uses it: the :class:`pbrkit.scene.MaterialSpec`
    (factors, model and terms) and optional glTF textures."""

    spec: MaterialSpec
    base_color_texture: TextureRef | None = None
    metallic_roughness_texture: TextureRef | None = None
    normal_texture: TextureRef | None = None
    occlusion_texture: TextureRef | None = None
    emissive_texture: TextureRef | None = None
    textures: list | None = None  # the Texture objects the refs index

    @property
    def textured(self):
        return any(r is not None for r in (self.base_color_texture, self.metallic_roughness_texture,
                                           self.normal_texture, self.occlusion_texture, self.emissive_texture))


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
    lights: list         # pbrkit.lights.Light
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
    Problems raise :class:`pbrkit.errors.InputError` naming the file."""
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


def mikktspace_tangents(positions, normals, uv, triangles):
    """Per-vertex tangents (V, 4) (xyz unit, w = +-1) for a triangle mesh, the way
    MikkTSpace builds them (module docstring): corner tangents dp/du projected into
    the vertex normal's tangent plane, normalised, angle-weighted and averaged over
    the corners sharing a vertex and a texture orientation; w = +1 when
    (T, N x T, N) agrees with dp/dv' for v' = 1 - v (glTF's image-up axis).
    Vertices used with both orientations take the majority one (MikkTSpace would
    split them; glTF stores one tangent per vertex)."""
    p = np.asarray(positions, dtype=float)
    n = np.asarray(normals, dtype=float)
    uv = np.asarray(uv, dtype=float)
    tri = np.asarray(triangles, dtype=np.int64)
    v_count = p.shape[0]
    corners = tri.reshape(-1)
    p0, p1, p2 = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    # v' = 1 - v: texture "up" is +v'
    s0, s1, s2 = uv[tri[:, 0], 0], uv[tri[:, 1], 0], uv[tri[:, 2], 0]
    t0, t1, t2 = 1.0 - uv[tri[:, 0], 1], 1.0 - uv[tri[:, 1], 1], 1.0 - uv[tri[:, 2], 1]
    e1 = p1 - p0
    e2 = p2 - p0
    ds1, ds2 = s1 - s0, s2 - s0
    dt1, dt2 = t1 - t0, t2 - t0
    det = ds1 * dt2 - ds2 * dt1
    orient = np.where(det >= 0.0, 1.0, -1.0)
    # dp/du and dp/dv' scaled by det (MikkTSpace keeps only directions and the sign)
    vos = (e1 * dt2[:, None] - e2 * dt1[:, None]) * orient[:, None]
    # corner angles
    angles = np.empty((tri.shape[0], 3))
    pts = (p0, p1, p2)
    for c in range(3):
        a = pts[(c + 1) % 3] - pts[c]
        b = pts[(c + 2) % 3] - pts[c]
        cosang = np.sum(a * b, axis=1) / np.maximum(np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-300)
        angles[:, c] = np.arccos(np.clip(cosang, -1.0, 1.0))
    nc = n[corners]
    tc = np.repeat(vos, 3, axis=0)
    tc = tc - np.sum(tc * nc, axis=1, keepdims=True) * nc
    length = np.linalg.norm(tc, axis=1, keepdims=True)
    good = (length[:, 0] > 1e-20) & (np.repeat(np.abs(det), 3) > 1e-20)
    tc = np.where(good[:, None], tc / np.maximum(length, 1e-300), 0.0)
    weight = angles.reshape(-1) * good
    oc = np.repeat(orient, 3)
    acc_pos = np.zeros((v_count, 3))
    acc_neg = np.zeros((v_count, 3))
    w_pos = np.zeros(v_count)
    w_neg = np.zeros(v_count)
    pos_mask = oc > 0
    np.add.at(acc_pos, corners[pos_mask], tc[pos_mask] * weight[pos_mask, None])
    np.add.at(acc_neg, corners[~pos_mask], tc[~pos_mask] * weight[~pos_mask, None])
    np.add.at(w_pos, corners[pos_mask], weight[pos_mask])
    np.add.at(w_neg, corners[~pos_mask], weight[~pos_mask])
    use_pos = w_pos >= w_neg
    t = np.where(use_pos[:, None], acc_pos, acc_neg)
    sign = np.where(use_pos, 1.0, -1.0)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    # fallback for vertices without a usable UV mapping: any vector orthogonal to n
    fallback = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
    t = np.where(length > 1e-20, t / np.maximum(length, 1e-300), fallback / np.maximum(
        np.linalg.norm(fallback, axis=1, keepdims=True), 1e-300))
    return np.concatenate([t, sign[:, None]], axis=1)


# ============================================================== the geometry


@dataclass
class Hits:
    """Closest hits of a batch of rays: t (inf where nothing was hit), kind
    (KIND_*), index (sphere / plane / mesh index), prim (triangle), and the
    barycentric coordinates (b1, b2) of triangle hits (p = (1 - b1 - b2) p0 + b1 p1 + b2 p2)."""

    t: np.ndarray
    kind: np.ndarray
    index: np.ndarray
    prim: np.ndarray
    b1: np.ndarray
    b2: np.ndarray

    @property
    def hit(self):
        return self.kind != KIND_NONE


@dataclass
class Surface:
    """Shading data at hit points (N rows): position p, geometric normal ng and
    shading normal n (both facing the incoming ray for double-sided materials),
    material index, and the textured parameters."""

    p: np.ndarray
    ng: np.ndarray
    n: np.ndarray
    material: np.ndarray
    base_color: np.ndarray
    metallic: np.ndarray
    roughness: np.ndarray
    occlusion: np.ndarray
    emissive: np.ndarray


class Geometry:
    """All surfaces of a scene, ready for ray casting and shading.

    ``materials`` is the list of :class:`SurfaceMaterial` that the material
    indices of :class:`Surface` refer to: the scene's named materials first
    (in ``material_names`` order), then those of each glTF file."""

    def __init__(self, scene):
        self.material_names = list(scene.materials)
        self.materials = [SurfaceMaterial(scene.materials[n]) for n in self.material_names]
        index_of = {n: i for i, n in enumerate(self.material_names)}
        spheres = [o for o in scene.objects if isinstance(o, Sphere)]
        planes = [o for o in scene.objects if isinstance(o, Plane)]
        self.spheres = np.array([[*s.center, s.radius] for s in spheres], dtype=np.float64).reshape(-1, 4)
        self.sphere_material = np.array([index_of[s.material] for s in spheres], dtype=np.int64)
        self.planes = np.array([[*p.point, *p.normal] for p in planes], dtype=np.float64).reshape(-1, 6)
        self.plane_material = np.array([index_of[p.material] for p in planes], dtype=np.int64)
        self.bvh = build_sphere_bvh(self.spheres[:, :3], self.spheres[:, 3])
        self.meshes = []
        self.lights = list(scene.lights)
        self.notes = []
        for obj in scene.objects:
            if isinstance(obj, GltfObject):
                asset = load_gltf(obj.file, obj.matrix())
                offset = len(self.materials)
                self.materials.extend(asset.materials)
                for m in asset.meshes:
                    m.material += offset
                    self.meshes.append(m)
                self.lights.extend(asset.lights)
                self.notes.extend(f"{obj.file}: {n}" for n in asset.notes)
        specs = [m.spec for m in self.materials]
        self._factor_base = np.array([sp.base_color for sp in specs], dtype=np.float64).reshape(-1, 3)
        self._factor_metallic = np.array([sp.metallic for sp in specs], dtype=np.float64)
        self._factor_roughness = np.array([sp.roughness for sp in specs], dtype=np.float64)
        self._factor_emissive = np.array([sp.emissive for sp in specs], dtype=np.float64).reshape(-1, 3)
        self._two_sided = np.array([sp.double_sided for sp in specs], dtype=bool)
        self._embree = None
        if self.meshes:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh

            self._embree = rtcore_scene.EmbreeScene()
            for m in self.meshes:
                TriangleMesh(self._embree, m.positions.astype(np.float32), m.indices.astype(np.int32))
        extent = [np.abs(self.spheres[:, :3]).max() + self.spheres[:, 3].max() if len(self.spheres) else 0.0]
        extent += [np.abs(m.positions).max() for m in self.meshes]
        self.scale = max(1.0, max(extent))

    @property
    def has_meshes(self):
        return bool(self.meshes)

    # ---------------------------------------------------------------- casting

    def _trace_analytic(self, origins, dirs, tmax, any_hit):
        """Rays against the spheres (BVH) and planes: (origins, dirs, tmax, t, kind, index)
        as contiguous float64 / int64 arrays, tmax infinite where None."""
        origins = np.ascontiguousarray(origins, dtype=np.float64)
        dirs = np.ascontiguousarray(dirs, dtype=np.float64)
        n = origins.shape[0]
        tmax = np.full(n, np.inf) if tmax is None else np.ascontiguousarray(np.broadcast_to(tmax, (n,)),
                                                                            dtype=np.float64)
        t = np.empty(n)
        kind = np.empty(n, dtype=np.int64)
        index = np.empty(n, dtype=np.int64)
        _trace_batch(origins, dirs, 0.0, tmax, any_hit, self.spheres, *self.bvh, self.planes, t, kind, index)
        return origins, dirs, tmax, t, kind, index

    def intersect(self, origins, dirs, tmax=None):
        """Closest hits of rays (N, 3) with unit directions, t in (0, tmax)."""
        origins, dirs, tmax, t, kind, index = self._trace_analytic(origins, dirs, tmax, False)
        n = origins.shape[0]
        prim = np.full(n, -1, dtype=np.int64)
        b1 = np.zeros(n)
        b2 = np.zeros(n)
        if self._embree is not None and n:
            far = np.minimum(t, tmax)
            r = self._embree.run(origins.astype(np.float32), dirs.astype(np.float32),
                                 dists=np.where(np.isfinite(far), far, 3e38).astype(np.float32), output=1)
            geom = r["geomID"].astype(np.int64)
            tri_t = r["tfar"].astype(np.float64)
            closer = (geom >= 0) & (tri_t < far)
            t[closer] = tri_t[closer]
            kind[closer] = KIND_TRIANGLE
            index[closer] = geom[closer]
            prim[closer] = r["primID"][closer]
            b1[closer] = r["u"][closer]
            b2[closer] = r["v"][closer]
        return Hits(t, kind, index, prim, b1, b2)

    def occluded(self, origins, dirs, tmax=None):
        """True where something lies on the ray before tmax (default: infinity)."""
        origins, dirs, tmax, t, kind, index = self._trace_analytic(origins, dirs, tmax, True)
        blocked = kind != KIND_NONE
        if self._embree is not None:
            rest = np.flatnonzero(~blocked)
            if rest.size:
                far = np.where(np.isfinite(tmax[rest]), tmax[rest], 3e38).astype(np.float32)
                r = self._embree.run(origins[rest].astype(np.float32), dirs[rest].astype(np.float32), dists=far,
                                     query="OCCLUDED")
                blocked[rest[np.asarray(r) >= 0]] = True
        return blocked

    def offset_origins(self, p, ng, directions):
        """Ray origins just off the surface on the side ``directions`` leave toward
        (avoids self-intersection; the offset is relative to the scene's scale,
        larger for triangles, which Embree intersects in single precision)."""
        eps = (1e-4 if self.meshes else 1e-7) * self.scale
        side = np.where(np.sum(ng * directions, axis=-1) >= 0.0, 1.0, -1.0)
        return p + (eps * side)[:, None] * ng

    # ---------------------------------------------------------------- shading

    def surface(self, hits, origins, dirs, rows=None):
        """:class:`Surface` data of the hit rays ``rows`` (default: every ray, which must all hit)."""
        rows = np.arange(hits.t.size) if rows is None else np.asarray(rows)
        k = hits.kind[rows]
        idx = hits.index[rows]
        o = origins[rows]
        d = dirs[rows]
        t = hits.t[rows]
        n_rows = rows.size
        p = o + t[:, None] * d
        ng = np.zeros((n_rows, 3))
        n = np.zeros((n_rows, 3))
        mat = np.zeros(n_rows, dtype=np.int64)
        base = np.zeros((n_rows, 3))
        metallic = np.zeros(n_rows)
        rough = np.zeros(n_rows)
        occl = np.ones(n_rows)
        emissive = np.zeros((n_rows, 3))
        sph = k == KIND_SPHERE
        if np.any(sph):
            if sph.all():
                s = self.spheres[idx]
                normal = p - s[:, :3]
                normal /= np.sqrt(np.einsum("ij,ij->i", normal, normal))[:, None]
                p = s[:, :3] + s[:, 3:4] * normal  # snap onto the sphere
                ng = normal
                n = normal.copy()
                mat = self.sphere_material[idx]
            else:
                s = self.spheres[idx[sph]]
                normal = p[sph] - s[:, :3]
                normal /= np.sqrt(np.einsum("ij,ij->i", normal, normal))[:, None]
                p[sph] = s[:, :3] + s[:, 3:4] * normal  # snap onto the sphere
                ng[sph] = normal
                n[sph] = normal
                mat[sph] = self.sphere_material[idx[sph]]
        pl = k == KIND_PLANE
        if np.any(pl):
            ng[pl] = self.planes[idx[pl], 3:6]
            n[pl] = ng[pl]
            mat[pl] = self.plane_material[idx[pl]]
        tri_rows = np.flatnonzero(k == KIND_TRIANGLE)
        uv_sets = {}
        tangents = np.zeros((n_rows, 4))
        has_tangent = np.zeros(n_rows, dtype=bool)
        for mi in np.unique(idx[tri_rows]):
            sel = tri_rows[idx[tri_rows] == mi]
            mesh = self.meshes[mi]
            tri = mesh.indices[hits.prim[rows[sel]]]
            w1 = hits.b1[rows[sel]][:, None]
            w2 = hits.b2[rows[sel]][:, None]
            w0 = 1.0 - w1 - w2
            p0, p1, p2 = (mesh.positions[tri[:, c]] for c in range(3))
            p[sel] = w0 * p0 + w1 * p1 + w2 * p2
            g = np.cross(p1 - p0, p2 - p0)
            g /= np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
            sn = w0 * mesh.normals[tri[:, 0]] + w1 * mesh.normals[tri[:, 1]] + w2 * mesh.normals[tri[:, 2]]
            sn /= np.maximum(np.linalg.norm(sn, axis=1, keepdims=True), 1e-300)
            g = np.where(np.sum(g * sn, axis=1, keepdims=True) < 0.0, -g, g)  # the side the normals give
            ng[sel] = g
            n[sel] = sn
            mat[sel] = mesh.material
            for s_i, tc in enumerate(mesh.texcoords):
                uv_sets.setdefault(s_i, np.zeros((n_rows, 2)))
                uv_sets[s_i][sel] = w0 * tc[tri[:, 0]] + w1 * tc[tri[:, 1]] + w2 * tc[tri[:, 2]]
            if mesh.tangents is not None:
                tv = (w0 * mesh.tangents[tri[:, 0], :3] + w1 * mesh.tangents[tri[:, 1], :3]
                      + w2 * mesh.tangents[tri[:, 2], :3])
                tangents[sel, :3] = tv
                tangents[sel, 3] = mesh.tangents[tri[:, 0], 3]
                has_tangent[sel] = True
        # material factors (gathered from per-material tables), then textures
        base[:] = self._factor_base[mat]
        metallic[:] = self._factor_metallic[mat]
        rough[:] = self._factor_roughness[mat]
        emissive[:] = self._factor_emissive[mat]
        textured = [mi for mi in range(len(self.materials)) if self.materials[mi].textured]
        for mi in (np.intersect1d(np.unique(mat), textured) if textured else ()):
            sel = np.flatnonzero(mat == mi)
            m = self.materials[mi]
            spec = m.spec

            def lookup(ref):
                uv = uv_sets.get(ref.texcoord)
                if uv is None:
                    raise ValueError(f"material {spec.name!r} uses TEXCOORD_{ref.texcoord}, which its mesh lacks")
                return m.textures[ref.texture].sample(uv[sel])

            if m.base_color_texture is not None:
                base[sel] *= lookup(m.base_color_texture)[:, :3]
            if m.metallic_roughness_texture is not None:
                mr = lookup(m.metallic_roughness_texture)
                rough[sel] *= mr[:, 1]
                metallic[sel] *= mr[:, 2]
            if m.occlusion_texture is not None:
                r = m.occlusion_texture
                occl[sel] = 1.0 + r.scale * (lookup(r)[:, 0] - 1.0)
            if m.emissive_texture is not None:
                emissive[sel] *= lookup(m.emissive_texture)[:, :3]
            if m.normal_texture is not None:
                ref = m.normal_texture
                c = lookup(ref)[:, :3] * 2.0 - 1.0
                c[:, :2] *= ref.scale
                nn = n[sel]
                tt = tangents[sel, :3]
                tt = tt - np.sum(tt * nn, axis=1, keepdims=True) * nn
                tt /= np.maximum(np.linalg.norm(tt, axis=1, keepdims=True), 1e-300)
                bb = np.cross(nn, tt) * tangents[sel, 3:4]
                mapped = c[:, 0:1] * tt + c[:, 1:2] * bb + c[:, 2:3] * nn
                length = np.linalg.norm(mapped, axis=1, keepdims=True)
                ok = has_tangent[sel][:, None] & (length > 1e-12)
                n[sel] = np.where(ok, mapped / np.maximum(length, 1e-300), nn)
        np.clip(base, 0.0, 1.0, out=base)
        np.clip(metallic, 0.0, 1.0, out=metallic)
        np.clip(rough, 0.0, 1.0, out=rough)
        # double-sided materials face the incoming ray
        back = (np.einsum("ij,ij->i", ng, d) > 0.0) & self._two_sided[mat]
        ng[back] = -ng[back]
        n[back] = -n[back]
        return Surface(p, ng, n, mat, base, metallic, rough, occl, emissive)
