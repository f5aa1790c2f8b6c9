"""Styled real-time rendering (:func:`render_styled`): the real-time path's hits,
lights and bake, shaded as a :class:`pbrkit.npr.style.Style` asks, then outlined.

Shadings (the terms are those of :mod:`pbrkit.npr.toon`; lights in the units of
:mod:`pbrkit.rendering.lights`, so a white surface facing a light has the luminance
the PBR Lambert gives it, E / pi):

- ``toon``: per punctual light its illuminance E_i (colour x intensity x falloff,
  at normal incidence), n.l_i and shadow ray visibility V_i.  ``summed`` bands the
  value x = sum_i Y(E_i) max(n.l_i, 0) V_i / sum_i Y(E_i) (the direct irradiance
  over its largest possible value, scale-free) and shades base / pi sum_i E_i
  shade(tone(x)); ``per_light`` sums base / pi E_i shade(tone(max(n.l_i, 0) V_i))
  (Lake et al. 2000 per light).  shade(t) is mix(shadow colour, 1, t) or the ramp
  image.  Highlights: strength x tone of D(n.h) / D(1) of the material's GGX lobe
  (alpha = r^2, :func:`pbrkit.microfacet.ggx.d_ggx`) x E_i V_i / pi.  The
  environment (``environment = true``): the bake's SH irradiance banded relative
  to its brightest direction (a banded SH irradiance), and the prefiltered
  specular in the mirror direction kept where its luminance exceeds the highlight
  threshold of its level's brightest texel (a thresholded prefiltered specular).
  Rim: MToon's parametric rim, tinted by the lighting by ``rim_mix``.
- ``mtoon``: VRM MToon 1.0 (its specification's Lighting, Global Illumination and
  Rim Lighting): per light mix(shade colour, base, linearstep(-1 + toony, 1 -
  toony, n.l + shift) V) E / pi; GI = the SH irradiance equalised towards the mean
  of up and down by ``gi_equalization``, times base / pi; the parametric rim.
- ``hatching``: the tone 1 - x (x over the lights and the environment as in
  ``summed``) drawn with a tonal art map (:mod:`pbrkit.npr.hatching`, Praun et al.
  2001) in object space (``hatching_space = "object"``: world coordinates box-mapped
  on the axis plane nearest the normal, ``hatching_scale`` repeats per unit) or in
  texture space (``"texture"``: the mesh's TEXCOORD_0 times ``hatching_scale``;
  hits without texture coordinates fall back to object space), the mip level from
  the pixel's footprint (its world size over the slant, times the map's repeats per
  world unit: per triangle sqrt(UV area / world area) in texture space), over the
  base colour lit by the brightest light.
- ``pbr``: the real-time image (:func:`pbrkit.rendering.realtime.render_realtime`).

Outlines (``outline``): ``image``: edges of the G-buffers (depth along the camera
ray, shading normal, object and material ids; :mod:`pbrkit.npr.outlines`),
``geometry``: silhouette, crease, boundary and material edges of the triangle
meshes drawn as lines visible against the depth buffer (:mod:`pbrkit.npr.edges`),
``both``; ``hull``: the inverted hull of spheres and meshes cast as rays
(:mod:`pbrkit.npr.hull`); constant width in pixels, anti-aliased (the hull by
``supersample``).  Area lights are not part of the
toon lighting (they light the ``pbr`` shading only).
"""

from __future__ import annotations

import math
import time
from functools import lru_cache

import numpy as np

from ..core.color import luminance, rec709_luminance
from ..core.jit import dual_use, row_kernel
from ..microfacet.ggx import d_ggx
from ..microfacet.roughness import alpha_from_roughness
from ..rendering.lights import light_incidence
from ..rendering.primitives import KIND_NONE, trace_analytic
from .style import Style
from .toon import (
    gi_equalized,
    highlight_tone,
    mtoon_shading,
    parametric_rim,
    ramp_channel,
    ramp_lookup,
    toon_shade,
    toon_tone,
)

__all__ = ["render_styled", "gbuffers", "GBuffers"]


