"""KHR_materials_transmission and KHR_materials_volume in the ground truth
(pbrkit.brdf.transmission, the estimator's transmissive vertices, the engines' media),
each against something independent:

- the BSDF's value against a transcription of the READMEs' formulas
  (reference_brdf.gltf_transmission_bsdf), both sides, thin and volume;
- the mixture sampler against its pdf by chi-square over the whole sphere (reflection,
  refraction both ways, total internal reflection, thin walls), and each sample's
  weight against f |cos| / pdf;
- the renderer: a smooth glass slab (two parallel planes) in front of an emitter against
  the analytic transmittance with Fresnel at both faces and the internal reflections,
  T = (1 - R)^2 e^{-sigma d} / (1 - R^2 e^{-2 sigma d}) (R = f0 at normal incidence,
  Schlick's F there); an index-matched slab against Beer-Lambert alone; a glass sphere in
  a white environment without absorption is a white furnace; a sphere's centre pixel
  with absorption against the same series over its diameter; the fused and the
  wavefront engines agree.
"""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest

from pbrkit.brdf.bxdf import NO_TANGENT
from pbrkit.brdf.transmission import DELTA_PDF, transmissive_f, transmissive_pdf, transmissive_probabilities, \
    transmissive_sample
from pbrkit.rendering.materials import hit_bxdf, material_tables
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import Camera, EnvironmentSpec, MaterialSpec, Plane, Scene, Sphere
from pbrkit.rendering.textures import SurfaceMaterial

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
    from . import reference_brdf as ref
except ImportError:
    import chi2
    import reference_brdf as ref

SEED = 20261127


def _u(case_id, n, k):
    rng = np.random.default_rng([SEED, zlib.crc32(case_id.encode())])
    return rng.random((n, k))


def _direction(theta_degrees, phi=0.7, below=False):
    t = math.radians(theta_degrees)
    z = math.cos(t)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), -z if below else z])


def _tables(**values):
    spec = MaterialSpec(name="m", model="gltf", **values)
    return material_tables([SurfaceMaterial(spec)])


@numba.njit(error_model="numpy")
def _evaluate(codes, params, rough, metal, base, wo, wi):
    """f (N, 3) and the mixture pdf (N) at the pairs (wo, wi[i]) of row 0's material."""
    b, t, bt = hit_bxdf(codes, params, 0, rough, metal, base[0], base[1], base[2], 0.0, 0.0, 1.0,
                        NO_TANGENT)
    p_t, p_spec, p_coat = transmissive_probabilities(b, wo[2])
    f = np.empty((wi.shape[0], 3))
    pdf = np.empty(wi.shape[0])
    for i in range(wi.shape[0]):
        v = transmissive_f(b, wo[0], wo[1], wo[2], wi[i, 0], wi[i, 1], wi[i, 2])
        f[i, 0] = v[0]
        f[i, 1] = v[1]
        f[i, 2] = v[2]
        pdf[i] = transmissive_pdf(b, wo[0], wo[1], wo[2], wi[i, 0], wi[i, 1], wi[i, 2], p_t, p_spec, p_coat)
    return f, pdf


@numba.njit(error_model="numpy")
def _sample(codes, params, rough, metal, base, wo, u):
    b, t, bt = hit_bxdf(codes, params, 0, rough, metal, base[0], base[1], base[2], 0.0, 0.0, 1.0,
                        NO_TANGENT)
    p_t, p_spec, p_coat = transmissive_probabilities(b, wo[2])
    wi = np.empty((u.shape[0], 3))
    w = np.empty((u.shape[0], 3))
    pdf = np.empty(u.shape[0])
    for i in range(u.shape[0]):
        x, y, z, wt, p = transmissive_sample(b, wo[0], wo[1], wo[2], u[i, 0], u[i, 1], u[i, 2], p_t, p_spec, p_coat)
        wi[i, 0] = x
        wi[i, 1] = y
        wi[i, 2] = z
        w[i, 0] = wt[0]
        w[i, 1] = wt[1]
        w[i, 2] = wt[2]
        pdf[i] = p
    return wi, w, pdf


