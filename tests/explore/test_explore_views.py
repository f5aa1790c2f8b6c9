"""pbrkit.explore.views: every view's numbers equal pbrkit's models (called by name,
at the directions the view reports), its geometry is what it says (angles
recomputed here from the directions), the albedo view agrees with analytic albedos
and pbrkit's converged tables, the terms recompose into the model, and a MERL file
written from a model shows in every view."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pbrkit.brdf import distributions, fresnel, masking, models
from pbrkit.explore import views as V

Z = np.array([0.0, 0.0, 1.0])
Y709 = np.array([0.2126, 0.7152, 0.0722])

# (views.model_brdf arguments, the model function of pbrkit.brdf.models and its keyword arguments)
CASES = [
    (dict(model="gltf", base_color=(0.9, 0.5, 0.2), metallic=0.3, roughness=0.35), models.gltf, {}),
    (dict(model="ue4", base_color=(0.2, 0.6, 0.9), metallic=0.0, roughness=0.5, reflectance=0.7), models.ue4, {}),
    (dict(model="filament", base_color=(0.7, 0.7, 0.2), metallic=1.0, roughness=0.2, diffuse="burley"),
     models.filament, {"diffuse": "burley"}),
    (dict(model="urp_mobile", base_color=(0.5, 0.5, 0.5), metallic=0.5, roughness=0.6), models.urp_mobile, {}),
    (dict(model="disney", base_color=(0.8, 0.3, 0.3), metallic=0.1, roughness=0.45, sheen=0.5, clearcoat=0.3,
          subsurface=0.4, specular_tint=0.2, anisotropy=0.5), models.disney, {}),
    (dict(model="cook_torrance", base_color=(0.3, 0.8, 0.3), roughness=0.3, distribution="beckmann",
          masking="separable", fresnel="exact-dielectric", diffuse="lambert"), models.cook_torrance,
     dict(distribution="beckmann", masking="separable", fresnel="exact-dielectric", diffuse="lambert")),
]


def material_of(brdf):
    return brdf.spec.material()


def model_f(case, l, v, n=Z):
    """The model by name at (l, v) about n = +z, with the local tangent +x (the views' frame) where it takes one."""
    args, fn, terms = case
    brdf = V.model_brdf(**args)
    kw = {"t": np.array([1.0, 0.0, 0.0])} if args["model"] in ("filament", "cook_torrance", "disney") else {}
    return fn(l, v, n, material_of(brdf), **terms, **kw)


def angle_between(a, b):
    return np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0))


def half_diff(l, v):
    """(theta_h, theta_d) of direction pairs, computed here: h = (l + v) / |l + v|."""
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    return np.arccos(np.clip(h[..., 2], -1, 1)), angle_between(l, h)


@pytest.fixture(scope="module", params=range(len(CASES)), ids=[c[0]["model"] for c in CASES])
def case(request):
    return CASES[request.param]


# ------------------------------------------------------------------ plots