class GBuffers:
    """Per camera ray (rows of the sub-pixel image, H k x W k): ``depth`` (distance
    along the unit ray, inf where nothing is hit), ``normal`` (shading normal, 0 where
    nothing is hit), ``object_id`` (-1 for none), ``material_id`` (-1 for none)."""

    def __init__(self, depth, normal, object_id, material_id, supersample):
        self.depth = depth
        self.normal = normal
        self.object_id = object_id
        self.material_id = material_id
        self.supersample = supersample


def _ray_image(scene, per_ray):
    """Rays (pixel-major, k^2 sub-rays per pixel) -> the (H k, W k, ...) sub-pixel image."""
    cam = scene.camera
    k = cam.supersample
    a = np.asarray(per_ray).reshape(cam.height, cam.width, k, k, *np.shape(per_ray)[1:])
    a = np.moveaxis(a, 2, 1)  # (H, k, W, k, ...)
    return a.reshape(cam.height * k, cam.width * k, *np.shape(per_ray)[1:])


def gbuffers(scene, prim):
    """:class:`GBuffers` of the primary hits ``prim`` (:func:`pbrkit.rendering.primary._primary`)."""
    n_rays = prim.dirs.shape[0]
    depth = np.full(n_rays, np.inf)
    normal = np.zeros((n_rays, 3))
    object_id = np.full(n_rays, -1, dtype=np.int64)
    material_id = np.full(n_rays, -1, dtype=np.int64)
    if prim.rows.size:
        depth[prim.rows] = np.linalg.norm(prim.surface.p - prim.origin, axis=1)
        normal[prim.rows] = prim.surface.n
        kind = prim.hits.kind[prim.rows]
        object_id[prim.rows] = kind * (1 << 40) + prim.hits.index[prim.rows]
        material_id[prim.rows] = prim.surface.material
    return GBuffers(_ray_image(scene, depth), _ray_image(scene, normal), _ray_image(scene, object_id),
                    _ray_image(scene, material_id), scene.camera.supersample)


def _shade(style, tone):
    """The colour multiplier (..., 3) of tones: the ramp image, or mix(shadow colour, 1, tone)."""
    if style.ramp_colors is not None:
        return ramp_lookup(style.ramp_colors, tone)
    return toon_shade(np.asarray(style.shadow_color), np.asarray(tone)[..., None])


class _Lit:
    """The punctual lights at the shaded points, one row per light: ``e`` illuminance at
    normal incidence (L, N, 3), ``nol`` n.l (L, N), ``vis`` visibility (L, N),
    ``direction`` to the light (L, N, 3)."""

    def __init__(self, e, nol, vis, direction):
        self.e, self.nol, self.vis, self.direction = e, nol, vis, direction

    def __len__(self):
        return self.e.shape[0]


def _lights(geometry, s, shadows=True):
    """:class:`_Lit` of the punctual lights at the surface points ``s``, shadow rays
    traced as the real-time path does."""
    from ..rendering.lights import light_arrays

    count = s.p.shape[0]
    n_lights = len(geometry.lights) if count else 0
    lit = _Lit(np.zeros((n_lights, count, 3)), np.zeros((n_lights, count)), np.zeros((n_lights, count)),
               np.zeros((n_lights, count, 3)))
    if not n_lights:
        return lit
    codes, values = light_arrays(geometry.lights)
    p = np.ascontiguousarray(s.p, dtype=np.float64)
    n = np.ascontiguousarray(s.n, dtype=np.float64)
    ng = np.ascontiguousarray(s.ng, dtype=np.float64)
    if shadows and not geometry.has_meshes:  # analytic scene: every light and its shadow ray in one pass
        _incidence_analytic_kernel(codes, values, p, n, ng, 1e-7 * geometry.scale, geometry.spheres,
                                   *geometry.bvh, geometry.planes, lit.direction, lit.e, lit.nol, lit.vis)
        return lit
    dist = np.empty(count)
    for li in range(n_lights):
        _incidence_kernel(codes, values, li, p, n, ng, lit.direction[li], dist, lit.e[li], lit.nol[li], lit.vis[li])
        reach = np.flatnonzero(lit.vis[li] > 0.0)
        if shadows and reach.size:
            direction = lit.direction[li, reach]
            origins = geometry.offset_origins(s.p[reach], s.ng[reach], direction)
            far = np.where(np.isfinite(dist[reach]), dist[reach] * (1.0 - 1e-6), np.inf)
            lit.vis[li, reach[geometry.occluded(origins, direction, far)]] = 0.0
    return lit