# (id, material values, view theta, view below)
MATERIALS = [
    ("thin-rough", dict(base_color=(0.9, 0.6, 0.3), roughness=0.5, transmission=1.0), 35.0, False),
    ("thin-half-metal", dict(base_color=(0.5, 0.8, 0.3), roughness=0.4, metallic=0.3, transmission=0.6), 60.0,
     False),
    ("thin-from-behind", dict(base_color=(0.7, 0.7, 0.9), roughness=0.3, transmission=0.8, ior=1.3), 20.0, True),
    ("volume-entering", dict(base_color=(0.9, 0.8, 0.7), roughness=0.4, transmission=1.0, thickness=1.0), 40.0,
     False),
    ("volume-specular", dict(base_color=(0.6, 0.9, 0.5), roughness=0.35, transmission=0.7, thickness=2.0,
                             ior=1.7, specular=0.7, specular_color=(1.0, 0.8, 1.2)), 70.0, False),
    ("volume-leaving", dict(base_color=(0.8, 0.8, 0.8), roughness=0.5, transmission=1.0, thickness=1.0), 25.0,
     True),
    ("volume-tir", dict(base_color=(0.8, 0.9, 1.0), roughness=0.3, transmission=1.0, thickness=1.0), 60.0, True),
]


@pytest.mark.parametrize("case_id, values, theta, below", MATERIALS, ids=[c[0] for c in MATERIALS])
def test_value_is_the_readmes(case_id, values, theta, below):
    """f on both sides against reference_brdf.gltf_transmission_bsdf (the READMEs'
    formulas, written independently), 1e-9 relative."""
    codes, params = _tables(**values)
    base = np.array(values["base_color"])
    rough = values["roughness"]
    metal = values.get("metallic", 0.0)
    wo = _direction(theta, below=below)
    rng = np.random.default_rng([SEED, zlib.crc32(case_id.encode())])
    wi = rng.normal(size=(4000, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    f, _ = _evaluate(codes, params, rough, metal, base, wo, wi)
    expected = ref.gltf_transmission_bsdf(wi, np.broadcast_to(wo, wi.shape), base, metal, rough,
                                          values["transmission"], values.get("ior", 1.5),
                                          values.get("thickness", 0.0), values.get("specular", 1.0),
                                          values.get("specular_color", (1.0, 1.0, 1.0)))
    assert np.all(np.isfinite(f))
    through = (wi[:, 2] * wo[2] < 0.0)
    assert np.count_nonzero(f[through].sum(axis=1) > 0.0) > 200  # light goes through
    np.testing.assert_allclose(f, expected, rtol=1e-9, atol=1e-12)


def _sphere_cells(wi, ok, density):
    theta, phi = chi2.directions_to_spherical(wi[ok])
    edges_t, edges_p = chi2.quantile_edges(density, (0.0, np.pi), (0.0, 2.0 * np.pi), (12, 20),
                                           fixed_a=(0.5 * np.pi,))
    probabilities = chi2.cell_integrals(density, edges_t, edges_p)
    observed = chi2.histogram2d(theta, phi, edges_t, edges_p).ravel()
    return observed, probabilities


CHI2_CASES = [c for c in MATERIALS if c[0] != "thin-from-behind"] + [
    ("volume-coated", dict(base_color=(0.9, 0.9, 0.9), roughness=0.45, transmission=0.9, thickness=1.0,
                           clearcoat=0.5, clearcoat_roughness=0.2, sheen_color=(0.3, 0.3, 0.3),
                           sheen_roughness=0.5), 30.0, False),
]
ALPHA_TEST = chi2.sidak_alpha(0.01, len(CHI2_CASES))


@pytest.mark.parametrize("case_id, values, theta, below", CHI2_CASES, ids=[c[0] for c in CHI2_CASES])
def test_sampler_matches_its_pdf_on_the_whole_sphere(case_id, values, theta, below):
    """Chi-square of the mixture's samples (reflection and transmission techniques)
    against transmissive_pdf over (theta, phi) cells of the sphere plus one cell of
    failures; every sample's weight is f |cos| / pdf at its direction."""
    codes, params = _tables(**values)
    base = np.array(values["base_color"])
    rough = values["roughness"]
    metal = values.get("metallic", 0.0)
    wo = _direction(theta, below=below)
    n = 160_000
    wi, w, pdf = _sample(codes, params, rough, metal, base, wo, _u(case_id, n, 3))
    ok = pdf > 0.0
    assert np.all(pdf[ok] < DELTA_PDF)  # rough: no deltas
    f, pdf_at = _evaluate(codes, params, rough, metal, base, wo, np.ascontiguousarray(wi[ok]))
    np.testing.assert_allclose(pdf[ok], pdf_at, rtol=1e-9)
    np.testing.assert_allclose(w[ok], f * np.abs(wi[ok, 2:3]) / pdf_at[:, None], rtol=1e-9, atol=1e-15)
    # both techniques produce samples on both sides (and, from inside, total internal reflection)
    assert np.count_nonzero(wi[ok, 2] * wo[2] < 0.0) > 100
    assert np.count_nonzero(wi[ok, 2] * wo[2] > 0.0) > 0.02 * n

    def density(t, p):
        t, p = np.broadcast_arrays(t, p)
        st = np.sin(t)
        x = np.stack([st * np.cos(p), st * np.sin(p), np.cos(t)], axis=-1)
        shape = x.shape[:-1]
        _, q = _evaluate(codes, params, rough, metal, base, wo, np.ascontiguousarray(x.reshape(-1, 3)))
        return q.reshape(shape) * st

    observed, probabilities = _sphere_cells(wi, ok, density)
    integral = float(probabilities.sum())
    observed = np.append(observed, n - ok.sum())
    expected = np.append(probabilities.ravel(), max(1.0 - integral, 0.0)) * n
    statistic, dof, p = chi2.pearson_chi2(observed, expected)
    print(f"{case_id}: chi2 p = {p:.3g} (dof {dof}), int pdf = {integral:.5f}, sampled = {ok.mean():.5f}")
    assert p > ALPHA_TEST, f"{case_id}: chi-square rejects the sampler (p = {p:.3g})"
    assert integral <= 1.0 + 1e-3
    assert integral == pytest.approx(ok.mean(), abs=5e-3)


def test_smooth_interface_is_a_delta_pair():
    """Roughness 0 and thickness > 0: the refraction is Snell's direction with weight
    (1 - F) tint / eta^2 / p_t and the delta's pdf; the reflection is the specular lobe
    (evaluated, not a delta)."""
    values = dict(base_color=(0.9, 0.8, 0.7), roughness=0.0, transmission=1.0, thickness=1.0, ior=1.5)
    codes, params = _tables(**values)
    base = np.array(values["base_color"])
    wo = _direction(40.0)
    wi, w, pdf = _sample(codes, params, 0.0, 0.0, base, wo, _u("smooth", 2000, 3))
    refracted = pdf == DELTA_PDF
    assert refracted.mean() > 0.8
    sin_t = math.sin(math.radians(40.0)) / 1.5
    np.testing.assert_allclose(wi[refracted, 2], -math.sqrt(1 - sin_t ** 2), rtol=1e-12)
    f0 = 0.04
    fresnel = f0 + (1 - f0) * (1 - math.cos(math.radians(40.0))) ** 5
    # p_t as transmissive_probabilities sets it: e_t / (e_s + e_t), clamped
    lum = 0.2126 * 0.9 + 0.7152 * 0.8 + 0.0722 * 0.7
    p_t = min(max((1 - fresnel) * lum / (fresnel + (1 - fresnel) * lum), 0.05), 0.95)
    expected = np.broadcast_to((1 - fresnel) * base / (1.5 ** 2 * p_t), w[refracted].shape)
    np.testing.assert_allclose(w[refracted], expected, rtol=1e-12)
    assert np.all(wi[~refracted & (pdf > 0), 2] > 0.0)


# ------------------------------------------------------------------ the renderer


def _slab_scene(material, depth, size=3, emitter=1.0):
    """A slab between the planes z = 0 (normal +z) and z = -depth (normal -z) of
    ``material``, an emitting black plane at z = -depth - 1 facing it, a black
    environment, the camera on the axis looking down with a narrow field."""
    cam = Camera(position=(0.0, 0.0, 3.0), look_at=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov=1.0, width=size,
                 height=size)
    materials = {"default": MaterialSpec(), "glass": material,
                 "light": MaterialSpec(model="gltf", base_color=(0.0, 0.0, 0.0), roughness=1.0,
                                       emissive=(emitter, emitter, emitter))}
    objects = (Plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="glass"),
               Plane(point=(0.0, 0.0, -depth), normal=(0.0, 0.0, -1.0), material="glass"),
               Plane(point=(0.0, 0.0, -depth - 1.0), normal=(0.0, 0.0, 1.0), material="light"))
    return Scene(camera=cam, environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)), materials=materials,
                 objects=objects)


