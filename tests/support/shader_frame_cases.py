"""The WebGL2 cases of ``pbrkit_khr_material.glsl``'s functions that take a tangent frame
(tests/shaders/test_shaders_khr_material.py runs them with the rest of the file's): KHR_materials_anisotropy
(its frame, D, V, specular lobe, BRDF and bent-normal IBL direction) and the normal of
KHR_materials_clearcoat's clearcoatNormalTexture (``pbrkit_clearcoatNormal``), each against
pbrkit's Python at random float32 inputs.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from shader_cases import N, Case, f32, random_alphas, random_cosines, random_units, vec4s

from pbrkit.brdf import models
from pbrkit.brdf.fresnel import f0_from_ior
from pbrkit.brdf.material import Material
from pbrkit.brdf.shading import gltf
from pbrkit.brdf.shading.registry import COLUMNS, LAYOUT


def _tangents(rng, n):
    """Random glTF TANGENTs (N, 4) at the unit normals n: neither unit nor orthogonal to n (their part across
    n at least a fifth of their length), handedness w = -1 or +1 (and a few 0 and -0.5: the sign counts)."""
    t = rng.normal(size=(N, 3)) * rng.uniform(0.5, 2.0, (N, 1))
    for _ in range(100):
        across = t - np.sum(t * n, axis=1, keepdims=True) * n
        bad = np.linalg.norm(across, axis=1) < 0.2 * np.linalg.norm(t, axis=1)
        if not bad.any():
            break
        t[bad] = rng.normal(size=(int(bad.sum()), 3))
    w = np.where(rng.uniform(size=N) < 0.5, -1.0, 1.0)
    w[4:8] = (0.0, -0.5, 0.0, -0.5)
    return f32(np.concatenate([t, w[:, None]], axis=1))


def _rotations(rng):
    """anisotropyRotation in [-4, 4] radians (float32), with 0 and the quarter turns on a few rows."""
    rotation = rng.uniform(-4.0, 4.0, N)
    rotation[:16] = (0.0, 0.0, 0.0, 0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 0.0, np.pi / 2, np.pi, 3.0,
                     2 * np.pi, -2 * np.pi, 1.0, -1.0)
    return f32(rotation)


def _direction(rotation):
    """The GLSL's direction (cos, sin) of each rotation, computed on the CPU (the README's u_AnisotropyRotation)."""
    return np.stack([np.cos(rotation), np.sin(rotation)], axis=1)


def _frames(n, tangent, rotation):
    """pbrkit's anisotropy frame (t, b) of each row (pbrkit.brdf.bxdf.shading_frame)."""
    from pbrkit.brdf.bxdf import shading_frame

    frames = [shading_frame.py_func(*n[q], SimpleNamespace(anisotropic=True, rotation=float(rotation[q])),
                                    tuple(tangent[q])) for q in range(N)]
    return np.array([f[0] for f in frames]), np.array([f[1] for f in frames])


def _anisotropy_material(base, metallic, roughness, strength, rotation, tangent, **extensions):
    """The Material of the rows, its rotation turned for handedness w < 0: pbrkit.brdf.models.evaluate takes
    tangents of handedness +1, and the frame of (T, w = -1) turned by theta is the frame of (T, +1) turned by
    -theta (cos theta T + sin theta (-(n x T)), with anisotropicB = n x anisotropicT either way)."""
    turned = np.where(tangent[:, 3] < 0.0, -rotation, rotation)
    # the same angle in the declared [-pi, pi] (float32 pi lies just above it)
    turned = np.clip(np.remainder(turned + np.pi, 2.0 * np.pi) - np.pi, -np.pi, np.pi)
    return Material(base_color=base, metallic=metallic, roughness=roughness, anisotropy_strength=strength,
                    anisotropy_rotation=turned, **extensions)


