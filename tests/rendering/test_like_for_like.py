"""Like-for-like comparisons: the glTF 2.0 metallic-roughness BRDF (Appendix B) as a
model, its diffuse weighting integrated exactly by the ground truth and approximated
by the real-time path, and ``compare`` measuring the real-time approximations only
(split sum, F*, SH), with each one's share."""

import math

import numpy as np
import pytest
from quadrature import hemisphere_rule
from reference_brdf import d_ggx, fresnel_schlick
from render_scenes import pixel_geometry, sphere_scene
from typer.testing import CliRunner

from pbrkit import Material
from pbrkit.cli import app
from pbrkit.brdf import models
from pbrkit.brdf.fresnel import f_schlick_roughness
from pbrkit.rendering.compare import compare_images, relative_error_pixels
from pbrkit.rendering.environment import EnvironmentLight
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.realtime import fresnel_mix_albedo_table, render_realtime
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.run import approximation_split, render_scene
from pbrkit.rendering.scene import EnvironmentSpec, MaterialSpec, builtin_scene


def _appendix_b(l, v, n, base, metallic, roughness):
    """glTF 2.0 Appendix B, written from the specification's definitions:
    material = mix(fresnel_mix(1.5, diffuse_brdf(base), specular_brdf), conductor_fresnel(base, specular_brdf),
    metallic); specular_brdf = D_GGX * G1(l) G1(v) / (4 |n.l| |n.v|) with
    G1(x) = 2 |n.x| / (|n.x| + sqrt(a^2 + (1 - a^2)(n.x)^2)); F = f0 + (1 - f0)(1 - |v.h|)^5."""
    a = roughness * roughness
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    nl, nv, nh, vh = (np.sum(x * y, axis=-1) for x, y in ((n, l), (n, v), (n, h), (v, h)))

    def g1(c):
        return 2.0 * np.abs(c) / (np.abs(c) + np.sqrt(a * a + (1.0 - a * a) * c * c))

    spec = (d_ggx(nh, 1.0 - nh * nh, a) * g1(nl) * g1(nv) / (4.0 * np.abs(nl) * np.abs(nv)))[..., None]
    f_d = fresnel_schlick(np.abs(vh), ((1.0 - 1.5) / (1.0 + 1.5)) ** 2)[..., None]
    dielectric = (1.0 - f_d) * base / np.pi + f_d * spec
    metal = spec * fresnel_schlick(np.abs(vh)[..., None], base)
    f = (1.0 - metallic) * dielectric + metallic * metal
    return np.where(((nl > 0) & (nv > 0))[..., None], f, 0.0)


def test_gltf_model_is_appendix_b():
    rng = np.random.default_rng(9)
    n = np.array([0.0, 0.0, 1.0])
    for _ in range(20):
        base = rng.random(3)
        metallic, roughness = rng.random(), 0.05 + 0.95 * rng.random()
        l = rng.normal(size=(500, 3))
        v = rng.normal(size=(500, 3))
        l /= np.linalg.norm(l, axis=-1, keepdims=True)
        v /= np.linalg.norm(v, axis=-1, keepdims=True)
        got = models.gltf(l, v, n, Material(base_color=base, metallic=metallic, roughness=roughness))
        want = _appendix_b(l, v, n, base, metallic, roughness)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_fresnel_mix_albedo_against_independent_quadrature():
    # W(mu) = integral over l of (1 - F_0.04(v.h)) (n.l) / pi, by a plain hemisphere rule.
    table = fresnel_mix_albedo_table()
    l, w = hemisphere_rule(96, 96)
    for i in (0, 5, 31, 63):
        mu = (i + 0.5) / table.size
        v = np.array([math.sqrt(1.0 - mu * mu), 0.0, mu])
        h = l + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        weight = 1.0 - fresnel_schlick(np.clip(h @ v, 0.0, 1.0), 0.04)
        want = float(np.sum(w * weight * l[:, 2])) / math.pi
        assert abs(table[i] - want) < 2e-5, (i, table[i], want)
    # It is not 1 - F*: that is the approximation compare measures.
    mu = (np.arange(table.size) + 0.5) / table.size
    assert np.abs((1.0 - f_schlick_roughness(mu, 0.04, 0.2)) - table).max() > 0.05


def _constant_scene(metallic, roughness, size=16):
    spec = MaterialSpec(name="m", metallic=metallic, roughness=roughness, base_color=(0.7, 0.5, 0.3))
    return sphere_scene(spec, EnvironmentSpec(color=(0.8, 0.8, 0.8)), size=size)