def _series(r, tau):
    """Transmittance of a slab with interface reflectance r and one-way transmittance tau,
    every internal reflection summed: (1 - r)^2 tau / (1 - r^2 tau^2)."""
    return (1.0 - r) ** 2 * tau / (1.0 - r * r * tau * tau)


def test_smooth_slab_transmittance_is_fresnel_and_beer_lambert():
    """A smooth glass slab (ior 1.5, R = 0.04 at normal incidence) of depth 0.5 with
    attenuation colour c at distance 1 (sigma = -ln c) in front of an emitter of
    radiance 1: each pixel is (1 - R)^2 e^{-sigma d} / (1 - R^2 e^{-2 sigma d}) within
    5 standard errors (the camera's rays are within 0.5 degree of the normal, where
    Schlick's F differs from f0 by < 1e-20)."""
    color = np.array([0.9, 0.5, 0.2])
    glass = MaterialSpec(model="gltf", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, thickness=0.5,
                         attenuation_color=tuple(color), attenuation_distance=1.0)
    depth = 0.5
    result = render_reference(_slab_scene(glass, depth), spp=256, bounces=6, seed=3)
    expected = _series(0.04, color ** depth)
    error = result.image - expected
    print("slab:", result.image.reshape(-1, 3).mean(axis=0), "expected", expected,
          "max |error| / stderr", np.max(np.abs(error) / np.maximum(result.stderr, 1e-12)))
    assert np.all(np.abs(error) <= 5.0 * result.stderr + 1e-9)
    # the nine pixels together: within 4 standard errors of their mean, which is below 0.006
    mean_stderr = np.sqrt(np.sum(result.stderr.reshape(-1, 3) ** 2, axis=0)) / 9
    assert np.all(mean_stderr < 0.006)
    assert np.all(np.abs(error.reshape(-1, 3).mean(axis=0)) <= 4.0 * mean_stderr)


