"""KHR_materials_dispersion: the channels' IORs against an independent transcription of
the README's Cauchy fit (A and B from the Abbe number's definition, not its rounded
constants), the Sample Viewer's half spread, the ground truth's pass per channel
(each channel of a dispersive glass sphere is, to the bit, the channel of the same
sphere without dispersion at that channel's IOR), real time's lookup per channel, and
the glTF files' factor and refusals."""

from __future__ import annotations

import numpy as np
import pytest

from pbrkit.brdf.transmission import FRAUNHOFER_NM, dispersion_iors, sample_viewer_dispersion_iors

LAMBDA_F, LAMBDA_D, LAMBDA_C = 486.1, 587.6, 656.3


def _cauchy(n_d, dispersion, lam):
    """The README's n(lambda) = A + B / lambda^2 with B = (n_d - 1) / (V_d (lambda_F^-2 -
    lambda_C^-2)), A = n_d - B / lambda_d^2, V_d = 20 / dispersion, at least 1."""
    v_d = 20.0 / dispersion
    b = (n_d - 1.0) / (v_d * (LAMBDA_F ** -2 - LAMBDA_C ** -2))
    a = n_d - b / LAMBDA_D ** 2
    return max(a + b / lam ** 2, 1.0)


@pytest.mark.parametrize("ior, dispersion", [(1.5, 0.33), (2.42, 0.36), (1.33, 1.0), (1.8, 2.04), (1.05, 3.0)])
def test_channel_iors_follow_cauchy_through_the_abbe_number(ior, dispersion):
    got = dispersion_iors(ior, dispersion)
    assert FRAUNHOFER_NM == (LAMBDA_C, LAMBDA_D, LAMBDA_F)
    spread = (ior - 1.0) * dispersion / 20.0  # n_F - n_C = (n_d - 1) / V_d
    for c, lam in enumerate(FRAUNHOFER_NM):
        # the README's rounded constants (523655, 1.5168) against the exact fit: within 0.1 % of the spread
        assert abs(got[c] - _cauchy(ior, dispersion, lam)) <= 1e-3 * spread + 1e-12, (c, got[c])
    assert got[0] < got[1] < got[2] or got[0] == 1.0  # red bends least
    if got[0] > 1.0:
        assert (got[1] - 1.0) / (got[2] - got[0]) == pytest.approx(20.0 / dispersion, rel=2e-3)
    np.testing.assert_array_equal(dispersion_iors(ior, 0.0), [ior] * 3)
    sv = sample_viewer_dispersion_iors(ior, dispersion)
    np.testing.assert_allclose(sv, [ior - 0.5 * spread, ior, ior + 0.5 * spread], rtol=1e-15)


def _glass(dispersion=0.0, ior=1.5):
    from pbrkit.rendering.scene import Camera, EnvironmentSpec, MaterialSpec, Scene, Sphere, bundled_environment

    keys = dict(base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=0.05, transmission=1.0, thickness=1.0, ior=ior)
    if dispersion:
        keys["dispersion"] = dispersion
    materials = {"default": MaterialSpec(), "glass": MaterialSpec(name="glass", **keys)}
    camera = Camera(position=(0.0, 0.0, 4.0), look_at=(0.0, 0.0, 0.0), fov=30.0, width=12, height=12)
    return Scene(camera=camera, environment=EnvironmentSpec(file=str(bundled_environment())), materials=materials,
                 objects=(Sphere(center=(0.0, 0.0, 0.0), radius=0.8, material="glass"),))


def test_the_ground_truth_traces_each_channel_at_its_own_ior():
    from pbrkit.rendering.reference import render_reference

    dispersion = 1.5
    iors = dispersion_iors(1.5, dispersion)
    got = render_reference(_glass(dispersion), spp=4, bounces=3, seed=7)
    assert "a pass per colour channel" in got.stats["engine"]
    for c in range(3):
        alone = render_reference(_glass(ior=float(iors[c])), spp=4, bounces=3, seed=7)
        np.testing.assert_array_equal(got.image[..., c], alone.image[..., c])
        np.testing.assert_array_equal(got.stderr[..., c], alone.stderr[..., c])
    plain = render_reference(_glass(), spp=4, bounces=3, seed=7)
    assert "per colour channel" not in plain.stats["engine"]
    assert np.abs(got.image - plain.image)[got.mask].max() > 1e-3  # the channels part


@pytest.mark.parametrize("engine", ["pbrkit", "khronos"])
def test_real_time_looks_each_channel_up_along_its_own_refraction(engine):
    from pbrkit.rendering.geometry import Surface
    from pbrkit.rendering.materials import material_tables
    from pbrkit.rendering.scene import MaterialSpec
    from pbrkit.rendering.textures import SurfaceMaterial
    from pbrkit.rendering.transmission_ibl import transmission_lookups

    rng = np.random.default_rng(11)
    count = 64
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = n + 0.6 * rng.normal(size=(count, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    surface = Surface(rng.normal(size=(count, 3)), n, n, np.zeros(count, dtype=np.int64), np.ones((count, 3)),
                      np.zeros(count), np.full(count, 0.3), np.ones(count), np.zeros((count, 3)))

    def sampler(directions, lod):  # a lookup that shows the direction and the level in every channel
        return directions * 0.5 + 0.5 + lod[:, None]

    def lookups(**keys):
        spec = MaterialSpec(name="g", base_color=(1.0, 1.0, 1.0), transmission=1.0, thickness=0.7, **keys)
        codes, params = material_tables([SurfaceMaterial(spec)])
        return transmission_lookups(codes, params, surface, v, (0.0, 0.0, 5.0), sampler, lambda d: d, 6, engine)

    got = lookups(ior=1.6, dispersion=1.0)
    iors = (sample_viewer_dispersion_iors if engine == "khronos" else dispersion_iors)(1.6, 1.0)
    for c in range(3):
        np.testing.assert_allclose(got[:, c], lookups(ior=float(iors[c]))[:, c], rtol=1e-13, atol=1e-13)
    # the channels part (least through the viewer's camera ray to the exit point, 0.3 mm away here)
    assert np.abs(got - lookups(ior=1.6)).max() > (1e-4 if engine == "khronos" else 1e-3)


def test_the_factor_is_read_from_gltf_files(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.gltf import load_gltf

    ext = {"KHR_materials_dispersion": {"dispersion": 0.36}, "KHR_materials_volume": {"thicknessFactor": 1.0},
           "KHR_materials_transmission": {"transmissionFactor": 1.0}}
    spec = load_gltf(write_quad_glb(tmp_path / "d.glb", material_extras=ext, extensions_required=tuple(ext))
                     ).materials[0].spec
    assert (spec.dispersion, spec.thickness, spec.transmission) == (0.36, 1.0, 1.0)
    for bad in ({"dispersion": -0.1}, {"dispersion": "1"}):
        with pytest.raises(InputError, match=r"KHR_materials_dispersion\.dispersion") as info:
            load_gltf(write_quad_glb(tmp_path / "b.glb", material_extras={"KHR_materials_dispersion": bad}))
        assert "\n" not in str(info.value)
