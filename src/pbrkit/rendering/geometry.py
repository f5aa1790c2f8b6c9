"""Scene geometry for the renderer: every surface of a scene ready for ray
casting (analytic primitives in compiled kernels, triangles through Embree,
Intel's ray-tracing kernels, via ``embreex``) and the surface data at hit
points (positions, normals, materials and their textured parameters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..brdf.bxdf import NO_TANGENT
from ..brdf.shading.registry import COLUMNS
from .alpha import coverage_tables, pass_through
from .area_lights import area_light_arrays, area_light_hits
from .gltf import load_gltf
from .materials import bounds_volume, material_tables
from .primitives import (
    KIND_NONE,
    KIND_PLANE,
    KIND_SPHERE,
    KIND_TRIANGLE,
    _trace_batch,
    build_sphere_bvh,
    sphere_normal_and_point,
)
from .scene import GltfObject, Plane, Sphere
from .textures import SurfaceMaterial, tangent_space_normal

__all__ = [
    "Hits",
    "Surface",
    "Geometry",
]

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
    material index, the textured parameters, ``uv``: the mesh's TEXCOORD_0 at
    each hit (NaN where the hit has none: analytic shapes, meshes without it), and
    ``tangent`` (N, 4): the mesh's interpolated TANGENT (xyz, handedness w) where it
    has one, else (0, 0, 0, 1) (:data:`pbrkit.brdf.bxdf.NO_TANGENT`: anisotropic
    materials then take :func:`pbrkit.brdf.bxdf.tangent_frame`'s); None where no hit has
    one."""

    p: np.ndarray
    ng: np.ndarray
    n: np.ndarray
    material: np.ndarray
    base_color: np.ndarray
    metallic: np.ndarray
    roughness: np.ndarray
    occlusion: np.ndarray
    emissive: np.ndarray
    uv: np.ndarray | None = None
    tangent: np.ndarray | None = None
    #: With KHR_materials extension textures: (hit rows, {parameter column: (K,) values}) of
    #: the hits whose extension parameters their textures change (:func:`pbrkit.rendering.
    #: materials.per_hit_tables` makes the kernels' tables of them); None without them.
    extension_values: tuple | None = None
    #: With a normalTexture at some hit: the normal before normal mapping (the interpolated
    #: vertex normal; n itself where the hit's material has no normalTexture), facing like n;
    #: None where no hit's material has a normalTexture (then it is n).  three.js takes its
    #: ``geometryRoughness`` from this one (``nonPerturbedNormal``).
    n_unmapped: np.ndarray | None = None


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
        self.area_lights = area_light_arrays(scene.area_lights)
        self.notes = []
        for obj in scene.objects:
            if isinstance(obj, GltfObject):
                asset = load_gltf(obj.file, obj.matrix(), getattr(scene, "allow_roots", ()))
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
        self._unlit = np.array([m.unlit for m in self.materials], dtype=bool)
        self._two_sided = np.array([sp.double_sided and not bounds_volume(sp) for sp in specs], dtype=bool)
        self._coverage = coverage_tables(self.materials)
        # the coated glTF materials whose coat has a normal of its own: a clearcoatNormalTexture, or
        # the unmapped normal under a base normalTexture (_extension_textures)
        self._coat_normals = {mi for mi, m in enumerate(self.materials)
                              if m.spec.model == "gltf" and np.any(np.asarray(m.spec.clearcoat) > 0.0)
                              and (m.normal_texture is not None
                                   or any(use[3] == "coat_normal" for use, _ in m.extension_textures))}
        self._tables = None  # the kernels' material tables, made when extension textures need them
        self._embree = None
        if self.meshes:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh

            self._embree = rtcore_scene.EmbreeScene()
            for m in self.meshes:
                TriangleMesh(self._embree, m.positions.astype(np.float32), m.indices.astype(np.int32))
        extent = [np.abs(self.spheres[:, :3]).max() + self.spheres[:, 3].max() if len(self.spheres) else 0.0]
        extent += [np.abs(m.positions).max() for m in self.meshes]
        extent += [float(np.abs(light.position).max()) + light.radius for light in scene.area_lights]
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

    def intersect(self, origins, dirs, tmax=None, salt=0):
        """Closest hits of rays (N, 3) with unit directions, t in (0, tmax), through the
        surfaces that glTF's alpha modes let rays pass (:mod:`pbrkit.rendering.alpha`;
        ``salt`` varies the coverage decisions of BLEND surfaces)."""
        hits = self._closest(origins, dirs, tmax)
        if self._coverage is not None:
            hits = pass_through(self, self._coverage, self._closest, hits, origins, dirs, tmax, salt)
        return hits

    @property
    def blends(self):
        """Whether a material has alphaMode BLEND (coverage varies from ray to ray)."""
        return self._coverage is not None and bool(np.any(self._coverage[0] == 2))

    def _closest(self, origins, dirs, tmax=None):
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
        """True where something lies on the ray before tmax (default: infinity); a surface
        that glTF's alpha modes let the ray through does not count."""
        if self._coverage is not None:  # the closest hits, through cutouts and coverage
            return self.intersect(origins, dirs, tmax).hit
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

    def area_light_hits(self, origins, dirs, tmax=None):
        """Nearest area lights on rays: (t, light index or -1, radiance seen (N, 3))
        (:func:`pbrkit.rendering.area_lights.area_light_hit`)."""
        return area_light_hits(self.area_lights, origins, dirs, tmax)

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
            s = self.spheres[idx[sph]]
            q = p[sph]
            nx, ny, nz, sx, sy, sz = sphere_normal_and_point(s[:, 0], s[:, 1], s[:, 2], s[:, 3],
                                                             q[:, 0], q[:, 1], q[:, 2])
            p[sph] = np.stack([sx, sy, sz], axis=-1)  # snapped onto the sphere
            ng[sph] = np.stack([nx, ny, nz], axis=-1)
            n[sph] = ng[sph]
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
        vertex_color = None
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
            if mesh.colors is not None:  # COLOR_0, interpolated: it multiplies the base colour
                if vertex_color is None:
                    vertex_color = np.ones((n_rows, 3))
                vertex_color[sel] = (w0 * mesh.colors[tri[:, 0]] + w1 * mesh.colors[tri[:, 1]]
                                     + w2 * mesh.colors[tri[:, 2]])
            if mesh.tangents is not None:
                tv = (w0 * mesh.tangents[tri[:, 0], :3] + w1 * mesh.tangents[tri[:, 1], :3]
                      + w2 * mesh.tangents[tri[:, 2], :3])
                tangents[sel, :3] = tv
                tangents[sel, 3] = mesh.tangents[tri[:, 0], 3]
                has_tangent[sel] = True
        # material factors (gathered from per-material tables), then textures
        base[:] = self._factor_base[mat]
        emissive[:] = self._factor_emissive[mat]
        if vertex_color is not None:  # on the base colour, and where it shows as emission (unlit) there
            base *= vertex_color
            unlit = self._unlit[mat]
            emissive[unlit] *= vertex_color[unlit]
        metallic[:] = self._factor_metallic[mat]
        rough[:] = self._factor_roughness[mat]
        hit_materials = np.unique(mat)
        normal_mapped = any(self.materials[mi].normal_texture is not None for mi in hit_materials)
        # the normal before normal mapping: a clear coat's (not normal-mapped), Surface.n_unmapped
        vertex_n = n.copy() if (self._coat_normals or normal_mapped) else None
        textured = [mi for mi in range(len(self.materials)) if self.materials[mi].textured]
        for mi in (np.intersect1d(hit_materials, textured) if textured else ()):
            sel = np.flatnonzero(mat == mi)
            m = self.materials[mi]
            spec = m.spec

            def lookup(ref):
                uv = uv_sets.get(ref.texcoord)
                if uv is None:
                    raise ValueError(f"material {spec.name!r} uses TEXCOORD_{ref.texcoord}, which its mesh lacks")
                return m.textures[ref.texture].sample(ref.lookup_uv(uv[sel]))

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
                n[sel] = tangent_space_normal(lookup(ref), ref.scale, n[sel], tangents[sel], has_tangent[sel])
        np.clip(base, 0.0, 1.0, out=base)
        np.clip(metallic, 0.0, 1.0, out=metallic)
        np.clip(rough, 0.0, 1.0, out=rough)
        tables = self._extension_textures(mat, uv_sets, vertex_n, tangents, has_tangent)
        # double-sided materials face the incoming ray
        back = (np.einsum("ij,ij->i", ng, d) > 0.0) & self._two_sided[mat]
        ng[back] = -ng[back]
        n[back] = -n[back]
        if vertex_n is not None:
            vertex_n[back] = -vertex_n[back]
        if tables is not None and COLUMNS.coat_normal in tables[1]:  # the coat's normal faces the ray too
            flip = back[tables[0]]
            for k in range(3):
                tables[1][COLUMNS.coat_normal + k][flip] *= -1.0
        uv0 = np.full((n_rows, 2), np.nan)
        if 0 in uv_sets:
            with_uv = np.zeros(n_rows, dtype=bool)
            for mi in np.unique(idx[tri_rows]):
                if self.meshes[mi].texcoords:
                    with_uv[tri_rows[idx[tri_rows] == mi]] = True
            uv0[with_uv] = uv_sets[0][with_uv]
        if has_tangent.any():
            tangents[~has_tangent] = NO_TANGENT
        else:  # no mesh tangent: none (the kernels read one row of NO_TANGENT)
            tangents = None
        return Surface(p, ng, n, mat, base, metallic, rough, occl, emissive, uv0, tangents, tables,
                       vertex_n if normal_mapped else None)

    def _extension_textures(self, mat, uv_sets, vertex_n, tangents, has_tangent):
        """The KHR_materials extension textures at hits of materials ``mat`` with the
        interpolated texture coordinates ``uv_sets``
        (:data:`pbrkit.io.gltf_materials.TEXTURE_USES`): :attr:`Surface.extension_values`,
        None where no hit's material has any.  The clear coat's own normal
        (``coat_normal``; KHR_materials_clearcoat's README, "Clearcoat"): its
        clearcoatNormalTexture in the tangent space of the unmapped normal ``vertex_n``
        and the mesh ``tangents``, or without one under a base normalTexture the unmapped
        normal ("no normal mapping is applied to the clear coat layer, even if normal
        mapping is applied to the base material")."""
        users = [mi for mi, m in enumerate(self.materials) if m.extension_textures or mi in self._coat_normals]
        if not users:
            return None
        rows = np.flatnonzero(np.isin(mat, users))
        if rows.size == 0:
            return None
        if self._tables is None:
            self._tables = material_tables(self.materials)
        params = self._tables[1]
        values = {}  # column -> per-row values (rows of `rows`)
        for mi in users:
            sel = np.flatnonzero(mat[rows] == mi)
            if sel.size == 0:
                continue
            m = self.materials[mi]
            for (_, key, _, op, parameter, channels), ref in m.extension_textures:
                uv = uv_sets.get(ref.texcoord)
                if uv is None:
                    raise ValueError(f"material {m.spec.name!r} uses TEXCOORD_{ref.texcoord}, which its mesh lacks")
                texel = m.textures[ref.texture].sample(ref.lookup_uv(uv[rows[sel]]))
                column = getattr(COLUMNS, parameter)
                for k, ch in enumerate(channels if op == "scale" else ()):
                    values.setdefault(column + k, params[mat[rows], column + k].copy())[sel] *= texel[:, ch]
                if op == "thickness":  # KHR_materials_iridescence: mix(minimum, maximum, G)
                    low = params[mi, COLUMNS.iridescence_thickness_minimum]
                    values.setdefault(column, params[mat[rows], column].copy())[sel] = \
                        low + (params[mi, column] - low) * texel[:, channels[0]]
                if op == "coat_normal":  # KHR_materials_clearcoat's clearcoatNormalTexture
                    r = rows[sel]
                    c = tangent_space_normal(texel, ref.scale, vertex_n[r], tangents[r], has_tangent[r])
                    for k in range(3):
                        values.setdefault(column + k, params[mat[rows], column + k].copy())[sel] = c[:, k]
                if op == "anisotropy":  # strength x B; the direction (R, G) 2 - 1 turned by the rotation
                    values.setdefault(column, params[mat[rows], column].copy())[sel] *= texel[:, 2]
                    turn = COLUMNS.anisotropy_rotation
                    angle = np.arctan2(2.0 * texel[:, 1] - 1.0, 2.0 * texel[:, 0] - 1.0)
                    rotation = values.setdefault(turn, params[mat[rows], turn].copy())
                    rotation[sel] = np.remainder(rotation[sel] + angle + np.pi, 2.0 * np.pi) - np.pi
            if mi in self._coat_normals and not any(use[3] == "coat_normal" for use, _ in m.extension_textures):
                column = COLUMNS.coat_normal  # under a base normal map, the coat keeps the unmapped normal
                for k in range(3):
                    values.setdefault(column + k, params[mat[rows], column + k].copy())[sel] = vertex_n[rows[sel], k]
        return rows, values