@row_kernel(3)
def _incidence_kernel(start, stop, codes, values, li, p, n, ng, out_dir, out_dist, out_e, out_nol, out_vis):
    """:func:`pbrkit.rendering.lights.light_incidence` of light li at every point: the
    direction and distance to it, its illuminance at normal incidence (colour x
    intensity x falloff), n.l, and 1 where the light can reach the point (in front of
    its geometric normal, inside the light's range), else 0 (before shadow rays)."""
    for i in range(start, stop):
        lx, ly, lz, d, f = light_incidence(codes[li, 0], codes[li, 1], values[li], p[i, 0], p[i, 1], p[i, 2])
        out_dir[i, 0] = lx
        out_dir[i, 1] = ly
        out_dir[i, 2] = lz
        out_dist[i] = d
        for c in range(3):
            out_e[i, c] = f * values[li, c]
        out_nol[i] = n[i, 0] * lx + n[i, 1] * ly + n[i, 2] * lz
        front = ng[i, 0] * lx + ng[i, 1] * ly + ng[i, 2] * lz > 0.0
        out_vis[i] = 1.0 if front and f > 0.0 else 0.0


@row_kernel(2)
def _incidence_analytic_kernel(start, stop, codes, values, p, n, ng, eps, spheres, lo, hi, skip, first, count, order, planes,
                               out_dir, out_e, out_nol, out_vis):
    """:func:`_incidence_kernel` for every light of an analytic scene, with the shadow
    ray traced in the kernel (:func:`pbrkit.rendering.primitives.trace_analytic`, as
    :func:`pbrkit.rendering.punctual.punctual_at` does)."""
    for i in range(start, stop):
        for li in range(codes.shape[0]):
            lx, ly, lz, d, f = light_incidence(codes[li, 0], codes[li, 1], values[li], p[i, 0], p[i, 1], p[i, 2])
            out_dir[li, i, 0] = lx
            out_dir[li, i, 1] = ly
            out_dir[li, i, 2] = lz
            for c in range(3):
                out_e[li, i, c] = f * values[li, c]
            out_nol[li, i] = n[i, 0] * lx + n[i, 1] * ly + n[i, 2] * lz
            gl = ng[i, 0] * lx + ng[i, 1] * ly + ng[i, 2] * lz
            visible = 0.0
            if gl > 0.0 and f > 0.0:
                _, k, _ = trace_analytic(p[i, 0] + eps * ng[i, 0], p[i, 1] + eps * ng[i, 1], p[i, 2] + eps * ng[i, 2],
                                         lx, ly, lz, 0.0, d * (1.0 - 1e-6), True, spheres, lo, hi, skip, first,
                                         count, order, planes)
                visible = 1.0 if k == KIND_NONE else 0.0
            out_vis[li, i] = visible


def _fibonacci_normals(n=256):
    """n unit vectors spread over the sphere (a Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = math.pi * (3.0 - math.sqrt(5.0)) * i
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def _environment(env, bake, s, v, style, specular=True):
    """(SH irradiance at n (N, 3), at +Y and -Y (3,), at the brightest of 256 directions
    (3,), prefiltered specular in the mirror direction (N, 3) and the luminance of its
    level's brightest texel (N,)); without ``specular`` the last two are None."""
    from ..ibl.cubemap import CubeSampler
    from ..ibl.prefilter import level_of_roughness
    from ..ibl.sh import irradiance_from_sh

    sh = np.asarray(bake.sh)

    def irradiance(normals):
        return irradiance_from_sh(sh, env.to_env_frame(normals)) * env.intensity

    e_n = irradiance(s.n)
    e_up, e_down = irradiance(np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]))
    probes = irradiance(_fibonacci_normals())
    e_max = probes[int(np.argmax(luminance(probes)))]
    if not specular:
        return e_n, e_up, e_down, e_max, None, None
    chain = [np.asarray(level) for level in bake.specular]
    nov = np.sum(s.n * v, axis=1, keepdims=True)
    refl = 2.0 * nov * s.n - v
    lod = np.asarray(level_of_roughness(s.roughness, len(chain)), dtype=np.float64)
    prefiltered = CubeSampler(chain)(env.to_env_frame(refl), lod) * env.intensity
    level_max = np.array([float(luminance(level).max()) for level in chain]) * env.intensity
    return e_n, e_up, e_down, e_max, prefiltered, level_max[np.clip(np.rint(lod).astype(int), 0, len(chain) - 1)]


