"""Real-time shading and Monte Carlo ground truth, each checked against something
independent: the NumPy models, the directional-albedo quadrature of the lookup
tables, the mirror direction of CONVENTIONS.md, half-vector quadrature of the
lit integral, closed-form geometric series and inverse-square lighting."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from render_scenes import pixel_geometry, sphere_scene
from scipy import stats

from pbrkit.brdf.models import (
    DIFFUSES,
    DISTRIBUTIONS,
    FRESNELS,
    MASKINGS,
    cook_torrance,
    evaluate_rows,
    filament,
    ue4,
    urp_mobile,
)
from pbrkit.core.color import TONEMAPS, luminance, tonemap
from pbrkit.rendering.compare import compare_images
from pbrkit.rendering.environment import (
    EnvironmentLight,
    _env_pdf_texel,
    _env_sample,
    _env_texel,
)
from pbrkit.rendering.lights import Light
from pbrkit.rendering.materials import material_tables
from pbrkit.rendering.realtime import render_realtime
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    MaterialSpec,
    Plane,
    Scene,
    Sphere,
)
from pbrkit.rendering.textures import SurfaceMaterial
from pbrkit.sampling.random import _path_key, _uniform

# ------------------------------------------------------------------ helpers


def random_unit(rng, n, hemisphere=True):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    if hemisphere:
        v[:, 2] = np.abs(v[:, 2])
    return v


def equirect_of(function, height):
    """An (H, 2H, 3) equirect whose texels hold ``function(direction)`` at the texel centres."""
    from pbrkit.ibl.equirect import equirect_directions

    return np.ascontiguousarray(function(equirect_directions(height)), dtype=np.float64)


# ========================================================== the kernel BRDF


_CASES = [("cook_torrance", d, g, f, df) for d in DISTRIBUTIONS for g in MASKINGS for f in FRESNELS
          for df in DIFFUSES if (f != "exact-conductor" or df == "lambert") and (d == "ggx" or g in (
              "height-correlated", "separable"))]
_CASES += [("filament", "ggx", "height-correlated", "schlick", "lambert"),
           ("filament", "ggx", "height-correlated", "schlick", "burley"),
           ("ue4", "ggx", "height-correlated", "schlick", "lambert"),
           ("urp_mobile", "ggx", "height-correlated", "schlick", "lambert")]


@pytest.mark.parametrize("model, dist, mask, fres, diff", _CASES)
def test_scene_materials_pack_as_the_numpy_materials(model, dist, mask, fres, diff):
    """A scene material packed for the kernels (material_tables: reflectance, conductor,
    model terms) evaluates to the NumPy API's value of the same Material."""
    rng = np.random.default_rng(len(model) + 7 * DISTRIBUTIONS.index(dist) + 31 * MASKINGS.index(mask))
    n_dirs = 64
    n = np.tile([0.0, 0.0, 1.0], (n_dirs, 1))
    l = random_unit(rng, n_dirs)
    v = random_unit(rng, n_dirs)
    l[:4] = -l[:4]  # a few below the horizon: zero
    base = np.array([0.9, 0.5, 0.2])
    kwargs = dict(model=model, base_color=tuple(base), metallic=0.3, roughness=0.45, diffuse=diff)
    if model != "urp_mobile":  # URP's dielectric f0 is its fixed 0.04
        kwargs["reflectance"] = 0.6
    if model == "cook_torrance":
        kwargs.update(distribution=dist, masking=mask, fresnel=fres)
        if fres == "exact-conductor":
            kwargs.update(conductor="copper", base_color=(0.5, 0.5, 0.5))
            kwargs.pop("metallic")
    spec = MaterialSpec(**kwargs)
    codes, params = material_tables([SurfaceMaterial(spec)])
    got = evaluate_rows(codes[0], params[0], l, v, n)
    material = spec.material()
    if model == "cook_torrance":
        expected = cook_torrance(l, v, n, material, distribution=dist, masking=mask, fresnel=fres, diffuse=diff)
    elif model == "filament":
        expected = filament(l, v, n, material, diffuse=diff)
    elif model == "ue4":
        expected = ue4(l, v, n, material)
    else:
        expected = urp_mobile(l, v, n, material)
    if fres == "none":  # the scene's F = specular colour (white by default) is cook_torrance's F = 1
        assert spec.specular_color == (1.0, 1.0, 1.0)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)
    assert np.all(got[:4] == 0.0)


def test_table_lookup_kernel_matches_sample_table():
    from pbrkit.albedo.lut import lookup_table
    from pbrkit.albedo.tables import sample_table, table_bilinear

    table = lookup_table("dfg", 16)[0].astype(np.float64)
    tables = np.ascontiguousarray(table[None])
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.random(200), [0.0, 1.0, 0.01, 0.99]])
    y = np.concatenate([rng.random(200), [1.0, 0.0, 0.995, 0.02]])

    @numba.njit
    def lookup(tables, x, y, out):
        for i in range(x.size):
            for c in range(2):
                out[i, c] = table_bilinear(tables, 0, x[i], y[i], c)

    out = np.empty((x.size, 2))
    lookup(tables, x, y, out)
    np.testing.assert_allclose(out, sample_table(table, x, y), rtol=1e-12, atol=1e-14)


