"""The pieces of the fast ground-truth kernel: the alias table (chi-square), the
polynomial elementary functions of the equirect mapping (against the C library),
the counter-based generator's layout, and the lane kernel's specialised BxDFs
against the generic per-sample path (the wavefront engine)."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from scipy import stats

from pbrkit.brdf.bxdf import CODE_COLUMNS
from pbrkit.rendering.environment import (
    _alias_sample,
    _alias_table,
    _atan2,
    _env_uv,
    _sincos,
)
from pbrkit.rendering.materials import material_tables
from pbrkit.rendering.lanes import _VARIANTS, material_variants
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    MaterialSpec,
    Plane,
    Scene,
    Sphere,
)
from pbrkit.sampling.random import (
    DIMENSIONS,
    _path_key,
    _sample_key,
    _stream_key,
    _uniform,
)


@numba.njit
def _draws(table, u):
    index = np.empty(u.shape[0], dtype=np.int64)
    rest = np.empty(u.shape[0])
    for k in range(u.shape[0]):
        index[k], rest[k] = _alias_sample(table, u[k])
    return index, rest


def _table(weight):
    weight = np.asarray(weight, dtype=float)
    threshold = np.zeros(weight.size)
    alias = np.zeros(weight.size, dtype=np.int64)
    _alias_table(weight / weight.sum(), threshold, alias)
    return np.ascontiguousarray(np.stack([threshold, alias], axis=1))


@pytest.mark.parametrize("case", ["gamma", "one-hot-ish", "zeros", "uniform"])
def test_alias_table_draws_in_proportion_to_the_weights(case):
    """Walker / Vose: index k is drawn with probability w_k / sum w (chi-square), weightless
    indices never, and the uniform left over is uniform and independent of the index."""
    rng = np.random.default_rng(3)
    n = 97
    weight = {"gamma": rng.gamma(0.4, 1.0, n), "uniform": np.ones(n),
              "one-hot-ish": np.r_[1000.0, np.full(n - 1, 0.01)],
              "zeros": np.where(rng.random(n) < 0.5, 0.0, rng.random(n))}[case]
    table = _table(weight)
    # the table's own probabilities: (threshold_k + sum of (1 - threshold_j) over j aliasing to k) / n
    exact = table[:, 0].copy()
    np.add.at(exact, table[:, 1].astype(np.int64), 1.0 - table[:, 0])
    np.testing.assert_allclose(exact / n, weight / weight.sum(), atol=1e-12)
    count = 200_000
    index, rest = _draws(table, rng.random(count))
    observed = np.bincount(index, minlength=n)
    expected = count * weight / weight.sum()
    assert observed[expected == 0].sum() == 0
    keep = expected >= 5
    other = count - observed[keep].sum()  # pooled small bins
    obs = np.r_[observed[keep], other]
    exp = np.r_[expected[keep], count - expected[keep].sum()]
    pool = exp > 0
    chi2 = np.sum((obs[pool] - exp[pool]) ** 2 / exp[pool])
    assert stats.chi2.sf(chi2, pool.sum() - 1) > 1e-3
    assert rest.min() >= 0.0 and rest.max() < 1.0
    assert stats.kstest(rest, "uniform").pvalue > 1e-3
    big = np.argmax(observed)
    assert stats.kstest(rest[index == big], "uniform").pvalue > 1e-3


def test_sincos_and_atan2_match_the_c_library():
    """The branch-free polynomial sin, cos and atan2 (Cephes coefficients) agree with libm
    to a few ulp, over the angles the equirect mapping meets and beyond."""
    rng = np.random.default_rng(8)
    x = np.r_[rng.uniform(-20.0, 20.0, 20000), np.linspace(-4 * np.pi, 4 * np.pi, 4001), 0.0, -0.0]
    for v in x:
        s, c = _sincos(v)
        assert abs(s - math.sin(v)) <= 4e-16 * max(1.0, abs(v) / 8)
        assert abs(c - math.cos(v)) <= 4e-16 * max(1.0, abs(v) / 8)
    pts = np.r_[rng.normal(size=(20000, 2)), [[0.0, 1.0], [0.0, -1.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 0.0],
                                               [1e-300, -1.0], [-0.0, -1.0], [1.0, 1.0], [-1.0, -1.0]]]
    for y, xx in pts:
        a = _atan2(y, xx)
        assert abs(a - math.atan2(y, xx)) <= 4 * math.ulp(max(abs(math.atan2(y, xx)), 1e-300)) + 1e-300, (y, xx)
    # the equirect coordinates of directions, as pbrkit.ibl.equirect.equirect_uv gives them
    from pbrkit.ibl.equirect import equirect_uv

    d = rng.normal(size=(5000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    u0, v0 = equirect_uv(d[:, 0], d[:, 1], d[:, 2])
    for k in range(d.shape[0]):
        u, v, st = _env_uv(d[k, 0], d[k, 1], d[k, 2])
        assert abs(u - u0[k]) < 1e-15 and abs(v - v0[k]) < 1e-15
        assert st == pytest.approx(math.hypot(d[k, 0], d[k, 2]), rel=1e-12)


def test_generator_windows_depend_on_the_sample_alone():
    """Sample j of a pixel's stream is j DIMENSIONS-wide windows into SplitMix64: the
    key of (seed, pixel, sample, bounce) is the same however it is reached, and the
    dimensions of consecutive samples do not overlap."""
    stream = _stream_key(7, 123, 0)
    for j in range(5):
        assert _path_key(7, 123, j, 0) == _sample_key(stream, j)
    a = [_uniform(_sample_key(stream, 0), d) for d in range(DIMENSIONS)]
    b = [_uniform(_sample_key(stream, 1), d) for d in range(DIMENSIONS)]
    assert len(set(a + b)) == 2 * DIMENSIONS
    # window j + 1 starts where window j ends: dimension d of sample 1 = dimension d + 8 of sample 0
    assert _uniform(_sample_key(stream, 1), 0) == _uniform(_sample_key(stream, 0), DIMENSIONS)
    u = np.array([_uniform(np.uint64(_path_key(1, p, 0, 0)), 0) for p in range(20000)])
    assert stats.kstest(u, "uniform").pvalue > 1e-3


_MATERIALS = [
    MaterialSpec(name="m", base_color=(0.8, 0.5, 0.3), metallic=0.3, roughness=0.4),  # glTF
    MaterialSpec(name="m", model="filament", base_color=(0.6, 0.7, 0.3), metallic=0.6, roughness=0.3),
    MaterialSpec(name="m", model="cook_torrance", base_color=(0.5, 0.5, 0.7), metallic=0.2, roughness=0.5),
    MaterialSpec(name="m", model="cook_torrance", metallic=1.0, roughness=0.5, masking="separable",
                 fresnel="none", diffuse="none", specular_color=(0.95, 0.64, 0.3)),
    MaterialSpec(name="m", model="cook_torrance", metallic=1.0, roughness=0.3, fresnel="none", diffuse="none"),
    MaterialSpec(name="m", model="cook_torrance", metallic=0.5, roughness=0.6, masking="separable",
                 fresnel="none"),
    # not specialised: generic lane loops
    MaterialSpec(name="m", model="cook_torrance", distribution="beckmann", metallic=0.5, roughness=0.4),
    MaterialSpec(name="m", model="disney", base_color=(0.7, 0.4, 0.3), roughness=0.45, clearcoat=0.6,
                 sheen=0.3),
    MaterialSpec(name="m", model="cook_torrance", metallic=0.3, roughness=0.4, anisotropy=0.5),
]


def _scene(material, env):
    camera = Camera(position=(0.0, 0.6, 4.0), look_at=(0.0, 0.0, 0.0), fov=35.0, width=12, height=12,
                    supersample=2)
    return Scene(camera=camera, environment=env, materials={"default": MaterialSpec(), "m": material},
                 objects=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="m"),
                          Sphere(center=(1.1, 0.5, -1.0), radius=0.4, material="default"),
                          Plane(point=(0.0, -1.0, 0.0), normal=(0.0, 1.0, 0.0), material="default")),
                 lights=())


def test_every_variant_of_the_specialisation_table_is_exercised():
    """Each row of _VARIANTS is the code row of one of the materials tested below."""
    from pbrkit.rendering.geometry import Geometry

    seen = set()
    for material in _MATERIALS:
        geometry = Geometry(_scene(material, EnvironmentSpec()))
        codes, params = material_tables(geometry.materials)
        seen.update(int(v) for v in material_variants(codes, params) if v >= 0)
        assert codes.shape[1] >= CODE_COLUMNS
    assert seen == set(range(len(_VARIANTS)))


@pytest.mark.parametrize("material", _MATERIALS, ids=lambda m: f"{m.model}-{m.distribution}-{m.fresnel}"
                         f"-{m.diffuse}-{m.masking}-a{m.anisotropy}")
def test_lane_kernel_gives_the_per_sample_paths_numbers(material):
    """Direct lighting (bounces 0) of an analytic scene runs in SIMD lanes with BxDFs
    specialised by material; the wavefront engine evaluates the generic BxDF sample by
    sample with the same random numbers: the same image and standard errors, with
    occlusion, for MIS and for BRDF sampling alone, under a map and a constant sky."""
    from pbrkit.rendering.scene import bundled_environment

    for env in (EnvironmentSpec(file=str(bundled_environment()), rotation=30.0), EnvironmentSpec(color=(1, 1, 1))):
        scene = _scene(material, env)
        for strategy in ("mis", "brdf"):
            a = render_reference(scene, spp=10, seed=4, strategy=strategy, engine="fused")
            b = render_reference(scene, spp=10, seed=4, strategy=strategy, engine="wavefront")
            assert "lanes" in a.stats["engine"]
            np.testing.assert_allclose(a.image, b.image, rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(a.stderr, b.stderr, rtol=1e-6, atol=1e-11)


def test_thread_count_does_not_change_the_bytes():
    """The kernels run ranges of pixels on a pool of threads (pbrkit.core.jit.run_in_threads);
    each pixel owns its outputs and its random numbers, so one thread and all of them
    give the same bytes, for the lane kernel and the scalar one (bounces)."""
    scene = _scene(_MATERIALS[0], EnvironmentSpec(color=(0.9, 0.8, 1.0)))
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two Numba threads")
    before = numba.get_num_threads()
    try:
        out = {}
        for threads in (1, 2):
            numba.set_num_threads(threads)
            out[threads] = [render_reference(scene, spp=6, seed=2, bounces=b) for b in (0, 1)]
    finally:
        numba.set_num_threads(before)
    for a, b in zip(out[1], out[2]):
        assert a.image.tobytes() == b.image.tobytes() and a.stderr.tobytes() == b.stderr.tobytes()


def test_run_in_threads_covers_every_item_once():
    from pbrkit.core.jit import run_in_threads, threaded_kernel

    @threaded_kernel
    def mark(start, stop, out):
        for i in range(start, stop):
            out[i] += i + 1

    for count in (0, 1, 7, 1000):
        out = np.zeros(count, dtype=np.int64)
        run_in_threads(mark, count, out)
        assert out.tolist() == list(range(1, count + 1))


@pytest.mark.parametrize("occlusion", [True, False])
def test_lane_kernel_with_area_lights_gives_the_per_sample_paths_numbers(occlusion):
    """Area lights in the lane kernel (light sampling, shadow rays that other lights and
    objects block, emission met by BxDF samples with MIS, paths that end on a light):
    the same numbers as the wavefront engine's per-sample path, for a rect, a disk, a
    sphere and a polygon light, an emissive plane, MIS and BRDF sampling alone."""
    from pbrkit.rendering.scene import AreaLight

    lights = (AreaLight(type="rect", position=(0.3, 2.0, 0.5), normal=(0.1, -1.0, 0.1), width=1.5, height=0.7,
                        intensity=3.0),
              AreaLight(type="disk", position=(-1.2, 1.4, 0.8), normal=(0.5, -1.0, 0.0), radius=0.4, intensity=4.0,
                        color=(1.0, 0.7, 0.4)),
              AreaLight(type="sphere", position=(1.4, 1.2, 1.0), radius=0.3, intensity=6.0),
              AreaLight(type="polygon", vertices=((0.8, 0.3, 1.6), (1.6, 0.3, 1.2), (1.2, 1.2, 1.8)), intensity=2.0))
    glow = MaterialSpec(name="glow", emissive=(0.3, 0.2, 0.1), roughness=0.8)
    for material in (_MATERIALS[0], _MATERIALS[3], _MATERIALS[6]):
        base = _scene(material, EnvironmentSpec(color=(0.3, 0.35, 0.4)))
        scene = Scene(camera=base.camera, environment=base.environment,
                      materials={**base.materials, "glow": glow},
                      objects=base.objects + (Plane(point=(0.0, 0.0, -2.5), normal=(0.0, 0.0, 1.0), material="glow"),),
                      lights=(), area_lights=lights)
        for strategy in ("mis", "brdf"):
            a = render_reference(scene, spp=12, seed=3, strategy=strategy, occlusion=occlusion, engine="fused")
            b = render_reference(scene, spp=12, seed=3, strategy=strategy, occlusion=occlusion, engine="wavefront")
            assert "lanes" in a.stats["engine"]
            np.testing.assert_allclose(a.image, b.image, rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(a.stderr, b.stderr, rtol=1e-6, atol=1e-11)


@pytest.mark.slow
def test_kernels_for_core_materials_carry_only_the_core_models_and_give_the_full_kernels_numbers(monkeypatch):
    """A scene whose materials use no extension runs kernels compiled with the dispatch
    over the registered models' cores (pbrkit.brdf.dispatch.restricted): their
    dispatch has no branch for an extended form, and the lane, fused and wavefront
    engines give the same bytes as the kernels over every compiled model.  A material
    with an extension gets the kernels over every model."""
    from pbrkit.brdf import dispatch
    from pbrkit.brdf.shading.registry import COMPILED, REGISTERED
    from pbrkit.rendering import lanes, materials, punctual, reference
    from pbrkit.rendering.geometry import Geometry

    core = COMPILED[:len(REGISTERED)]
    source = dispatch.family(core)["bxdf_f"].__source__
    assert source.count("return value") == len(core) and f"value{len(core)}" not in source
    assert dispatch.family(COMPILED)["bxdf_f"] is dispatch.bxdf_f
    scene = _scene(_MATERIALS[0], EnvironmentSpec(color=(0.9, 0.8, 1.0)))
    codes, _ = material_tables(Geometry(scene).materials)
    assert materials.for_materials(lanes._direct_kernel, codes) is not lanes._direct_kernel
    sheen = MaterialSpec(name="m", model="gltf", roughness=0.5, sheen_color=(0.5, 0.4, 0.3))
    codes, _ = material_tables(Geometry(_scene(sheen, EnvironmentSpec())).materials)
    assert materials.for_materials(lanes._direct_kernel, codes) is lanes._direct_kernel
    runs = [dict(engine="fused"), dict(engine="fused", bounces=1), dict(engine="wavefront")]
    restricted = [render_reference(scene, spp=6, seed=2, **kw).image for kw in runs]
    for module in (lanes, reference, punctual):
        monkeypatch.setattr(module, "for_materials", lambda fn, codes: fn)
    for kw, image in zip(runs, restricted):
        np.testing.assert_array_equal(render_reference(scene, spp=6, seed=2, **kw).image, image)