def _spec_color(s):
    """Highlight colour: white for dielectrics, the base colour for metals (mixed by metallic)."""
    m = s.metallic[:, None]
    return 1.0 + (s.base_color - 1.0) * m


@dual_use
def _tone_colour(ramp, shadow, tone, c):
    """Channel c of the colour multiplier of a tone: the ramp (M, 3) when it has rows
    (:func:`pbrkit.npr.toon.ramp_channel`), else :func:`pbrkit.npr.toon.toon_shade`
    of the shadow colour (:func:`_shade` in a kernel)."""
    if ramp.shape[0] == 0:
        return toon_shade(shadow[c], tone)
    return ramp_channel(ramp, tone, c)


@row_kernel(0)
def _toon_kernel(start, stop, n, v, base, rough, metal, emissive, light_e, light_dir, light_vis, summed, thresholds, softness,
                 shadow, ramp, specular, spec_threshold, spec_softness, has_env, e_n, e_max, prefiltered,
                 level_max, rim_color, rim_power, rim_lift, rim_mix, out):
    """The toon shading of every pixel (module docstring) in one pass."""
    n_lights = light_e.shape[0]
    y_max = max(rec709_luminance(e_max[0], e_max[1], e_max[2]), 1e-300)
    for i in range(start, stop):
        nov = min(max(n[i, 0] * v[i, 0] + n[i, 1] * v[i, 1] + n[i, 2] * v[i, 2], 0.0), 1.0)
        alpha = alpha_from_roughness(rough[i])
        d_peak = d_ggx(1.0, alpha)
        o = np.zeros(3)
        lighting = np.zeros(3)
        weight = 0.0
        norm = 0.0
        total = np.zeros(3)
        for li in range(n_lights):
            e0, e1, e2 = light_e[li, i, 0], light_e[li, i, 1], light_e[li, i, 2]
            dx, dy, dz = light_dir[li, i, 0], light_dir[li, i, 1], light_dir[li, i, 2]
            nol = n[i, 0] * dx + n[i, 1] * dy + n[i, 2] * dz
            lit = max(nol, 0.0) * light_vis[li, i]
            y = rec709_luminance(e0, e1, e2)
            weight += y * lit
            norm += y
            total[0] += e0
            total[1] += e1
            total[2] += e2
            lighting[0] += e0 * lit / np.pi
            lighting[1] += e1 * lit / np.pi
            lighting[2] += e2 * lit / np.pi
            if not summed:
                tone = toon_tone(lit, thresholds, softness)
                o[0] += base[i, 0] / np.pi * e0 * _tone_colour(ramp, shadow, tone, 0)
                o[1] += base[i, 1] / np.pi * e1 * _tone_colour(ramp, shadow, tone, 1)
                o[2] += base[i, 2] / np.pi * e2 * _tone_colour(ramp, shadow, tone, 2)
            if specular > 0.0 and nol > 0.0 and light_vis[li, i] > 0.0:
                hx, hy, hz = dx + v[i, 0], dy + v[i, 1], dz + v[i, 2]
                hl = max(math.sqrt(hx * hx + hy * hy + hz * hz), 1e-300)
                noh = min(max((n[i, 0] * hx + n[i, 1] * hy + n[i, 2] * hz) / hl, 0.0), 1.0)
                h = highlight_tone(d_ggx(noh, alpha), d_peak, spec_threshold, spec_softness) * light_vis[li, i]
                for c in range(3):
                    sc = 1.0 + (base[i, c] - 1.0) * metal[i]
                    o[c] += specular * sc * light_e[li, i, c] / np.pi * h
        if summed and n_lights > 0:
            x = weight / norm if norm > 0.0 else 0.0
            tone = toon_tone(x, thresholds, softness)
            for c in range(3):
                o[c] += base[i, c] / np.pi * total[c] * _tone_colour(ramp, shadow, tone, c)
        if has_env:
            tone = toon_tone(rec709_luminance(e_n[i, 0], e_n[i, 1], e_n[i, 2]) / y_max, thresholds, softness)
            keep = 0.0
            if specular > 0.0:
                keep = highlight_tone(rec709_luminance(prefiltered[i, 0], prefiltered[i, 1], prefiltered[i, 2]),
                                      level_max[i], spec_threshold, spec_softness)
            for c in range(3):
                o[c] += base[i, c] / np.pi * e_max[c] * _tone_colour(ramp, shadow, tone, c)
                o[c] += specular * (1.0 + (base[i, c] - 1.0) * metal[i]) * prefiltered[i, c] * keep
                lighting[c] += e_n[i, c] / np.pi
        rim = parametric_rim(nov, rim_power, rim_lift)
        for c in range(3):
            out[i, c] = o[c] + rim_color[c] * rim * (1.0 + (lighting[c] - 1.0) * rim_mix) + emissive[i, c]