def test_index_matched_slab_is_beer_lambert_alone():
    """ior 1 and specular 0 (no Fresnel reflection, no refraction): the slab's
    transmittance is T = attenuationColor^(x / attenuationDistance) exactly (the volume
    README, "Attenuation"), x = d / cos theta the ray's path through the slab, every
    sample alike."""
    color = np.array([0.8, 0.4, 0.1])
    glass = MaterialSpec(model="gltf", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, thickness=1.0,
                         ior=1.0, specular=0.0, attenuation_color=tuple(color), attenuation_distance=0.5)
    depth = 0.3
    scene = _slab_scene(glass, depth)
    result = render_reference(scene, spp=16, bounces=4, seed=4)
    # the real path length inside: depth / cos theta of each pixel's ray
    cos = np.abs(scene.camera.ray_directions().reshape(result.image.shape)[..., 2:3])
    # (to 1e-6: the rays start 1e-7 of the scene's size off each face)
    np.testing.assert_allclose(result.image, color ** (depth / cos / 0.5), rtol=1e-6)
    assert np.all(result.stderr == 0.0)


def _sphere_scene(material, size, fov, environment=(1.0, 1.0, 1.0), emitter=None):
    cam = Camera(position=(0.0, 0.0, 4.0), look_at=(0.0, 0.0, 0.0), fov=fov, width=size, height=size)
    materials = {"default": MaterialSpec(), "glass": material}
    objects = (Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="glass"),)
    if emitter is not None:
        materials["light"] = MaterialSpec(model="gltf", base_color=(0.0, 0.0, 0.0), emissive=(emitter,) * 3)
        objects += (Plane(point=(0.0, 0.0, -3.0), normal=(0.0, 0.0, 1.0), material="light"),)
    return Scene(camera=cam, environment=EnvironmentSpec(color=environment), materials=materials, objects=objects)