def test_incidence_plane_is_the_model(case):
    brdf = V.model_brdf(**case[0])
    theta_v = math.radians(35.0)
    p = V.incidence_plane(brdf, theta_v, count=61)
    l, v = p["l"], p["v"]
    np.testing.assert_allclose(v, [math.sin(theta_v), 0.0, math.cos(theta_v)], atol=1e-15)
    np.testing.assert_allclose(np.arctan2(l[:, 0], l[:, 2]), p["theta_l"], atol=1e-12)  # in the xz plane, signed
    assert np.all(l[:, 1] == 0.0) and np.all(np.abs(p["theta_l"]) < math.pi / 2)
    f = model_f(case, l, np.broadcast_to(v, l.shape))
    np.testing.assert_allclose(p["f"], f, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(p["f_cos"], f * l[:, 2:3], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(p["value"], p["f_cos"] @ Y709, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.hypot(p["x"], p["y"]), p["value"], rtol=1e-12, atol=1e-15)


def test_incidence_plane_peaks_at_the_mirror_direction():
    brdf = V.model_brdf("gltf", (1.0, 1.0, 1.0), 1.0, 0.1)
    p = V.incidence_plane(brdf, math.radians(30.0), count=721)
    assert abs(math.degrees(p["theta_l"][np.argmax(p["value"])]) + 30.0) < 0.5


def test_lobe_3d_is_the_model(case):
    brdf = V.model_brdf(**case[0])
    lobe = V.lobe_3d(brdf, math.radians(50.0), math.radians(30.0), n_theta=6, n_phi=12)
    l = lobe["l"]
    np.testing.assert_allclose(np.linalg.norm(l, axis=-1), 1.0, atol=1e-14)
    assert np.all(l[..., 2] >= 0.0)
    np.testing.assert_allclose(angle_between(l, Z)[:, 0], lobe["theta"], atol=1e-7)
    v = lobe["v"]
    np.testing.assert_allclose(v, [math.sin(math.radians(50)) * math.cos(math.radians(30)),
                                   math.sin(math.radians(50)) * math.sin(math.radians(30)),
                                   math.cos(math.radians(50))], atol=1e-15)
    f = model_f(case, l, np.broadcast_to(v, l.shape))
    np.testing.assert_allclose(lobe["f"], f, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(lobe["radius"], (f * l[..., 2:3]) @ Y709, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(lobe["points"], axis=-1), lobe["radius"], rtol=1e-12, atol=1e-15)


def test_half_difference_views_are_the_model(case):
    brdf = V.model_brdf(**case[0])
    pd = math.radians(70.0)
    s = V.theta_h_slice(brdf, math.radians(25.0), pd, count=30)
    th, td = half_diff(s["l"], s["v"])
    np.testing.assert_allclose(th, s["theta_h"], atol=1e-7)
    np.testing.assert_allclose(td, math.radians(25.0), atol=1e-7)
    f = model_f(case, s["l"], s["v"])
    np.testing.assert_allclose(s["f"], f, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(s["value"], f @ Y709, rtol=1e-12, atol=1e-15)
    s = V.theta_d_slice(brdf, math.radians(10.0), pd, count=30)
    th, td = half_diff(s["l"], s["v"])
    np.testing.assert_allclose(th, math.radians(10.0), atol=1e-7)
    np.testing.assert_allclose(td, s["theta_d"], atol=1e-7)
    np.testing.assert_allclose(s["f"], model_f(case, s["l"], s["v"]), rtol=1e-12, atol=1e-15)
    img = V.half_diff_image(brdf, pd, size=16)
    th, td = half_diff(img["l"], img["v"])
    np.testing.assert_allclose(th, np.broadcast_to(img["theta_h"][None, :], th.shape), atol=1e-7)  # columns
    np.testing.assert_allclose(td, np.broadcast_to(img["theta_d"][:, None], td.shape), atol=1e-7)  # rows
    f = model_f(case, img["l"], img["v"])
    np.testing.assert_allclose(img["f"], f, rtol=1e-12, atol=1e-15)
    valid = (img["l"][..., 2] > 0) & (img["v"][..., 2] > 0)
    np.testing.assert_array_equal(img["valid"], valid)
    assert np.all(img["f"][~valid] == 0.0)


def test_phi_d_is_the_azimuth_of_l_about_h():
    brdf = V.model_brdf("gltf")
    for phi_d in (0.0, 0.6, math.pi / 2, 2.5):
        s = V.theta_d_slice(brdf, math.radians(20.0), phi_d, count=5)
        l, v = s["l"], s["v"]
        h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
        b = np.cross(Z, h)
        b /= np.linalg.norm(b, axis=-1, keepdims=True)
        t = np.cross(b, h)
        np.testing.assert_allclose(np.arctan2(np.sum(l * b, -1), np.sum(l * t, -1)), phi_d, atol=1e-9)


# ------------------------------------------------------------------ albedo


def test_albedo_of_a_lambertian_lobe_is_its_colour():
    # cook_torrance with the exact dielectric Fresnel of f0 = 0 (IOR 1) has no specular lobe: Lambert alone
    for r in (0.0, 0.3, 1.0):
        brdf = V.model_brdf("cook_torrance", (0.5, 0.3, 0.2), 0.0, r, fresnel="exact-dielectric", reflectance=0.0)
        e = V.directional_albedo(brdf)
        np.testing.assert_allclose(e["albedo"], np.broadcast_to([0.5, 0.3, 0.2], e["albedo"].shape), atol=3e-5)
        np.testing.assert_allclose(e["mu"], np.cos(e["theta_v"]))


def test_albedo_white_furnace_against_the_tables_and_1_minus_ln2():
    from pbrkit.albedo.tables import specular_integrals

    for r in (0.2, 0.6, 1.0):
        e = V.directional_albedo(V.model_brdf("filament", (0.3, 0.3, 0.3), 0.0, r))
        ab = specular_integrals(e["mu"], [r], "height-correlated")[0]  # F0 A + B; F = 1: A + B
        np.testing.assert_allclose(e["white"], ab[:, 0] + ab[:, 1], atol=1e-4)
        assert np.all(e["furnace"] == 1.0)
        assert np.all(np.abs(e["compensated"] - 1.0) < 0.02)  # the compensated white furnace is 1
    # GGX at alpha = 1 seen at normal incidence keeps 1 - ln 2 (Kulla & Conty 2017)
    assert abs(e["white"][0] - (1.0 - math.log(2.0))) < 2e-4


def test_albedo_of_a_model_against_a_brute_force_rule():
    # a 2-D Gauss-Legendre rule over (theta_l, phi_l), independent of albedo_quadrature's half-vector map
    brdf = V.model_brdf("ue4", (0.7, 0.4, 0.2), 0.0, 0.6)
    e = V.directional_albedo(brdf, count=8)
    xt, wt = np.polynomial.legendre.leggauss(256)
    xp, wp = np.polynomial.legendre.leggauss(256)
    theta = 0.25 * math.pi * (xt + 1.0)
    phi = math.pi * (xp + 1.0)
    weight = (0.25 * math.pi * wt)[:, None] * (math.pi * wp)[None, :] * np.sin(theta)[:, None]
    l = np.stack(np.broadcast_arrays(np.sin(theta)[:, None] * np.cos(phi), np.sin(theta)[:, None] * np.sin(phi),
                                     np.cos(theta)[:, None]), axis=-1)
    for k in (0, 3, 7):
        v = np.array([math.sin(e["theta_v"][k]), 0.0, math.cos(e["theta_v"][k])])
        f = models.ue4(l, v, Z, material_of(brdf))
        ref = np.einsum("tpc,tp->c", f, weight * l[..., 2])
        np.testing.assert_allclose(e["albedo"][k], ref, atol=2e-4)


# ------------------------------------------------------------------ spheres


def test_point_lit_sphere_is_f_cos_times_irradiance():
    brdf = V.model_brdf("filament", (0.8, 0.5, 0.2), 0.0, 0.3, anisotropy=0.6)
    size = 24
    s = V.lit_sphere_point(brdf, math.radians(40.0), math.radians(120.0), size=size)
    lt, lp = math.radians(40.0), math.radians(120.0)
    light = np.array([math.sin(lt) * math.cos(lp), math.sin(lt) * math.sin(lp), math.cos(lt)])
    np.testing.assert_allclose(s["light"], light, atol=1e-15)
    rng = np.random.default_rng(1)
    inside = np.argwhere(s["mask"])
    for i, j in inside[rng.choice(len(inside), 12, replace=False)]:
        x = 1.1 * (2.0 * (j + 0.5) / size - 1.0)
        y = 1.1 * (1.0 - 2.0 * (i + 0.5) / size)
        n = np.array([x, y, math.sqrt(1.0 - x * x - y * y)])
        t = np.cross(n, [0.0, 1.0, 0.0])  # the renderer's tangent: along the parallels about +Y
        t /= np.linalg.norm(t)
        f = models.filament(light, Z, n, material_of(brdf), t=t)
        np.testing.assert_allclose(s["radiance"][i, j], f * max(n @ light, 0.0) * math.pi, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(s["normal"][i, j], n, atol=1e-15)
    assert np.all(s["radiance"][~s["mask"]] == 0.0)


def lambert_table():
    from pbrkit.measured.merl import merl_table

    lambertian = V.model_brdf("cook_torrance", (0.6, 0.5, 0.4), 0.0, 0.5, fresnel="exact-dielectric",
                              reflectance=0.0)
    return lambertian, merl_table(lambda l, v, n: lambertian.evaluate(l, v, n))


def test_environment_sphere_renderer_and_measured_quadrature_agree_for_lambert():
    # two independent computations of one image: the real-time renderer (SH irradiance of the bake) for the
    # model, the quadrature over the environment's texels for the same BRDF as a MERL table
    from pbrkit.measured.merl import MerlBRDF

    lambertian, table = lambert_table()
    a = V.lit_sphere_environment(lambertian, size=32)
    b = V.lit_sphere_environment(MerlBRDF(table, "lambert"), size=32)
    np.testing.assert_array_equal(a["mask"], b["mask"])
    _, mask, n, v = V._sphere_hits(32)
    np.testing.assert_array_equal(a["mask"], mask)
    # away from the silhouette, where the MERL grid's bins below the horizon (0) meet grazing views
    facing = np.sum(n * v, axis=-1) > 0.5
    la, lb = (a["radiance"][mask] @ Y709)[facing], (b["radiance"][mask] @ Y709)[facing]
    assert np.median(np.abs(lb / la - 1.0)) < 0.01  # SH9 irradiance against the texel sum
    assert np.max(np.abs(lb / la - 1.0)) < 0.06
    np.testing.assert_allclose(a["radiance"][~a["mask"]], b["radiance"][~b["mask"]], rtol=1e-6, atol=1e-6)


# ------------------------------------------------------------------ terms


def test_terms_are_the_papers_terms():
    r, alpha = 0.4, 0.16
    theta_v = math.radians(40.0)
    t = V.terms(V.model_brdf("gltf", (0.9, 0.5, 0.1), 0.4, r), theta_v, count=40)
    np.testing.assert_allclose(t["D"], distributions.d_ggx(np.cos(t["theta_h"]), alpha), rtol=1e-10)
    f0 = fresnel.f0_metallic(np.array([0.9, 0.5, 0.1]), 0.4, 0.04)
    np.testing.assert_allclose(t["F"], fresnel.f_schlick(np.cos(t["theta_d"])[:, None], f0, 1.0), rtol=1e-10)
    nol, nov = np.cos(t["theta_l"]), math.cos(theta_v)
    sep = masking.g2_separable(masking.lambda_ggx(nol, alpha), masking.lambda_ggx(nov, alpha))
    np.testing.assert_allclose(t["G"], sep, rtol=1e-10)  # glTF's V is the separable Smith-GGX
    t = V.terms(V.model_brdf("filament", roughness=r), theta_v, count=40)
    hc = masking.g2_height_correlated(masking.lambda_ggx(nol, alpha), masking.lambda_ggx(nov, alpha))
    np.testing.assert_allclose(t["G"], hc, rtol=1e-9)
    t = V.terms(V.model_brdf("ue4", roughness=r), theta_v, count=40)
    np.testing.assert_allclose(t["G"], masking.g2_schlick_ggx(nol, nov, masking.k_ue4_direct(r)), rtol=1e-10)
    t = V.terms(V.model_brdf("cook_torrance", roughness=r, distribution="beckmann"), theta_v, count=40)
    np.testing.assert_allclose(t["D"], distributions.d_beckmann(np.cos(t["theta_h"]), alpha), rtol=1e-10)
    t = V.terms(V.model_brdf("urp_mobile", roughness=r), theta_v, count=40)
    np.testing.assert_allclose(t["D"], distributions.d_ggx(np.cos(t["theta_h"]), alpha), rtol=1e-12)


def _fresnel_of(name, voh, base, metallic):
    if name == "exact-dielectric":  # IOR from f0 = 0.04 (reflectance 0.5), metallic ignored
        return fresnel.f_conductor(voh, fresnel.ior_from_f0(0.04), 0.0)[:, None] * np.ones(3)
    f0 = fresnel.f0_metallic(np.asarray(base), metallic, 0.04)
    if name == "schlick-pow4":
        return fresnel.f_schlick_pow4(voh[:, None], f0, 1.0)
    return fresnel.f_schlick(voh[:, None], f0, 1.0)


@pytest.mark.parametrize("fres", ["schlick", "exact-dielectric", "schlick-pow4"])
def test_terms_recompose_the_model(fres):
    # D (n.h) G / (4 n.l n.v) F (v.h) at the directions of the G sweep is cook_torrance without diffuse, and
    # the F curve is the Fresnel term at v.h = cos theta_d
    theta_v = math.radians(30.0)
    base, metallic, r = (0.9, 0.6, 0.3), 0.5, 0.45
    brdf = V.model_brdf("cook_torrance", base, metallic, r, fresnel=fres, diffuse="none")
    t = V.terms(brdf, theta_v, count=50)
    np.testing.assert_allclose(t["F"], _fresnel_of(fres, np.cos(t["theta_d"]), base, metallic), rtol=1e-10)
    l = np.stack([np.sin(t["theta_l"]), 0 * t["theta_l"], np.cos(t["theta_l"])], axis=-1)
    v = np.array([math.sin(theta_v), 0.0, math.cos(theta_v)])
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    d = distributions.d_ggx(h[:, 2], r * r)
    f = models.cook_torrance(l, v, Z, material_of(brdf), fresnel=fres, diffuse="none")
    spec = (d * t["G"] / (4 * l[:, 2] * v[2]))[:, None] * _fresnel_of(fres, h @ v, base, metallic)
    np.testing.assert_allclose(spec, f, rtol=1e-10)


def test_terms_of_a_measured_brdf_are_none():
    class Measured:
        name = "m"

        def evaluate(self, l, v, n=None):
            return np.ones(np.broadcast_shapes(np.shape(l), np.shape(v)))

    assert V.terms(Measured(), 0.3) is None


# ------------------------------------------------------------------ MERL


@pytest.fixture(scope="module")
def merl_file(tmp_path_factory):
    from pbrkit.measured.merl import merl_table, write_merl

    brdf = V.model_brdf("cook_torrance", (0.7, 0.4, 0.2), 0.0, 0.35, diffuse="lambert")
    path = tmp_path_factory.mktemp("merl") / "ggx.binary"
    write_merl(path, merl_table(lambda l, v, n: brdf.evaluate(l, v, n)))
    return brdf, path


def test_a_merl_file_shows_in_the_views(merl_file):
    from pbrkit.measured.merl import merl_bin_centres, read_merl

    model, path = merl_file
    measured = read_merl(path)
    assert measured.name == "ggx"
    th, _, pd = merl_bin_centres()
    # at bin centres the measured BRDF is the model it was sampled from (nearest bin, exact)
    s_m = V.theta_d_slice(measured, th[20], pd[90], count=90)
    s_a = V.theta_d_slice(model, th[20], pd[90], count=90)
    ok = (s_a["l"][:, 2] > 0) & (s_a["v"][:, 2] > 0)
    np.testing.assert_allclose(s_m["f"][ok], s_a["f"][ok], rtol=1e-12)
    img_m = V.half_diff_image(measured, pd[90], size=90)
    np.testing.assert_allclose(img_m["f"][:, 20], V.theta_d_slice(measured, img_m["theta_h"][20], pd[90])["f"])
    # every view runs, finite, and close to the model's where binning allows
    p_m, p_a = V.incidence_plane(measured, 0.6), V.incidence_plane(model, 0.6)
    assert np.all(np.isfinite(p_m["f"])) and np.corrcoef(p_m["value"], p_a["value"])[0, 1] > 0.99
    e_m, e_a = V.directional_albedo(measured, count=8), V.directional_albedo(model, count=8)
    assert e_m["white"] is None and e_m["compensated"] is None
    np.testing.assert_allclose(e_m["albedo"], e_a["albedo"], atol=0.02)
    assert np.all(np.isfinite(V.lobe_3d(measured, 0.5)["radius"]))
    sp_m, sp_a = V.lit_sphere_point(measured, 0.5, size=32), V.lit_sphere_point(model, 0.5, size=32)
    assert np.median(np.abs(sp_m["radiance"] - sp_a["radiance"])[sp_a["mask"]]) < 0.02
    c = V.compare(model, measured, 0.6, size=16)
    assert c["sphere_difference"].shape == (16, 16, 3) and np.all(np.isfinite(c["value_difference"]))


# ------------------------------------------------------------------ BRDFs


def test_model_brdf_checks_like_a_scene_material():
    with pytest.raises(ValueError, match="sheen needs model 'disney'"):
        V.model_brdf("gltf", sheen=0.5)
    with pytest.raises(ValueError, match="unknown model"):
        V.model_brdf("phong")
    with pytest.raises(ValueError, match="distribution can only be chosen"):
        V.model_brdf("ue4", distribution="beckmann")
    assert V.applicable_parameters("gltf", {"sheen": 0.5, "reflectance": 0.2}) == {}
    assert V.applicable_parameters("disney", {"anisotropy": -0.5}) == {"anisotropy": 0.0}
    white = V.model_brdf("cook_torrance", conductor="gold", fresnel="exact-conductor", roughness=0.3).white()
    assert white.spec.fresnel == "none" and white.spec.diffuse == "none" and white.spec.roughness == 0.3


def test_view_threads_restores_the_count():
    import numba

    before = numba.get_num_threads()
    with V.view_threads(1):
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before


# ------------------------------------------------------------------ glTF's KHR_materials extensions


GLTF_EXTENSIONS = {
    "clearcoat": dict(clearcoat=1.0, clearcoat_roughness=0.05),
    "sheen": dict(sheen_color=(1.0, 1.0, 1.0), sheen_roughness=0.5),
    "specular": dict(specular=0.3, specular_color=(1.0, 0.5, 0.2)),
    "ior": dict(ior=2.4),
}


@pytest.mark.parametrize("extension", sorted(GLTF_EXTENSIONS))
def test_gltf_extensions_change_the_views_by_the_models_values(extension):
    """Each KHR_materials extension's parameters reach the views: the theta_h slice of
    the gltf model moves, and is the model's value with those parameters."""
    core = V.model_brdf("gltf", (0.3, 0.05, 0.05), 0.0, 0.5)
    brdf = V.model_brdf("gltf", (0.3, 0.05, 0.05), 0.0, 0.5, **GLTF_EXTENSIONS[extension])
    pd, td = math.radians(90.0), math.radians(30.0)
    s0, s = V.theta_h_slice(core, td, pd, count=30), V.theta_h_slice(brdf, td, pd, count=30)
    np.testing.assert_allclose(s["f"], models.gltf(s["l"], s["v"], Z, material_of(brdf)), rtol=1e-12, atol=1e-15)
    change = np.max(np.abs(s["value"] - s0["value"]) / s0["value"])
    assert change > 0.05, (extension, change)
    if extension in ("clearcoat", "ior"):  # a second (sharp) lobe, a brighter dielectric: more at the mirror
        assert s["value"][0] > 1.2 * s0["value"][0]
    if extension == "specular":  # weaker, orange F0: less, and less blue than red
        assert s["value"][0] < s0["value"][0] and s["f"][0, 2] < s["f"][0, 0]
    if extension == "sheen":  # the Charlie lobe adds most where the half vector leans away from n
        assert s["value"][-1] - s0["value"][-1] > s["value"][0] - s0["value"][0]
    for parameter in GLTF_EXTENSIONS[extension]:
        assert parameter in V.MODEL_PARAMETERS["gltf"] + V.COLOUR_PARAMETERS["gltf"]


def test_every_parameter_has_a_finite_slider_and_the_white_lobe_drops_the_extras():
    assert set(V.SLIDER_RANGES) == set(V.PARAMETER_RANGES) | set(V.COLOUR_RANGES)
    for name, (lo, hi) in V.SLIDER_RANGES.items():
        assert math.isfinite(lo) and math.isfinite(hi) and lo < hi, name
    assert V.SLIDER_RANGES["ior"] == (1.0, 3.0) and V.SLIDER_RANGES["specular_color"] == (0.0, 2.0)
    assert set(V.COLOUR_PARAMETERS["gltf"]) == {"sheen_color", "specular_color"}
    assert V.applicable_parameters("gltf", {"sheen_color": (2.0, 0.5, -1.0), "ior": 2.4, "sheen": 0.5}) == {
        "sheen_color": (1.0, 0.5, 0.0), "ior": 2.4}
    # the albedo view's white lobe (F = 1): no sheen, no coat, whatever the material has
    brdf = V.model_brdf("gltf", **GLTF_EXTENSIONS["clearcoat"], **GLTF_EXTENSIONS["sheen"], ior=2.4)
    white = brdf.white()
    assert white.spec.clearcoat == 0.0 and tuple(white.spec.sheen_color) == (0.0, 0.0, 0.0)
    np.testing.assert_allclose(V.directional_albedo(white, count=8)["value"],
                               V.directional_albedo(V.model_brdf("gltf").white(), count=8)["value"], rtol=1e-12)
    assert V.model_brdf("disney", sheen=0.5, clearcoat=0.5).white().spec.clearcoat == 0.0