def _toon(style, geometry, env, bake, s, v):
    count = s.p.shape[0]
    lit = _lights(geometry, s)
    has_env = bool(style.environment and bake is not None)
    if has_env:
        e_n, _, _, e_max, prefiltered, level_max = _environment(env, bake, s, v, style)
    else:
        e_n, e_max, prefiltered, level_max = np.zeros((1, 3)), np.zeros(3), np.zeros((1, 3)), np.zeros(1)
    ramp = np.zeros((0, 3)) if style.ramp_colors is None else np.ascontiguousarray(style.ramp_colors)
    out = np.empty((count, 3))
    c = np.ascontiguousarray
    _toon_kernel(c(s.n), c(v), c(s.base_color), c(s.roughness), c(s.metallic), c(s.emissive), lit.e, lit.direction,
                 lit.vis, style.lighting == "summed", c(style.threshold_values), style.softness,
                 np.asarray(style.shadow_color), ramp, style.specular, style.specular_threshold,
                 style.specular_softness, has_env, c(e_n), c(np.asarray(e_max, dtype=np.float64)), c(prefiltered),
                 c(np.asarray(level_max, dtype=np.float64)), np.asarray(style.rim_color), style.rim_power,
                 style.rim_lift, style.rim_mix, out)
    return out


def _mtoon(style, geometry, env, bake, s, v):
    lights = _lights(geometry, s)
    base = s.base_color
    shade = np.asarray(style.shade_color)[None, :]
    out = np.zeros_like(base)
    lighting = np.zeros_like(base)
    for e, nol, vis in zip(lights.e, lights.nol, lights.vis):
        shading = (mtoon_shading(nol, style.shading_shift, style.shading_toony) * vis)[:, None]
        out += (shade + (base - shade) * shading) * e / math.pi
        lighting += e / math.pi
    if bake is not None:
        e_n, e_up, e_down, _, _, _ = _environment(env, bake, s, v, style, specular=False)
        gi = gi_equalized(e_n, e_up[None, :], e_down[None, :], style.gi_equalization)
        out += gi / math.pi * base
        lighting += gi / math.pi
    nov = np.clip(np.sum(s.n * v, axis=1), 0.0, 1.0)
    rim = np.asarray(style.rim_color)[None, :] * parametric_rim(nov, style.rim_power, style.rim_lift)[:, None]
    out += rim * (1.0 + (lighting - 1.0) * style.rim_mix)
    return out + s.emissive