@pytest.mark.parametrize("thickness", [1.0, 0.0], ids=["volume", "thin"])
def test_glass_sphere_is_a_white_furnace(thickness):
    """A smooth glass sphere without absorption in a white environment: reflection F and
    transmission 1 - F at every interface, radiance's 1 / eta^2 on entering undone on
    leaving: every pixel is 1 within 5 standard errors (+ 1e-3 for the paths cut at 40
    bounces: near the silhouette the internal reflectance is F(grazing) each time) and the
    image's mean within 4 of its standard error."""
    glass = MaterialSpec(model="gltf", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0,
                         thickness=thickness)
    result = render_reference(_sphere_scene(glass, 6, 30.0), spp=1024, bounces=40, seed=5)
    on = result.mask
    error = result.image[on] - 1.0
    print("furnace:", result.image[on].mean(), "max |error| / stderr",
          np.max(np.abs(error) / np.maximum(result.stderr[on], 1e-12)))
    assert np.all(np.abs(error) <= 5.0 * result.stderr[on] + 1e-3)
    mean_error = error.mean()
    mean_stderr = np.sqrt(np.sum(result.stderr[on] ** 2)) / error.size
    assert abs(mean_error) <= 4.0 * mean_stderr + 1e-3


def test_absorbing_sphere_centre_against_its_diameter():
    """An absorbing smooth glass sphere (radius 1) in front of an emitter, black
    environment: the centre pixel (rays within 0.1 degree of the axis) sees the emitter
    through the diameter, (1 - R)^2 e^{-2 sigma r} / (1 - R^2 e^{-4 sigma r}), within 5
    standard errors (below 0.006) + 1e-3 (the rays' small offsets from the axis)."""
    color = np.array([0.7, 0.5, 0.9])
    glass = MaterialSpec(model="gltf", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, thickness=2.0,
                         attenuation_color=tuple(color), attenuation_distance=1.0)
    result = render_reference(_sphere_scene(glass, 3, 0.2, environment=(0.0, 0.0, 0.0), emitter=1.0), spp=2048,
                              bounces=6, seed=6)
    centre = result.image[1, 1]
    expected = _series(0.04, color ** 2.0)
    print("sphere centre:", centre, "expected", expected, "stderr", result.stderr[1, 1])
    assert np.all(result.stderr[1, 1] < 0.006)
    assert np.all(np.abs(centre - expected) <= 5.0 * result.stderr[1, 1] + 1e-3)