def anisotropy_cases(rng):
    """KHR_materials_anisotropy: the frame against pbrkit.brdf.bxdf.shading_frame (tangents not unit, not
    orthogonal to n, of either handedness, turned), alpha_t against the model's setup, D and V against
    pbrkit's anisotropic GGX and the model's V (pbrkit.brdf.shading.gltf._v_khr), the specular lobe and the
    whole BRDF against pbrkit.brdf.models.evaluate("gltf", ..., t=tangent) (checked first against the
    README's transcription in tests/support/reference_brdf.py), and the bent-normal lookup direction against
    pbrkit.rendering.ibl_lookups.khr_anisotropic_reflection."""
    import reference_brdf as ref
    from shader_cases import random_directions

    from pbrkit.brdf import distributions
    from pbrkit.brdf.bxdf import Cosines as FrameCosines
    from pbrkit.brdf.shading.gltf import _v_khr
    from pbrkit.rendering.realtime import khr_anisotropic_reflection

    cases = []
    add = cases.append
    n = random_units(rng)
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    t, b = _frames(n, tangent, rotation)
    inputs = [vec4s(n), tangent, vec4s(_direction(rotation))]
    add(Case("anisotropicFrame_t", ("pbrkit_anisotropicFrame",), "pbrkit_anisotropicFrame(a.xyz, b, c.xy)[0]",
             inputs, t, rtol=0.0, atol=1e-6))
    add(Case("anisotropicFrame_b", ("pbrkit_anisotropicFrame",), "pbrkit_anisotropicFrame(a.xyz, b, c.xy)[1]",
             inputs, b, rtol=0.0, atol=1e-6))

    r, strength = f32(rng.uniform(0.0, 1.0, N)), f32(rng.uniform(0.0, 1.0, N))
    r[:4], strength[:6] = (0.0, 1.0, 0.0, 0.5), (0.0, 1.0, 1.0, 0.0, 1.0, 0.0)
    params = np.zeros((N, LAYOUT.size))
    params[:, COLUMNS.anisotropy_strength] = strength
    codes = np.zeros((1, 5), dtype=np.int64)
    alpha_t = np.array([gltf.setup(codes, 0, params, q, COLUMNS, float(r[q]), 0.0, 0.0, 0.0, 0.0).alpha_x
                        for q in range(N)])
    add(Case("anisotropicAlphaT", ("pbrkit_anisotropicAlphaT",),
             "pbrkit_anisotropicAlphaT(pbrkit_alphaFromRoughness(a.x), a.y)", [vec4s(r, strength)],
             alpha_t[:, None], atol=1e-7))

    # D and V at directions in the frame: n.x from random_cosines (many near 1 and 0), the
    # azimuth uniform; alpha_b from 1e-3 to 1, alpha_t = mix(alpha_b, 1, s^2)
    def local(lo):
        c = random_cosines(rng, lo)[rng.permutation(N)]
        phi = rng.uniform(0.0, 2.0 * np.pi, N)
        s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
        return c, f32(s * np.cos(phi)), f32(s * np.sin(phi))

    alpha_b = random_alphas(rng)
    alpha_t = f32(alpha_b + (1.0 - alpha_b) * rng.uniform(0.0, 1.0, N) ** 2)
    noh, toh, boh = local(-0.2)
    add(Case("dGGXAnisotropic", ("pbrkit_dGGXAnisotropic",), "pbrkit_dGGXAnisotropic(a.x, a.y, a.z, b.x, b.y)",
             [vec4s(noh, toh, boh), vec4s(alpha_t, alpha_b)],
             distributions.d_ggx_anisotropic(noh, toh, boh, alpha_t, alpha_b)[:, None]))
    (nol, tol, bol), (nov, tov, bov) = local(-0.2), local(-0.2)
    bxdf = gltf.setup(codes, 0, params, 1, COLUMNS, 0.5, 0.0, 0.0, 0.0, 0.0)  # an anisotropic BxDF (strength 1)
    assert bxdf.anisotropic
    expected = np.array([_v_khr.py_func(bxdf._replace(alpha_x=float(alpha_t[q]), alpha_y=float(alpha_b[q])),
                                        FrameCosines(*map(float, (nol[q], nov[q], 0.0, 0.0, tol[q], bol[q], tov[q],
                                                                  bov[q], 0.0, 0.0)))) for q in range(N)])
    add(Case("vGGXAnisotropic", ("pbrkit_vGGXAnisotropic",), "pbrkit_vGGXAnisotropic(a.x, a.y, a.z, b.x, b.y, b.z, "
             "c.x, c.y)", [vec4s(nol, tol, bol), vec4s(nov, tov, bov), vec4s(alpha_t, alpha_b)],
             expected[:, None], atol=1e-30))

    # the specular lobe and the whole material at random_directions' directions (the near-mirror half at
    # r >= 0.3, as BRDF_glTF's case)
    l, v, n = random_directions(rng)
    mirror = np.arange(N) >= N // 2
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    rough = f32(rng.uniform(np.where(mirror, 0.3, 0.03), 1.0))
    strength = f32(np.where(rng.uniform(size=N) < 0.2, 1.0, rng.uniform(0.01, 1.0, N)))
    # the lobe: metals (f0 = base colour, f90 1) and, on odd rows, black dielectrics with KHR_materials_specular
    # (f0 = min(f0(ior) specularColor, 1) specular, f90 = specular): no diffuse either way
    odd = np.arange(N) % 2 == 1
    f0 = f32(rng.uniform(0, 1, (N, 3)))
    specular, specular_color = f32(rng.uniform(0, 1, N)), f32(rng.uniform(0, 2, (N, 3)))
    ior = f32(rng.uniform(1.0, 3.0, N))
    dielectric_f0 = f32(np.minimum(f0_from_ior(ior)[:, None] * specular_color, 1.0) * specular[:, None])
    f0 = np.where(odd[:, None], dielectric_f0, f0)
    f90 = np.where(odd, specular, 1.0)
    material = _anisotropy_material(np.where(odd[:, None], 0.0, f0), np.where(odd, 0.0, 1.0), rough, strength,
                                    rotation, tangent, specular=np.where(odd, specular, 1.0),
                                    specular_color=np.where(odd[:, None], specular_color, 1.0),
                                    ior=np.where(odd, ior, 1.5))
    expected = models.evaluate("gltf", l, v, n, material, t=tangent[:, :3])
    # (1e-6: float32 unit vectors are unit to ~1e-7, where the README's form of V and pbrkit's differ)
    metal = ~odd
    with np.errstate(invalid="ignore"):  # its h at l = -v (row 1)
        readme = ref.gltf_anisotropy_brdf(l[metal], v[metal], n[metal], tangent[metal, :3],
                                          np.where(tangent[metal, 3] < 0.0, -1.0, 1.0), f0[metal], 1.0, rough[metal],
                                          strength[metal], rotation[metal])
    assert np.allclose(expected[metal], readme, rtol=1e-6, atol=1e-9)
    add(Case("anisotropicSpecular", ("pbrkit_anisotropicSpecular",),
             "pbrkit_anisotropicSpecular(a.xyz, b.xyz, pbrkit_anisotropicFrame(c.xyz, d, f.xy), e.xyz, e.w, b.w, c.w)",
             [vec4s(l), vec4s(v, rough), vec4s(n, strength), tangent, vec4s(f0, f90), vec4s(_direction(rotation))],
             expected,
             rtol=1e-4, atol=1e-6))

    base = f32(rng.uniform(0, 1, (N, 3)))
    metallic = f32(np.where(rng.uniform(size=N) < 0.3, rng.integers(0, 2, N), rng.uniform(0, 1, N)))
    strength = f32(np.where(rng.uniform(size=N) < 0.15, 0.0, strength))  # 0: the core model (BRDF_glTF)
    material = _anisotropy_material(base, metallic, rough, strength, rotation, tangent)
    expected = models.evaluate("gltf", l, v, n, material, t=tangent[:, :3])
    on = strength > 0.0
    with np.errstate(invalid="ignore"):
        readme = ref.gltf_anisotropy_brdf(l[on], v[on], n[on], tangent[on, :3],
                                          np.where(tangent[on, 3] < 0.0, -1.0, 1.0), base[on], metallic[on], rough[on],
                                          strength[on], rotation[on])
    assert np.allclose(expected[on], readme, rtol=1e-6, atol=1e-9)
    add(Case("BRDF_glTFAnisotropic", ("BRDF_glTFAnisotropic",),
             "BRDF_glTFAnisotropic(a.xyz, b.xyz, c.xyz, d, e.xyz, e.w, b.w, c.w, f.xy)",
             [vec4s(l), vec4s(v, rough), vec4s(n, strength), tangent, vec4s(base, metallic),
              vec4s(_direction(rotation))],
             expected, rtol=1e-4, atol=1e-6))

    # the lookup direction: v above n, anisotropicB of a turned frame, strength and r in [0, 1] with their ends
    n = random_units(rng)
    v = random_units(rng)
    v = f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    _, b = _frames(n, tangent, rotation)
    b = f32(b)
    strength, r = f32(rng.uniform(0.0, 1.0, N)), f32(rng.uniform(0.0, 1.0, N))
    strength[:8], r[:8] = (0.0, 1.0, 1.0, 0.0, 1.0, 0.5, 1.0, 0.0), (0.0, 0.0, 1.0, 1.0, 0.5, 0.0, 0.0, 0.5)
    expected = np.array([khr_anisotropic_reflection(*n[q], *v[q], tuple(b[q]), float(strength[q]),
                                                    float(r[q])) for q in range(N)])
    add(Case("anisotropicReflection", ("pbrkit_anisotropicReflection",),
             "pbrkit_anisotropicReflection(a.xyz, b.xyz, c.xyz, a.w, b.w)",
             [vec4s(n, strength), vec4s(v, r), vec4s(b)], expected, rtol=0.0, atol=2e-6))
    return cases