@pytest.mark.parametrize("metallic, roughness", [(0.0, 0.3), (0.5, 0.7)])
def test_realtime_with_exact_diffuse_weight_is_the_ground_truth_in_a_constant_environment(metallic, roughness):
    """In a constant environment the split sum is exact, SH and the irradiance cube are
    exact, and the exact diffuse weight W(n.v) is the diffuse integral: the real-time
    path must then agree with the Monte Carlo integral of the glTF BRDF (the default
    model) within its noise; with F* it must differ by exactly the F* error."""
    scene = _constant_scene(metallic, roughness)
    assert scene.materials["m"].model == "gltf"
    env = EnvironmentLight(scene.environment)
    ref = render_reference(scene, spp=1024, seed=11, env=env)
    exact = render_realtime(scene, env=env, bake_size=32, diffuse_weight="exact")
    fstar = render_realtime(scene, env=env, bake_size=32)
    sel = ref.mask & exact.mask
    tolerance = np.sqrt(ref.stderr[sel] ** 2 + (2e-3 * ref.image[sel]) ** 2)
    z = (exact.image[sel] - ref.image[sel]) / tolerance  # the channels share their samples: count pixels
    assert np.mean(np.abs(z).max(axis=1) > 3) < 0.03 and np.abs(z).max() < 5.0
    # With F*, the real-time image differs from the exact one by the diffuse colour times
    # (1 - F*(n.v, 0.04, r)) - W(n.v) times the radiance (E / pi = L): all of it F*'s (SH is exact here),
    # and far above the noise at grazing n.v.
    _, p, v = pixel_geometry(scene)
    nov = np.clip(np.sum(p * v, axis=-1)[sel], 0.0, 1.0)
    w = np.interp(nov, (np.arange(64) + 0.5) / 64, fresnel_mix_albedo_table())
    predicted = (np.array([0.7, 0.5, 0.3]) * (1.0 - metallic) * 0.8
                 * ((1.0 - f_schlick_roughness(nov, 0.04, roughness)) - w)[:, None])
    np.testing.assert_allclose(fstar.image[sel] - exact.image[sel], predicted, atol=2e-3)
    assert np.abs((fstar.image[sel] - ref.image[sel]) / tolerance).max() > 6


def test_compare_defaults_are_like_for_like(tmp_path):
    scene = builtin_scene("spheres", 28, 28)
    summary = render_scene(scene, tmp_path / "c.exr", mode="compare", spp=4, bake_size=32, flip=False)
    assert summary["reference"]["includes"] == {"occlusion": False, "bounces": 0}
    assert summary["reference"]["occlusion"] is False
    assert set(summary["errors"]["split"]) == {"sh", "fstar", "split_sum"}
    assert (tmp_path / "c.exr").is_file() and (tmp_path / "c.stderr.exr").is_file()
    ref = render_scene(scene, tmp_path / "r.exr", mode="reference", spp=2)
    assert ref["reference"]["includes"] == {"occlusion": True, "bounces": 0}
    assert all(m.model == "gltf" for m in scene.materials.values())


def test_split_isolates_each_approximation_in_a_constant_environment():
    """Constant environment: SH is exact (its share is 0), the split sum is exact (the
    remainder is within noise of 0) and the whole error is F*'s."""
    scene = _constant_scene(0.2, 0.5, size=20)
    env = EnvironmentLight(scene.environment)
    bake = env.bake(size=32)
    geometry = Geometry(scene)
    rt = render_realtime(scene, geometry, env, bake=bake)
    ref = render_reference(scene, spp=1024, seed=3, geometry=geometry, env=env)
    mask = rt.mask & ref.mask
    split = approximation_split(scene, geometry, env, bake, rt.image, ref.image, ref.stderr, mask)
    metrics = compare_images(rt.image, ref.image, mask, ref.stderr, flip=False)
    assert split["sh"]["rms_relative_error"] < 1e-3
    assert split["split_sum"]["rms_relative_error"] < 0.01
    assert split["fstar"]["rms_relative_error"] > 0.02
    assert split["fstar"]["rms_relative_error"] == pytest.approx(metrics["rms_relative_error_noise_removed"],
                                                                 rel=0.25)
    assert relative_error_pixels(ref.image, mask).sum() == metrics["pixels"]


def test_cli_compare_says_what_the_ground_truth_includes(tmp_path):
    out = tmp_path / "c.png"
    r = CliRunner().invoke(app, ["render", "spheres", "-o", str(out), "--mode", "compare", "--spp", "4",
                                 "--width", "24", "--height", "24", "--bake-size", "32"])
    assert r.exit_code == 0, r.output
    assert "environment and area lights unoccluded, direct light only" in r.output
    assert "approximation error: HDR-FLIP" in r.output and "RMS relative error" in r.output
    for name in ("sh", "fstar", "split_sum"):
        assert f"  {name} " in r.output
    r = CliRunner().invoke(app, ["render", "spheres", "-o", str(out), "--mode", "compare", "--spp", "4",
                                 "--width", "24", "--height", "24", "--bake-size", "32", "--occlusion"])
    assert r.exit_code == 0, r.output
    assert "inter-object occlusion" in r.output and "approximation error" not in r.output