def test_fused_and_wavefront_engines_agree_with_media():
    """The wavefront loop keeps the same media and offsets as the fused kernel: the same
    numbers for a rough absorbing sphere and a thin sheet."""
    glass = MaterialSpec(model="gltf", base_color=(0.9, 0.95, 1.0), roughness=0.3, transmission=1.0, thickness=1.0,
                         attenuation_color=(0.6, 0.8, 0.9), attenuation_distance=1.5)
    scene = _sphere_scene(glass, 6, 30.0, environment=(1.0, 0.9, 0.8))
    a = render_reference(scene, spp=8, bounces=5, seed=7, engine="fused")
    b = render_reference(scene, spp=8, bounces=5, seed=7, engine="wavefront")
    np.testing.assert_allclose(a.image, b.image, rtol=1e-9, atol=1e-12)


# ------------------------------------------------------------------ glTF files


def test_transmission_and_volume_are_read_from_gltf_files(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    ext = {"KHR_materials_transmission": {"transmissionFactor": 0.8},
           "KHR_materials_volume": {"thicknessFactor": 0.25, "attenuationDistance": 0.5,
                                    "attenuationColor": [0.9, 0.5, 0.25]}}
    asset = load_gltf(write_quad_glb(tmp_path / "t.glb", material_extras=ext, extensions_required=tuple(ext)))
    spec = asset.materials[0].spec
    assert (spec.transmission, spec.thickness, spec.attenuation_distance, spec.attenuation_color) == \
        (0.8, 0.25, 0.5, (0.9, 0.5, 0.25))
    assert not asset.notes
    # the READMEs' defaults; attenuationDistance's +Infinity is the parameter's 0
    asset = load_gltf(write_quad_glb(tmp_path / "d.glb", material_extras={k: {} for k in ext}))
    spec = asset.materials[0].spec
    assert (spec.transmission, spec.thickness, spec.attenuation_distance, spec.attenuation_color) == \
        (0.0, 0.0, 0.0, (1.0, 1.0, 1.0))


@pytest.mark.parametrize("ext, fragment", [
    ({"KHR_materials_transmission": {"transmissionFactor": 1.5}}, "KHR_materials_transmission.transmissionFactor"),
    ({"KHR_materials_transmission": {"transmissionTexture": {"index": 7}}},
     "KHR_materials_transmission.transmissionTexture"),
    ({"KHR_materials_volume": {"thicknessFactor": -1}}, "KHR_materials_volume.thicknessFactor"),
    ({"KHR_materials_volume": {"attenuationDistance": 0}}, "KHR_materials_volume.attenuationDistance"),
    ({"KHR_materials_volume": {"attenuationColor": [1, 2, 1]}}, "KHR_materials_volume.attenuationColor"),
    ({"KHR_materials_volume": "x"}, "KHR_materials_volume"),
])
def test_bad_transmission_fields_are_refused_naming_the_field(tmp_path, ext, fragment):
    from gltf_scenes import write_quad_glb

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.gltf import load_gltf

    with pytest.raises(InputError, match=fragment.replace(".", r"\.")) as info:
        load_gltf(write_quad_glb(tmp_path / "b.glb", material_extras=ext))
    assert "\n" not in str(info.value)


def test_a_plain_material_keeps_the_core_model_and_a_volume_its_outward_normals():
    """transmission 0 compiles as the core glTF model (its speed unchanged); a volume
    boundary is never double-sided (the volume README: doubleSided has no effect)."""
    from pbrkit.brdf.shading.registry import EXTENDED_CODES, MODELS

    codes, params = _tables(base_color=(0.5, 0.5, 0.5), transmission=0.0, attenuation_distance=0.0)
    assert codes[0, 0] == MODELS.index("gltf")
    codes, params = _tables(transmission=1.0)
    assert codes[0, 0] == EXTENDED_CODES["gltf"]
    from pbrkit.brdf.shading.registry import COLUMNS
    assert params[0, COLUMNS.double_sided] == 1.0
    codes, params = _tables(transmission=1.0, thickness=1.0)
    assert params[0, COLUMNS.double_sided] == 0.0


# ---------------------------------------------------------------- real time


def test_refract_is_snells_law():
    """GLSL's refract as the real-time lookups use it: the refracted direction is a unit
    vector in the plane of incidence with sin t = eta sin i, on the far side; total
    internal reflection gives 0."""
    from pbrkit.rendering.transmission_ibl import ior_roughness, refract

    rng = np.random.default_rng(7)
    i = rng.normal(size=(200, 3))
    i /= np.linalg.norm(i, axis=1, keepdims=True)
    n = np.tile([0.0, 0.0, 1.0], (200, 1))
    i[:, 2] = -np.abs(i[:, 2])  # arriving from above
    for eta in (1.0 / 1.5, 1.5):
        t = refract(i, n, np.full(200, eta))
        sin_i = np.linalg.norm(np.cross(i, n), axis=1)
        tir = eta * sin_i > 1.0
        assert np.all(t[tir] == 0.0)
        ok = ~tir
        np.testing.assert_allclose(np.linalg.norm(t[ok], axis=1), 1.0, rtol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(np.cross(t[ok], n[ok]), axis=1), eta * sin_i[ok], atol=1e-12)
        assert np.all(t[ok, 2] < 0.0)
        np.testing.assert_allclose(np.einsum("ij,ij->i", np.cross(i[ok], n[ok]), t[ok]), 0.0, atol=1e-12)
    np.testing.assert_allclose(ior_roughness(0.6, np.array([1.0, 1.25, 1.5, 2.0])), [0.0, 0.3, 0.6, 0.6])


def test_sample_viewer_background_is_its_cube_seen_from_behind_the_centre():
    """The Sample Viewer's background (``cubemap.vert``: the view's translation replaced by
    (0, 0, 0, 0.1), so clip w = -z_view + 0.1): along the viewing direction the same
    direction; on the cube's front face the ray from 0.1 behind the centre, tan 1.1 times
    the camera ray's; unit directions, and a turned camera turns nothing but e."""
    from pbrkit.rendering.transmission_ibl import sample_viewer_background_direction

    forward = np.array([0.0, 0.0, -1.0])
    np.testing.assert_allclose(sample_viewer_background_direction(forward, forward), forward, atol=1e-15)
    angle = np.radians([1.0, 5.0, 14.0, 30.0])
    d = np.stack([np.sin(angle), np.zeros(4), -np.cos(angle)], axis=-1)
    a = sample_viewer_background_direction(d, forward)
    np.testing.assert_allclose(np.linalg.norm(a, axis=-1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(a[:, 0] / -a[:, 2], 1.1 * np.tan(angle), rtol=1e-12)
    # looking along +X: the cube's +X face, e = (-0.1, 0, 0)
    a = sample_viewer_background_direction(np.array([np.cos(0.2), np.sin(0.2), 0.0]), np.array([2.0, 0.0, 0.0]))
    np.testing.assert_allclose(a[1] / a[0], 1.1 * np.tan(0.2), rtol=1e-12)


def test_realtime_transmission_under_a_constant_environment():
    """Real time, a constant white environment (every lookup 1): the light a thin wall
    lets through, weighted as the diffuse it replaces (baseColor x the diffuse's Fresnel
    weight), equals that diffuse's E / pi = 1, so transmission 1 renders as transmission
    0; a volume scales that part by attenuationColor^(thickness / attenuationDistance).
    Under engine khronos the transmitted part is (1 - (F0 A + B)) baseColor x the light
    (getIBLVolumeRefraction), F0 A + B the split-sum albedo of the viewer's lut_ggx."""
    from render_scenes import pixel_geometry, sphere_scene

    from pbrkit.rendering.realtime import render_realtime

    env = EnvironmentSpec(color=(1.0, 1.0, 1.0))

    def render(engine="pbrkit", base=(0.8, 0.5, 0.3), **kw):
        scene = sphere_scene(MaterialSpec(name="m", roughness=0.3, base_color=base, **kw), env, size=16)
        return render_realtime(scene, bake_size=16, engine=engine).image

    mask, _, _ = pixel_geometry(sphere_scene(MaterialSpec(name="m"), env, size=16))
    plain, black = render(), render(base=(0.0, 0.0, 0.0))
    np.testing.assert_allclose(render(transmission=1.0), plain, rtol=1e-12, atol=1e-15)
    volume = render(transmission=1.0, thickness=0.5, attenuation_color=(0.5, 0.8, 1.0), attenuation_distance=1.0)
    np.testing.assert_allclose((volume - black)[mask], (plain - black)[mask] * np.sqrt([0.5, 0.8, 1.0]), rtol=1e-9)
    half = render(transmission=0.5, thickness=0.5, attenuation_color=(0.5, 0.8, 1.0), attenuation_distance=1.0)
    np.testing.assert_allclose((half - black)[mask], (plain - black)[mask] * (0.5 + 0.5 * np.sqrt([0.5, 0.8, 1.0])),
                               rtol=1e-9)
    k_plain, k_black = render("khronos"), render("khronos", base=(0.0, 0.0, 0.0))
    k_glass = render("khronos", transmission=1.0)
    # F0 A + B of the viewer's lut_ggx (the bake's height-correlated table): pbrkit's split sum of
    # filament's black dielectric (f0 0.16 reflectance^2 = 0.04, f90 1, that table)
    split_sum = render(base=(0.0, 0.0, 0.0), model="filament")
    expected = k_black + (1.0 - split_sum) * (k_plain - k_black)
    np.testing.assert_allclose(k_glass[mask], expected[mask], rtol=1e-6)  # the lookups: 1 to 3e-8


@pytest.mark.parametrize("mode", ["reference", "realtime"])
def test_a_light_behind_a_thin_wall_shines_through_it(mode):
    """A directional light below a thin transmissive plane (z = 0, normal +z), the camera
    above, a black environment: each pixel is the light's E times f(v, l) |n.l| of the
    READMEs' BSDF on the far side (reference_brdf.gltf_transmission_bsdf), in both modes
    (the same punctual evaluation; the ground truth's shadow ray leaves from the light's
    side); an opaque plane stays black."""
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.lights import Light

    values = dict(base_color=(0.9, 0.6, 0.3), roughness=0.5, transmission=1.0)
    to_light = np.array([0.3, -0.2, -1.0])
    to_light /= np.linalg.norm(to_light)

    def scene(**keys):
        cam = Camera(position=(0.0, 0.4, 3.0), look_at=(0.0, 0.0, 0.0), fov=20.0, width=6, height=6)
        light = Light(type="directional", color=(1.0, 0.9, 0.8), intensity=2.0, direction=tuple(-to_light))
        return Scene(camera=cam, environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)),
                     materials={"default": MaterialSpec(), "w": MaterialSpec(name="w", **keys)},
                     objects=(Plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="w"),),
                     lights=(light,))

    def render(s):
        return render_reference(s, spp=2, seed=1) if mode == "reference" else render_realtime(s, bake_size=8)

    got = render(scene(**values))
    s = scene(**values)
    d = s.camera.ray_directions()[:, :, 0]
    v = -d / np.linalg.norm(d, axis=-1, keepdims=True)
    l = np.broadcast_to(to_light, v.shape)
    f = ref.gltf_transmission_bsdf(l.reshape(-1, 3), v.reshape(-1, 3), np.array(values["base_color"]), 0.0,
                                   values["roughness"], values["transmission"])
    expected = (f * np.abs(to_light[2]) * 2.0 * np.array([1.0, 0.9, 0.8])).reshape(v.shape)
    assert got.mask.all() and expected.min() > 1e-3
    np.testing.assert_allclose(got.image, expected, rtol=1e-9, atol=1e-12)
    assert np.all(render(scene(**dict(values, transmission=0.0))).image == 0.0)