# ================================================== environment sampling


def test_environment_sampling_is_proportional_to_luminance_times_solid_angle():
    """Texels are drawn with probability luminance x texel solid angle (alias table),
    the returned pdf is the pdf of the texel the direction lands in, and within a
    texel the direction is uniform in solid angle (cos theta and phi uniform)."""
    rng = np.random.default_rng(11)
    image = rng.gamma(0.6, 1.0, size=(8, 16, 3))
    image[2, 5] = 40.0  # a bright texel
    image[7, :] = 0.0  # a black row
    env = EnvironmentLight(EnvironmentSpec(equirect=image, rotation=40.0))
    func, total, alias, rows = env.distribution

    @numba.njit
    def draw(count, func, total, alias, rows, c, s, out_dir, out_pdf, out_pdf2, out_texel):
        for k in range(count):
            key = _path_key(5, k, 0, 0)
            x, y, z, pdf, i, j = _env_sample(func, total, alias, rows, c, s, _uniform(key, 0),
                                             _uniform(key, 1))
            out_dir[k, 0], out_dir[k, 1], out_dir[k, 2] = x, y, z
            out_pdf[k] = pdf
            ii, jj = _env_texel(func.shape[0], func.shape[1], c, s, x, y, z)
            out_pdf2[k] = _env_pdf_texel(func, total, ii, jj)
            out_texel[k, 0], out_texel[k, 1] = ii, jj

    count = 200_000
    d = np.empty((count, 3))
    pdf = np.empty(count)
    pdf2 = np.empty(count)
    texel = np.empty((count, 2), dtype=np.int64)
    draw(count, func, total, alias, rows, env.cos, env.sin, d, pdf, pdf2, texel)
    # the returned pdf is the pdf of the texel the direction lands in (rotation included)
    np.testing.assert_allclose(pdf, pdf2, rtol=1e-9)
    # chi-square over texels: expected frequency luminance * solid angle / sum
    lum = image @ np.array([0.2126, 0.7152, 0.0722])
    theta_edges = np.pi * np.arange(9) / 8
    solid = (2 * np.pi / 16) * (np.cos(theta_edges[:-1]) - np.cos(theta_edges[1:]))
    weight = lum * solid[:, None]
    expected = count * weight.ravel() / weight.sum()
    observed = np.bincount(texel[:, 0] * 16 + texel[:, 1], minlength=128).astype(float)
    assert observed[expected == 0].sum() == 0
    keep = expected >= 5
    chi2 = np.sum((observed[keep] - expected[keep]) ** 2 / expected[keep])
    assert stats.chi2.sf(chi2, keep.sum() - 1) > 1e-3
    # within the bright texel, cos theta and phi (map frame) are uniform (Kolmogorov-Smirnov)
    local = env.to_env_frame(d[(texel[:, 0] == 2) & (texel[:, 1] == 5)])
    assert local.shape[0] > 1000
    cos_t = (local[:, 1] - np.cos(theta_edges[2])) / (np.cos(theta_edges[3]) - np.cos(theta_edges[2]))
    phi = np.arctan2(local[:, 2], local[:, 0])  # u = 0.5 + phi / (2 pi): column 5 of 16
    u_in = (0.5 + phi / (2 * np.pi)) * 16 - 5
    assert stats.kstest(cos_t, "uniform").pvalue > 1e-3
    assert stats.kstest(u_in, "uniform").pvalue > 1e-3
    # the solid-angle pdf integrates to 1 over the sphere (fine midpoint grid in the map frame)
    h = 256
    from pbrkit.ibl.equirect import equirect_directions, equirect_solid_angles

    dirs = equirect_directions(h).reshape(-1, 3)
    world = np.stack([env.cos * dirs[:, 0] + env.sin * dirs[:, 2], dirs[:, 1],
                      -env.sin * dirs[:, 0] + env.cos * dirs[:, 2]], axis=1)  # R_y(theta) d

    @numba.njit
    def pdfs(d, func, total, c, s, out):
        for k in range(d.shape[0]):
            i, j = _env_texel(func.shape[0], func.shape[1], c, s, d[k, 0], d[k, 1], d[k, 2])
            out[k] = _env_pdf_texel(func, total, i, j)

    p = np.empty(world.shape[0])
    pdfs(world, func, total, env.cos, env.sin, p)
    assert np.sum(p * np.asarray(equirect_solid_angles(h)).ravel()) == pytest.approx(1.0, abs=2e-3)