def clearcoat_normal_cases(rng):
    """KHR_materials_clearcoat's normal from a clearcoatNormalTexture texel, pbrkit_clearcoatNormal, against
    pbrkit.rendering.textures.tangent_space_normal: unit normals, glTF TANGENTs (not unit, not orthogonal to n,
    handedness +-1) made into the frame (t, b, n) as tangent_space_normal makes it, random texels (the flat
    (0.5, 0.5, 1) on a few rows, and (0.5, 0.5, 0.5), which maps to 0: n itself) and scales in [-1, 3]
    (0 and 1 on a few rows)."""
    from pbrkit.rendering.textures import tangent_space_normal

    n = random_units(rng)
    tangent = _tangents(rng, n)
    tangent[:, 3] = np.where(tangent[:, 3] < 0.0, -1.0, 1.0)  # glTF's handedness
    texel = f32(rng.uniform(0.0, 1.0, (N, 3)))
    scale = f32(np.where(rng.uniform(size=N) < 0.2, 1.0, rng.uniform(-1.0, 3.0, N)))
    texel[:6] = ((0.5, 0.5, 1.0), (0.5, 0.5, 0.5), (1.0, 0.5, 0.5), (0.5, 0.0, 0.5), (0.5, 0.5, 1.0), (0.2, 0.9, 0.7))
    scale[:6] = (1.0, 1.0, 1.0, 2.0, 0.0, 0.0)

    def mapped_length(rows):
        c = (2.0 * texel[rows] - 1.0) * np.stack([scale[rows], scale[rows], np.ones(len(rows))], axis=1)
        return np.linalg.norm(c, axis=1)

    # away from 0 (where normalising magnifies float32 rounding) but on row 1
    for _ in range(100):
        rows = np.arange(6, N)
        short = rows[mapped_length(rows) < 0.2]
        if not short.size:
            break
        texel[short] = f32(rng.uniform(0.0, 1.0, (short.size, 3)))
    expected = tangent_space_normal(texel, scale[:, None], n, tangent, np.ones(N, dtype=bool))
    assert np.array_equal(expected[1], n[1]) and np.allclose(expected[0], n[0], atol=1e-12)
    t = tangent[:, :3] - np.sum(tangent[:, :3] * n, axis=1, keepdims=True) * n
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t) * tangent[:, 3:4]
    assert np.mean(np.sum(expected * n, axis=1) < 0.9) > 0.5  # mostly well away from n
    return [Case("clearcoatNormal", ("pbrkit_clearcoatNormal",),
                 "vec4(pbrkit_clearcoatNormal(a.xyz, b.xyz, c.xyz, d.xyz, a.w), 0.0)",
                 [vec4s(f32(t), scale), vec4s(f32(b)), vec4s(n), vec4s(texel)], expected, rtol=0.0,
                 atol=2e-6)]