def render_styled(scene, style=None, geometry=None, env=None, bake=None, bake_size=256):
    """Render ``scene`` in ``style`` (module docstring; default the scene's own
    ``style``, else plain PBR).  Returns a :class:`pbrkit.rendering.primary.RenderResult`
    whose stats hold the timings of the shading and of the outlines."""
    from ..rendering.environment import EnvironmentLight
    from ..rendering.geometry import Geometry
    from ..rendering.primary import RenderResult, _background, _primary, _resolve
    from ..rendering.realtime import render_realtime

    style = style or getattr(scene, "style", None) or Style()
    timings = {}
    t0 = time.perf_counter()
    geometry = geometry or Geometry(scene)
    env = env or EnvironmentLight(scene.environment)
    if bake is None and (style.shading == "pbr" or style.environment or style.shading == "mtoon"):
        bake = env.bake(size=bake_size)
    t1 = time.perf_counter()
    timings["load_and_bake"] = t1 - t0
    prim = _primary(scene, geometry)
    if style.shading == "pbr":
        base = render_realtime(scene, geometry, env, bake=bake, primary=prim)
        image, mask = base.image, base.mask
    else:
        radiance = np.zeros((prim.dirs.shape[0], 3))
        radiance[~prim.hit] = _background(prim, env)
        s = prim.surface
        if prim.rows.size:
            v = -prim.dirs[prim.rows]
            if style.shading == "toon":
                radiance[prim.rows] = _toon(style, geometry, env, bake, s, v)
            elif style.shading == "mtoon":
                radiance[prim.rows] = _mtoon(style, geometry, env, bake, s, v)
            else:
                radiance[prim.rows] = _hatching(style, scene, geometry, env, bake, s, v, prim)
        image, mask = _resolve(scene, radiance, prim.hit)
    t2 = time.perf_counter()
    timings["shading"] = t2 - t1
    if style.outline != "none":
        image = _outline(style, scene, geometry, prim, image)
    timings["outlines"] = time.perf_counter() - t2
    timings["total"] = time.perf_counter() - t0
    stats = {"mode": "styled", "shading": style.shading, "outline": style.outline, "timings": timings,
             "pixels": int(scene.camera.width * scene.camera.height)}
    return RenderResult(image, mask, None, stats)


@lru_cache(maxsize=4)
def _tam(tones):
    """The default tonal art map of ``tones`` tones (:func:`pbrkit.npr.hatching.tonal_art_map`, seed 0)."""
    from .hatching import tonal_art_map

    return tonal_art_map(tones=tones, size=256, seed=0)


def box_uv(p, n, scale):
    """Object-space texture coordinates: the world position on the axis plane most
    nearly facing the normal (box mapping), times ``scale`` repeats per unit."""
    axis = np.argmax(np.abs(n), axis=1)
    u = np.where(axis == 0, p[:, 2], p[:, 0])
    v = np.where(axis == 1, p[:, 2], p[:, 1])
    return np.stack([u, v], axis=-1) * scale


@row_kernel(3)
def _summed_light_kernel(start, stop, e, nol, vis, weight, norm):
    """Per point the numerator sum_i Y(E_i) max(n.l_i, 0) V_i and the denominator
    sum_i Y(E_i) of the summed lighting value (module docstring)."""
    for i in range(start, stop):
        w = 0.0
        total = 0.0
        for li in range(e.shape[0]):
            y = rec709_luminance(e[li, i, 0], e[li, i, 1], e[li, i, 2])
            w += y * max(nol[li, i], 0.0) * vis[li, i]
            total += y
        weight[i] = w
        norm[i] = total


def _hatching(style, scene, geometry, env, bake, s, v, prim):
    from .hatching import hatch

    lights = _lights(geometry, s)
    weight, norm = np.empty(s.p.shape[0]), np.empty(s.p.shape[0])
    _summed_light_kernel(lights.e, lights.nol, lights.vis, weight, norm)
    reference = lights.e.max(axis=1).sum(axis=0)
    if style.environment and bake is not None:
        e_n, _, _, e_max, _, _ = _environment(env, bake, s, v, style, specular=False)
        weight = weight + luminance(e_n)
        norm = norm + float(luminance(e_max))
        reference = reference + e_max
    norm = np.asarray(norm, dtype=np.float64)
    x = np.where(norm > 0.0, weight / np.where(norm > 0.0, norm, 1.0), 0.0)
    tam = _tam(style.hatching_tones)
    cam = scene.camera
    depth = np.linalg.norm(s.p - prim.origin, axis=1)
    pixel = depth * 2.0 * math.tan(math.radians(cam.fov) / 2.0) / cam.height / cam.supersample
    slant = np.maximum(np.abs(np.sum(s.n * v, axis=1)), 0.25)
    uv = box_uv(s.p, s.n, style.hatching_scale)
    density = np.full(uv.shape[0], style.hatching_scale)  # map repeats per world unit
    if style.hatching_space == "texture" and s.uv is not None:
        textured = np.flatnonzero(np.isfinite(s.uv[:, 0]))
        uv[textured] = s.uv[textured] * style.hatching_scale
        density[textured] = style.hatching_scale * _uv_density(geometry, prim, textured)
    footprint = pixel / slant * density * tam.sizes[0]
    ink = hatch(np.clip(1.0 - x, 0.0, 1.0), uv, tam, footprint=np.maximum(footprint, 1e-6))
    return s.base_color * reference / math.pi * ink[:, None] + s.emissive