def test_environment_rotation_turns_the_map_about_plus_y():
    """rotation theta: the radiance from world direction d is the map's at R_y(-theta) d,
    R_y(theta) = [[cos, 0, sin], [0, 1, 0], [-sin, 0, cos]] (counter-clockwise seen from +Y)."""
    image = equirect_of(_octant_colour, 64)
    env = EnvironmentLight(EnvironmentSpec(equirect=image, rotation=90.0))
    rng = np.random.default_rng(4)
    d = random_unit(rng, 2000, hemisphere=False)
    undo = np.stack([-d[:, 2], d[:, 1], d[:, 0]], axis=1)  # R_y(-90 degrees) d
    away = np.min(np.abs(undo), axis=1) > 0.1
    np.testing.assert_allclose(env.lookup(d)[away], _octant_colour(undo)[away])
    np.testing.assert_allclose(env.background(d)[away], _octant_colour(undo)[away], atol=1e-12)
    np.testing.assert_allclose(env.to_env_frame(d), undo, atol=1e-12)


# ============================================================ ground truth


@pytest.mark.parametrize("masking", ["separable", "height-correlated"])
def test_furnace_reference_gives_the_directional_albedo(masking):
    """F = 1, constant white environment: each pixel is E(mu) of the lookup-table
    quadrature (pbrkit.albedo.tables.specular_integrals) within 3 standard errors."""
    from pbrkit.albedo.tables import specular_integrals

    roughness = 0.8
    material = MaterialSpec(model="cook_torrance", name="m", metallic=1.0, roughness=roughness, masking=masking, fresnel="none",
                            diffuse="none")
    scene = sphere_scene(material, EnvironmentSpec(color=(1.0, 1.0, 1.0)), size=18)
    result = render_reference(scene, spp=2048, seed=1)
    mask, p, v = pixel_geometry(scene)
    inner = mask & result.mask
    mu = np.sum(p * v, axis=-1)[inner]
    ab = specular_integrals(mu, [roughness], visibility=masking)[0]
    albedo = ab[:, 0] + ab[:, 1]
    z = (result.image[inner][:, 0] - albedo) / np.maximum(result.stderr[inner][:, 0], 1e-12)
    assert inner.sum() > 120
    assert np.mean(np.abs(z) > 3.0) <= 0.01, np.sort(np.abs(z))[-5:]
    assert np.abs(z).max() < 4.5
    assert 0.6 < np.mean(z * z) < 1.5  # the standard errors are honest
    # the other masking term is rejected: its albedo is several standard errors away
    other = "height-correlated" if masking == "separable" else "separable"
    ab2 = specular_integrals(mu, [roughness], visibility=other)[0]
    z_other = (result.image[inner][:, 0] - ab2[:, 0] - ab2[:, 1]) / result.stderr[inner][:, 0]
    assert np.mean(z_other * z_other) > 4.0


def _octant_colour(d):
    """Eight distinct colours by the signs of (x, y, z)."""
    d = np.asarray(d)
    return np.stack([np.where(d[..., 0] > 0, 1.0, 0.05), np.where(d[..., 1] > 0, 1.0, 0.05),
                     np.where(d[..., 2] > 0, 1.0, 0.05)], axis=-1) * np.where(d[..., 1:2] > 0, 1.0, 0.5)


@pytest.mark.parametrize("mode", ["reference", "realtime"])
def test_mirror_sphere_reflects_the_conventional_direction(mode):
    """Roughness 0, F = 1: the pixel shows the environment in the mirror direction
    r = 2 (n.v) n - v, looked up with the equirect mapping of CONVENTIONS.md."""
    env = EnvironmentSpec(equirect=equirect_of(_octant_colour, 128))
    material = MaterialSpec(model="cook_torrance", name="m", metallic=1.0, roughness=0.0, fresnel="none", diffuse="none")
    scene = sphere_scene(material, env, size=40, fov=30.0)
    cam = scene.camera
    if mode == "reference":
        result = render_reference(scene, spp=8, seed=2)
    else:
        result = render_realtime(scene, bake_size=64)
    mask, p, v = pixel_geometry(scene)
    r = 2.0 * np.sum(p * v, axis=-1, keepdims=True) * p - v
    margin = np.min(np.abs(r), axis=-1) > 0.15  # away from the octant boundaries
    sel = mask & margin & result.mask
    expected = _octant_colour(r)[sel]
    got = result.image[sel]
    assert sel.sum() > 300
    # the octant colours differ by >= 0.45 in some channel; a wrong mirror or axis convention fails here
    assert np.mean(np.all(np.abs(got - expected) < 0.12, axis=-1)) > 0.97
    # and the camera sees the environment itself around the sphere (row 0 = up: +Y colours at the top)
    top = result.image[0, cam.width // 2]
    assert top[1] > 0.9 and EnvironmentLight(env).background(cam.ray_directions()[0, cam.width // 2])[0][1] > 0.9


@pytest.mark.parametrize("roughness", [0.3, 0.75])
def test_realtime_equals_reference_where_the_split_sum_is_exact(roughness):
    """Constant environment: the prefiltered chain is constant, so the split sum is
    exact and real time (DFG table) must match the Monte Carlo integral."""
    material = MaterialSpec(name="m", metallic=1.0, roughness=roughness, base_color=(0.95, 0.64, 0.3))
    scene = sphere_scene(material, EnvironmentSpec(color=(0.8, 0.8, 0.8)), size=16)
    ref = render_reference(scene, spp=512, seed=3)
    rt = render_realtime(scene, bake_size=32)
    sel = ref.mask & rt.mask
    z = (rt.image[sel] - ref.image[sel]) / np.sqrt(ref.stderr[sel] ** 2 + (2e-3 * ref.image[sel]) ** 2)
    assert np.mean(np.abs(z) > 3) < 0.01 and np.abs(z).max() < 5.0


def test_realtime_mirror_converges_to_reference_in_a_smooth_environment():
    def sky(d):
        return np.stack([0.6 + 0.4 * d[..., 0], 0.7 + 0.3 * d[..., 1], 0.5 + 0.5 * d[..., 2] ** 2], axis=-1)

    material = MaterialSpec(name="m", metallic=1.0, roughness=0.0, base_color=(0.9, 0.9, 0.9))
    scene = sphere_scene(material, EnvironmentSpec(equirect=equirect_of(sky, 256)), size=24)
    ref = render_reference(scene, spp=16, seed=4)
    rt = render_realtime(scene, bake_size=128)
    sel = ref.mask & rt.mask
    rel = np.abs(rt.image[sel] - ref.image[sel]) / ref.image[sel]
    assert np.median(rel) < 0.01 and np.percentile(rel, 95) < 0.03


def _half_vector_truth(scene, env, material_spec, pixels, n_theta=40, n_phi=40):
    """Integral of f (n.l) L(l) dl per pixel by Gauss quadrature over the half vector
    (pbrkit.albedo.furnace.half_vector_domain, mirrored for the full azimuth), with the NumPy
    model pbrkit.brdf.models.cook_torrance and the environment's own texel lookup."""
    from pbrkit.albedo.furnace import half_vector_domain

    mask, p, v = pixel_geometry(scene)
    alpha = max(material_spec.roughness ** 2, 1e-3)
    out = []
    material = material_spec.material()
    for (i, j) in pixels:
        n = p[i, j]
        vv = v[i, j]
        mu = float(n @ vv)
        x = vv - mu * n
        x /= np.linalg.norm(x)
        y = np.cross(n, x)
        h, w = half_vector_domain(np.array(mu), np.array(alpha), n_theta, n_phi)
        h = h.reshape(-1, 3)
        w = w.reshape(-1)
        total = np.zeros(3)
        for sign in (1.0, -1.0):
            hl = h * np.array([1.0, sign, 1.0])
            v_local = np.array([math.sqrt(max(0.0, 1 - mu * mu)), 0.0, mu])
            voh = hl @ v_local
            l_local = 2.0 * voh[:, None] * hl - v_local
            l_world = l_local[:, :1] * x + l_local[:, 1:2] * y + l_local[:, 2:3] * n
            f = cook_torrance(l_local, v_local, np.array([0.0, 0.0, 1.0]), material, fresnel="schlick",
                              diffuse="none")
            g = 4.0 * voh * np.maximum(l_local[:, 2], 0.0) * w * 0.5
            total += np.sum(f * env.lookup(l_world) * g[:, None], axis=0)
        out.append(total)
    return np.array(out)


def test_compare_reports_the_split_sum_error_against_independent_quadrature():
    """A rough metal under a smooth environment with a soft bright lobe: the ground
    truth agrees with half-vector quadrature of the lit integral, and the errors that
    compare reports for the real-time image are its errors against that quadrature
    (the known split-sum error), well above the ground truth's noise."""
    def sky(d):
        s = np.array([0.5, 0.6, -0.62])
        s /= np.linalg.norm(s)
        lobe = np.maximum(d @ s, 0.0) ** 6
        return 0.15 + np.stack([3.0 * lobe, 2.6 * lobe, 2.0 * lobe], axis=-1)

    spec = MaterialSpec(model="cook_torrance", name="m", metallic=1.0, roughness=0.5, base_color=(0.95, 0.93, 0.88), diffuse="none")
    env_spec = EnvironmentSpec(equirect=equirect_of(sky, 128))
    scene = sphere_scene(spec, env_spec, size=12, fov=28.0)
    env = EnvironmentLight(env_spec)
    ref = render_reference(scene, spp=2048, seed=5, env=env)
    rt = render_realtime(scene, env=env, bake_size=64)
    mask = ref.mask & rt.mask
    pixels = list(zip(*np.nonzero(mask)))
    truth = _half_vector_truth(scene, env, spec, pixels)
    got = ref.image[mask]
    z = (got - truth) / np.sqrt(ref.stderr[mask] ** 2 + (3e-3 * truth) ** 2)
    assert np.mean(np.abs(z) > 3) < 0.02 and np.abs(z).max() < 5.0
    metrics = compare_images(rt.image, ref.image, mask, ref.stderr, flip=True)
    y_true = luminance(truth)
    true_rel = np.abs(luminance(rt.image[mask]) - y_true) / y_true
    assert metrics["pixels"] == mask.sum()
    assert metrics["mean_relative_error"] == pytest.approx(true_rel.mean(), abs=3 * metrics["mean_relative_stderr"])
    assert true_rel.mean() > 5 * metrics["mean_relative_stderr"]  # a real error, not noise
    assert 0.0 < metrics["flip"] < 1.0


# ======================================================= bounces and lights


@pytest.mark.parametrize("engine", ["fused", "wavefront"])
def test_bounces_inside_a_closed_emissive_sphere_sum_the_geometric_series(engine):
    """Camera inside a sphere whose Lambertian inner wall has albedo rho and emits Le:
    with B bounces every pixel is Le (1 + rho + ... + rho^(B + 1)) exactly (cosine
    sampling of a Lambertian lobe has zero variance, the walls block the environment)."""
    rho, le = 0.6, 0.5
    material = MaterialSpec(model="cook_torrance", name="m", base_color=(rho, rho, rho), metallic=0.0, fresnel="none",
                            specular_color=(0.0, 0.0, 0.0), emissive=(le, le, le))
    cam = Camera(position=(0.0, 0.0, 0.3), look_at=(0.0, 0.0, -1.0), fov=60.0, width=6, height=6)
    scene = Scene(camera=cam, environment=EnvironmentSpec(color=(5.0, 5.0, 5.0)),
                  materials={"default": MaterialSpec(), "m": material},
                  objects=(Sphere(center=(0.0, 0.0, 0.0), radius=2.0, material="m"),))
    for bounces in (0, 1, 3):
        result = render_reference(scene, spp=8, bounces=bounces, seed=6, engine=engine)
        expected = le * (1 - rho ** (bounces + 2)) / (1 - rho)
        np.testing.assert_allclose(result.image, expected, rtol=1e-9)
        np.testing.assert_allclose(result.stderr, 0.0, atol=1e-9)


def test_point_and_spot_lights_follow_the_inverse_square_law():
    """A Lambertian floor lit by a point light I at height h: L = rho / pi * I cos / d^2
    (black environment), in both modes; a sphere between them casts a shadow."""
    rho, intensity, height = 0.5, 20.0, 2.0
    floor = MaterialSpec(model="cook_torrance", name="floor", base_color=(rho, rho, rho), fresnel="none", specular_color=(0, 0, 0))
    cam = Camera(position=(0.0, 6.0, 0.01), look_at=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0), fov=60.0, width=24,
                 height=24)
    env = EnvironmentSpec(color=(0.0, 0.0, 0.0))
    for light in (Light(type="point", position=(0.0, height, 0.0), intensity=intensity),
                  Light(type="spot", position=(0.0, height, 0.0), direction=(0.0, -1.0, 0.0), intensity=intensity,
                        inner_cone_angle=1.2, outer_cone_angle=1.3)):
        scene = Scene(camera=cam, environment=env, materials={"default": MaterialSpec(), "floor": floor},
                      objects=(Plane(point=(0, 0, 0), normal=(0, 1, 0), material="floor"),), lights=(light,))
        d = cam.ray_directions()[:, :, 0]
        t = -cam.position[1] / d[..., 1]
        p = np.asarray(cam.position) + t[..., None] * d
        to_light = np.array([0.0, height, 0.0]) - p
        dist = np.linalg.norm(to_light, axis=-1)
        expected = rho / np.pi * intensity * (to_light[..., 1] / dist) / dist**2
        for result in (render_realtime(scene, bake_size=16), render_reference(scene, spp=2)):
            np.testing.assert_allclose(result.image[..., 0], expected, rtol=1e-9)
    # a sphere between the light and the floor's centre shadows it, in both modes
    shadowed = Scene(camera=cam, environment=env,
                     materials={"default": MaterialSpec(), "floor": floor},
                     objects=(Plane(point=(0, 0, 0), normal=(0, 1, 0), material="floor"),
                              Sphere(center=(0.0, 1.0, 0.0), radius=0.3, material="floor")),
                     lights=(Light(type="point", position=(0.0, height, 0.0), intensity=intensity),))
    for result in (render_realtime(shadowed, bake_size=16), render_reference(shadowed, spp=2)):
        rows, cols = cam.project(np.array([[0.45, 0.0, 0.0]]))
        assert result.image[int(rows[0]), int(cols[0]), 0] == 0.0  # in the shadow
        assert result.image[1, 1, 0] > 0.0


def test_spot_cone_and_directional_light():
    floor = MaterialSpec(model="cook_torrance", name="floor", base_color=(1.0, 1.0, 1.0), fresnel="none", specular_color=(0, 0, 0))
    cam = Camera(position=(0.0, 5.0, 0.01), look_at=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0), fov=70.0, width=16,
                 height=16)
    env = EnvironmentSpec(color=(0.0, 0.0, 0.0))
    sun = Light(type="directional", direction=(0.0, -1.0, -1.0), intensity=3.0, color=(1.0, 0.5, 0.25))
    scene = Scene(camera=cam, environment=env, materials={"default": MaterialSpec(), "floor": floor},
                  objects=(Plane(point=(0, 0, 0), normal=(0, 1, 0), material="floor"),), lights=(sun,))
    img = render_realtime(scene, bake_size=16).image
    np.testing.assert_allclose(img, np.broadcast_to(np.array([1.0, 0.5, 0.25]) * 3.0 / np.pi / math.sqrt(2),
                                                    img.shape), rtol=1e-12)
    spot = Light(type="spot", position=(0.0, 1.0, 0.0), direction=(0.0, -1.0, 0.0), intensity=1.0,
                 inner_cone_angle=0.3, outer_cone_angle=0.6)
    scene = Scene(camera=cam, environment=env, materials={"default": MaterialSpec(), "floor": floor},
                  objects=(Plane(point=(0, 0, 0), normal=(0, 1, 0), material="floor"),), lights=(spot,))
    img = render_reference(scene, spp=1).image[..., 0]
    d = cam.ray_directions()[:, :, 0]
    p = np.asarray(cam.position) + (-cam.position[1] / d[..., 1])[..., None] * d
    angle = np.arctan2(np.hypot(p[..., 0], p[..., 2]), 1.0)
    assert np.all(img[angle > 0.6 + 1e-9] == 0.0)
    inside = angle < 0.3 - 1e-9
    dist2 = 1.0 + p[..., 0] ** 2 + p[..., 2] ** 2
    np.testing.assert_allclose(img[inside], (1.0 / np.pi * np.cos(angle) / dist2)[inside], rtol=1e-12)


def test_energy_compensation_makes_the_realtime_furnace_white():
    """Filament's 1 + F0 (1 / DFG2 - 1) with F = 1 turns the albedo DFG2 into 1."""
    material = MaterialSpec(model="cook_torrance", name="m", metallic=1.0, roughness=0.9, fresnel="none", diffuse="none")
    scene = sphere_scene(material, EnvironmentSpec(color=(1.0, 1.0, 1.0)), size=12)
    plain = render_realtime(scene, bake_size=32)
    comp = render_realtime(scene, bake_size=32, energy_compensation=True)
    sel = plain.mask
    assert plain.image[sel].min() < 0.85
    np.testing.assert_allclose(comp.image[sel], 1.0, atol=2e-5)


# ================================================ engines, determinism, tone maps


def test_fused_and_wavefront_engines_give_the_same_numbers():
    scene = sphere_scene(MaterialSpec(name="m", metallic=0.3, roughness=0.35, base_color=(0.7, 0.5, 0.3)),
                         EnvironmentSpec(), size=10, lights=(Light(type="point", position=(2, 2, 2), intensity=5),))
    scene = Scene(camera=scene.camera, environment=scene.environment, materials=scene.materials,
                  objects=scene.objects + (Plane(point=(0, -1, 0), normal=(0, 1, 0), material="m"),),
                  lights=scene.lights)
    for bounces in (0, 2):
        a = render_reference(scene, spp=6, bounces=bounces, seed=9, engine="fused")
        b = render_reference(scene, spp=6, bounces=bounces, seed=9, engine="wavefront")
        np.testing.assert_allclose(a.image, b.image, rtol=1e-10, atol=1e-13)
        np.testing.assert_allclose(a.stderr, b.stderr, rtol=1e-7, atol=1e-12)


def test_reference_is_deterministic_and_seeded():
    scene = sphere_scene(MaterialSpec(name="m", roughness=0.4), EnvironmentSpec(), size=8, supersample=2)
    a = render_reference(scene, spp=8, seed=1)
    b = render_reference(scene, spp=8, seed=1)
    c = render_reference(scene, spp=8, seed=2)
    assert a.image.tobytes() == b.image.tobytes() and a.stderr.tobytes() == b.stderr.tobytes()
    assert not np.array_equal(a.image, c.image)


def test_brdf_sampling_only_agrees_with_mis_and_is_noisier():
    scene = sphere_scene(MaterialSpec(name="m", roughness=0.3, metallic=0.0), EnvironmentSpec(), size=10)
    mis = render_reference(scene, spp=256, seed=7)
    brdf = render_reference(scene, spp=256, seed=8, strategy="brdf")
    sel = mis.mask
    z = (mis.image[sel] - brdf.image[sel]) / np.sqrt(mis.stderr[sel] ** 2 + brdf.stderr[sel] ** 2)
    assert np.mean(np.abs(z) > 3) < 0.02
    assert np.mean(mis.stderr[sel] ** 2) < np.mean(brdf.stderr[sel] ** 2)


def test_tone_mappers():
    x = np.linspace(0.0, 50.0, 2001)[:, None] * np.array([1.0, 0.6, 0.3])
    for name in TONEMAPS:
        y = tonemap(x, name)
        assert y.min() >= 0.0 and y.max() <= 1.0
        # monotonic in the input's scale (AgX's polynomial fit overshoots by < 1e-5 near white)
        assert np.all(np.diff(y[:, 0]) >= (-1e-5 if name == "agx" else -1e-12))
    assert tonemap(np.array([1.0, 1.0, 1.0]), "reinhard")[0] == 0.5
    assert tonemap(np.array([0.25, 0.25, 0.25]), "reinhard", exposure=2.0)[0] == 0.5
    # Khronos PBR Neutral is the identity minus the 0.04 offset below the compression start
    np.testing.assert_allclose(tonemap(np.array([0.5, 0.3, 0.2]), "khronos-neutral"), [0.46, 0.26, 0.16])
    np.testing.assert_allclose(tonemap(np.array([0.5, 0.3, 2.0]), "none"), [0.5, 0.3, 1.0])
    # Hill's ACES fit: RRTAndODTFit(0) = -0.000090537 / 0.238081 -> 0 after the clamp; white saturates;
    # mid grey 0.18 -> ~0.106 (three.js scales the input by 1 / 0.6 to lift it; pbrkit leaves that to --exposure)
    assert tonemap(np.zeros(3), "aces")[0] == 0.0
    assert tonemap(np.full(3, 100.0), "aces")[0] == pytest.approx(1.0, abs=2e-2)
    assert tonemap(np.full(3, 0.18), "aces")[0] == pytest.approx(0.1056, abs=1e-3)
    # AgX keeps mid grey near 0.18-0.22 (display linear) and stays neutral for grey input
    agx_grey = tonemap(np.full(3, 0.18), "agx")
    assert 0.18 < agx_grey[0] < 0.25 and np.ptp(agx_grey) < 1e-3
    with pytest.raises(ValueError, match="tone mapper"):
        tonemap(x, "filmic")


# ====================================================================== CLI


def _cli(args):
    from typer.testing import CliRunner

    from pbrkit.cli import app

    return CliRunner().invoke(app, args)


def test_cli_render_modes_write_their_files(tmp_path):
    import imageio.v3 as iio

    from pbrkit.io.exr import read_exr

    def read_image(path):
        return read_exr(path) if path.suffix == ".exr" else iio.imread(path)

    out = tmp_path / "a.png"
    r = _cli(["render", "sphere", "-o", str(out), "--width", "24", "--height", "16", "--bake-size", "32", "-q"])
    assert r.exit_code == 0, r.output
    assert read_image(out).shape == (16, 24, 3)
    out = tmp_path / "b.exr"
    r = _cli(["render", "sphere", "-o", str(out), "--mode", "reference", "--spp", "4", "--width", "16", "--height",
              "16", "--tonemap", "agx"])
    assert r.exit_code == 0, r.output
    assert read_image(out).shape == (16, 16, 3) and (tmp_path / "b.stderr.exr").exists()
    out = tmp_path / "c.png"
    r = _cli(["render", "spheres", "-o", str(out), "--mode", "compare", "--spp", "4", "--width", "28", "--height",
              "28", "--bake-size", "32", "--no-occlusion"])
    assert r.exit_code == 0, r.output
    shape = read_image(out).shape  # the titled figure: three 28-row panels shown at 280 rows, a colour bar
    assert shape[2] == 3 and shape[0] > 280 and shape[1] > 3 * 280
    assert "mean relative error" in r.output and "FLIP" in r.output


@pytest.mark.parametrize("args, fragment", [
    (["render", "nosuchscene.toml", "-o", "{out}"], "no such scene file"),
    (["render", "sphere", "-o", "{dir}/x.jpg"], "must be .exr"),
    (["render", "sphere", "-o", "{out}", "--mode", "fast"], "unknown mode"),
    (["render", "sphere", "-o", "{out}", "--tonemap", "filmic"], "unknown tone mapper"),
    (["render", "sphere", "-o", "{out}", "--mode", "reference", "--spp", "0"], "spp"),
    (["render", "sphere", "-o", "{out}", "--width", "0"], "--width"),
    (["render", "sphere", "-o", "{out}", "--env", "{dir}/missing.hdr"], "not found"),
    (["render", "{dir}/bad.toml", "-o", "{out}"], "unknown key"),
])
def test_cli_render_errors_are_one_line_with_no_output(tmp_path, args, fragment):
    (tmp_path / "bad.toml").write_text("[camera]\nlens = 2\n[[objects]]\ntype = 'sphere'\n")
    out = tmp_path / "out.png"
    r = _cli([a.format(out=out, dir=tmp_path) for a in args])
    assert r.exit_code == 1
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "pbrkit: error:" in lines[0] and fragment in lines[0], r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


# ======================================================= every model in scenes


def _local_view(n, v, anisotropic):
    """View in the frame of pbrkit.brdf.bxdf.tangent_frame, written independently:
    t = normalize(n x Y) for anisotropic lobes (n away from the poles)."""
    t = np.cross(n, [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    b = np.cross(n, t)
    assert anisotropic
    return np.stack([np.sum(v * t, -1), np.sum(v * b, -1), np.sum(v * n, -1)], axis=-1)


@pytest.mark.slow
def test_disney_with_clear_coat_sheen_and_anisotropy_renders_in_both_modes():
    """Under a constant white environment each pixel of the ground truth is the
    directional albedo of the full Disney BRDF (diffuse, subsurface, sheen,
    anisotropic specular, clear coat) at that pixel's view, integrated by the
    independent rule of tests/support/quadrature.py; the real-time image approximates it
    (split sum, (1 - F*) diffuse weight, tabulated sheen, clear coat as a GGX lobe)."""
    from quadrature import albedo_nodes

    from pbrkit.brdf.models import disney

    spec = MaterialSpec(name="m", model="disney", base_color=(0.7, 0.3, 0.2), metallic=0.2, roughness=0.45,
                        anisotropy=0.6, subsurface=0.3, sheen=0.8, sheen_tint=0.4, specular_tint=0.2,
                        clearcoat=1.0, clearcoat_gloss=0.6)
    scene = sphere_scene(spec, EnvironmentSpec(color=(1.0, 1.0, 1.0)), size=14)
    ref = render_reference(scene, spp=512, seed=3)
    rt = render_realtime(scene, bake_size=32)
    mask, p, v = pixel_geometry(scene)
    inner = mask & ref.mask & (np.abs(p[..., 1]) < 0.9)  # away from the tangent frame's poles
    wo = _local_view(p[inner], v[inner], True)
    material = spec.material()
    a = max(spec.roughness ** 2, 1e-3)
    aspect = np.sqrt(1.0 - 0.9 * spec.anisotropy)
    albedo = []
    for w in wo:
        l, weight = albedo_nodes(w, a / aspect, a * aspect, n_psi_nodes=6, psi_levels=5, n_panels=24, n_nodes=6)
        f = disney(l, np.broadcast_to(w, l.shape), np.array([0.0, 0.0, 1.0]), material,
                   t=np.array([1.0, 0.0, 0.0]))
        albedo.append(np.tensordot(weight, f, axes=(0, 0)))
    albedo = np.array(albedo)
    z = (ref.image[inner] - albedo) / np.maximum(ref.stderr[inner], 1e-12)
    assert inner.sum() > 60
    assert np.mean(np.abs(z) > 3.0) <= 0.02, np.sort(np.abs(z).ravel())[-5:]
    assert 0.5 < np.mean(z * z) < 1.6
    # the real-time image: finite, positive, and within the split-sum approximations' error
    assert np.all(np.isfinite(rt.image)) and np.all(rt.image[inner] > 0.0)
    rel = np.abs(rt.image[inner] - albedo) / albedo
    assert np.mean(rel) < 0.1, np.mean(rel)


@pytest.mark.parametrize("model, extra", [("disney", {"clearcoat": 0.7, "sheen": 0.5}),
                                          ("cook_torrance", {"anisotropy": -0.5, "distribution": "beckmann"}),
                                          ("filament", {"anisotropy": 0.6, "diffuse": "burley"}),
                                          ("gltf", {"sheen_color": [1.0, 0.8, 0.6], "sheen_roughness": 0.5})])
def test_scene_file_materials_of_every_model_render(tmp_path, model, extra):
    import json

    scene = {"camera": {"width": 12, "height": 12, "position": [0, 0, 4], "fov": 35},
             "environment": {"color": [0.8, 0.9, 1.0]},
             "materials": {"m": {"model": model, "roughness": 0.4, "base_color": [0.7, 0.5, 0.3], **extra}},
             "objects": [{"type": "sphere", "material": "m"}],
             "lights": [{"type": "directional", "direction": [0.3, -1.0, -0.5], "intensity": 2.0}]}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    from pbrkit.rendering.scene import load_scene

    s = load_scene(path)
    rt = render_realtime(s, bake_size=16)
    ref = render_reference(s, spp=16, seed=0)
    for image in (rt.image, ref.image):
        assert np.all(np.isfinite(image)) and image[rt.mask].min() > 0.0
    # the two modes agree to the accuracy of the real-time approximations plus the noise
    assert abs(rt.image[rt.mask].mean() / ref.image[rt.mask].mean() - 1.0) < 0.15


@pytest.mark.parametrize("material, fragment", [
    (dict(model="ue4", anisotropy=0.3), "anisotropy needs model 'cook_torrance', 'filament' or 'disney'"),
    (dict(model="filament", sheen=0.5), "sheen needs model 'disney'"),
    (dict(model="disney", anisotropy=-0.2), r"anisotropy must be in \[0, 1\] for model 'disney' \(Burley"),
    (dict(model="cook_torrance", distribution="blinn-phong", anisotropy=0.2), "Blinn-Phong"),
    (dict(model="gltf", anisotropy=0.2), "anisotropy needs model"),
    (dict(model="gltf", reflectance=0.3), "reflectance needs model"),
    (dict(model="urp_mobile", reflectance=0.3), "reflectance needs model"),
    (dict(distribution="beckmann"), "fixes it"),
    (dict(model="disney", diffuse="none"), "fixes it: burley"),
    (dict(model="filament", diffuse="eon"), "model 'filament' has no diffuse 'eon'"),
])
def test_scene_materials_refuse_options_their_model_lacks(material, fragment):
    with pytest.raises(ValueError, match=fragment):
        MaterialSpec(name="m", **material)