def _uv_density(geometry, prim, textured):
    """UV units per world unit at the hits ``textured`` (rows of the surface): per
    triangle sqrt(UV area / world area), the isotropic scale of its texture mapping
    (Praun et al. 2001 sample the TAM with the hardware's mip selection, which this
    stands in for in a ray caster without screen-space derivatives)."""
    rows = prim.rows[textured]
    mesh_of, triangle = prim.hits.index[rows], prim.hits.prim[rows]
    out = np.ones(rows.size)
    for mi in np.unique(mesh_of):
        mesh = geometry.meshes[mi]
        sel = np.flatnonzero(mesh_of == mi)
        tri = mesh.indices[triangle[sel]]
        p0, p1, p2 = (mesh.positions[tri[:, c]] for c in range(3))
        t0, t1, t2 = (mesh.texcoords[0][tri[:, c]] for c in range(3))
        world = np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)
        e1, e2 = t1 - t0, t2 - t0
        texture = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        out[sel] = np.sqrt(np.where(world > 0.0, texture / np.where(world > 0.0, world, 1.0), 1.0))
    return np.where(out > 0.0, out, 1.0)


def _outline(style, scene, geometry, prim, image):
    """``image`` with the style's outlines composited over it (module docstring)."""
    from .outlines import composite, outline_mask

    g = gbuffers(scene, prim)
    cam = scene.camera
    coverage = np.zeros((cam.height, cam.width))
    if style.outline in ("image", "both"):
        thresholds = {"depth": style.outline_depth, "normal": style.outline_normal, "object_id": 0.25,
                      "material_id": 0.25}
        coverage = np.maximum(coverage, outline_mask(g.depth, g.normal, g.object_id, g.material_id,
                                                     thresholds=thresholds, width_px=style.outline_pixels(cam),
                                                     supersample=g.supersample))
    if style.outline in ("geometry", "both") and geometry.meshes:
        coverage = np.maximum(coverage, _mesh_lines(style, cam, geometry, g))
    if style.outline == "hull":
        from .hull import hull_rays

        rays = hull_rays(scene, geometry, prim, style.outline_pixels(cam),
                         world=style.outline_width_mode == "world").astype(np.float64)
        coverage = rays.reshape(cam.height, cam.width, cam.supersample ** 2).mean(axis=2)
    return composite(image, coverage, np.asarray(style.outline_color))


def _mesh_lines(style, cam, geometry, g):
    """Coverage of the meshes' silhouette, crease (dihedral angle above
    ``outline_normal``), boundary and material edges, drawn at ``outline_width``
    pixels against the depth buffer (:mod:`pbrkit.npr.edges`)."""
    from .edges import draw_lines, mesh_edges, silhouette_edges

    positions, indices, material = [], [], []
    offset = 0
    for mesh in geometry.meshes:  # one mesh for all: material edges between primitives too
        positions.append(mesh.positions)
        indices.append(mesh.indices + offset)
        material.append(np.full(mesh.indices.shape[0], mesh.material, dtype=np.int64))
        offset += mesh.positions.shape[0]
    edges = mesh_edges(np.concatenate(positions), np.concatenate(indices), material=np.concatenate(material),
                       crease_angle_deg=style.outline_normal)
    chosen = edges.crease | edges.boundary | edges.material_edge | silhouette_edges(edges, eye=cam)
    k = g.supersample
    depth = g.depth.reshape(cam.height, k, cam.width, k).min(axis=(1, 3))  # the nearest sub-ray per pixel
    return draw_lines(edges.segments(chosen), cam, depth, width_px=style.outline_pixels(cam))
