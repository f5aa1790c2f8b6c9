"""Property tests (Hypothesis) of every shading term and model.

Over random directions in the upper hemisphere -- including grazing ones down to
cos theta = 1e-6 and exactly 0 -- and random materials (roughness including
exactly 0 and 1, metallic in [0, 1], anisotropy in [-1, 1]):

* every model returns finite values >= 0 of shape (..., 3), and 0 when a
  direction is exactly on the horizon;
* every term is finite and in its range: D >= 0, Lambda >= 0, G1 and G2 in
  [0, 1] (Kelemen's G2 = n.l n.v / (v.h)^2 included: with
  (v.h)^2 = (1 + l.v) / 2 and l.v >= n.l n.v - sin theta_l sin theta_v it never
  exceeds 1), F in [0, 1], diffuse factors >= 0, visibility >= 0.

Settings are modest (150 examples, no deadline) and derandomised, so CI runs
are reproducible.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pbrkit import Material
from pbrkit.brdf import diffuse as df
from pbrkit.brdf import distributions as dist
from pbrkit.brdf import fresnel as fr
from pbrkit.brdf import masking as mk
from pbrkit.brdf.models import (
    DISTRIBUTIONS,
    FRESNELS,
    MASKINGS,
    cook_torrance,
    disney,
    filament,
    frame_cosines,
    ue4,
    urp_mobile,
)

PROPERTY = settings(max_examples=150, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
N = np.array([0.0, 0.0, 1.0])
T = np.array([1.0, 0.0, 0.0])
COUNT = 6  # direction pairs per example

unit = st.floats(0.0, 1.0, allow_nan=False)
cosines = st.one_of(st.sampled_from([0.0, 1e-6, 1e-3, 1.0]), st.floats(1e-6, 1.0))
angles = st.floats(0.0, 2.0 * np.pi, allow_nan=False)
roughness = st.one_of(st.sampled_from([0.0, 1.0]), unit)


@st.composite
def directions(draw):
    """(COUNT, 3) unit vectors with n.d >= 0 (local frame, n = +z)."""
    c = np.array(draw(st.lists(cosines, min_size=COUNT, max_size=COUNT)))
    phi = np.array(draw(st.lists(angles, min_size=COUNT, max_size=COUNT)))
    s = np.sqrt(1.0 - c * c)
    return np.stack([s * np.cos(phi), s * np.sin(phi), c], axis=-1)


@st.composite
def materials(draw, conductor=False):
    kwargs = {}
    if conductor:
        kwargs = dict(eta=np.array(draw(st.lists(st.floats(1e-3, 50.0), min_size=3, max_size=3))),
                      k=np.array(draw(st.lists(st.floats(0.0, 50.0), min_size=3, max_size=3))))
    return Material(base_color=np.array(draw(st.lists(unit, min_size=3, max_size=3))),
                    metallic=np.array(draw(st.lists(unit, min_size=COUNT, max_size=COUNT))),
                    roughness=np.array(draw(st.lists(roughness, min_size=COUNT, max_size=COUNT))),
                    reflectance=draw(unit),
                    anisotropy=draw(st.one_of(st.sampled_from([0.0, -1.0, 1.0]), st.floats(-1.0, 1.0))),
                    **kwargs)


def _check_model_output(out, l, v):
    assert out.shape == (COUNT, 3)
    assert np.all(np.isfinite(out)), out
    assert np.all(out >= 0.0), out
    horizon = (l[:, 2] == 0.0) | (v[:, 2] == 0.0)
    assert np.all(out[horizon] == 0.0)


@PROPERTY
@given(l=directions(), v=directions(), material=materials())
def test_engine_models_are_finite_and_non_negative(l, v, material):
    iso = Material(base_color=material.base_color, metallic=material.metallic, roughness=material.roughness,
                   reflectance=material.reflectance)
    for out in (ue4(l, v, N, iso), urp_mobile(l, v, N, iso),
                filament(l, v, N, material, t=T), filament(l, v, N, material, diffuse="burley", t=T),
                filament(l, v, N, iso)):
        _check_model_output(out, l, v)
    principled = Material(base_color=material.base_color, metallic=material.metallic,
                          roughness=material.roughness, reflectance=material.reflectance,
                          anisotropy=np.abs(material.anisotropy), subsurface=0.5, sheen=1.0, clearcoat=1.0,
                          specular_tint=0.5, clearcoat_gloss=material.reflectance)
    _check_model_output(disney(l, v, N, principled, t=T), l, v)


@PROPERTY
@given(l=directions(), v=directions(), material=materials(conductor=True),
       distribution=st.sampled_from(DISTRIBUTIONS), masking=st.sampled_from(MASKINGS),
       fresnel=st.sampled_from(FRESNELS), diffuse=st.sampled_from(("lambert", "burley", "none")))
def test_cook_torrance_is_finite_and_non_negative(l, v, material, distribution, masking, fresnel, diffuse):
    out = cook_torrance(l, v, N, material, distribution=distribution, masking=masking, fresnel=fresnel,
                        diffuse=diffuse, t=T)
    _check_model_output(out, l, v)


def _finite_in(x, lo=None, hi=None, tol=1e-12):
    x = np.asarray(x)
    assert np.all(np.isfinite(x)), x
    if lo is not None:
        assert np.all(x >= lo - tol), x
    if hi is not None:
        assert np.all(x <= hi + tol), x


@PROPERTY
@given(l=directions(), v=directions(), r=st.lists(roughness, min_size=COUNT, max_size=COUNT),
       anisotropy=st.floats(-1.0, 1.0), gamma=st.floats(0.5, 4.0))
def test_distributions_and_masking_terms_in_range(l, v, r, anisotropy, gamma):
    r = np.asarray(r)
    c = frame_cosines(l, v, N, t=T, tangent_frame=True)
    alpha = dist.alpha_from_roughness(r)
    at, ab = dist.anisotropic_alphas(alpha, anisotropy)
    bx, by = dist.anisotropic_alphas_burley(alpha, abs(anisotropy))
    for d in (dist.d_ggx(c.noh, alpha), dist.d_beckmann(c.noh, alpha), dist.d_gtr(c.noh, alpha, gamma),
              dist.d_gtr1(c.noh, alpha), dist.d_blinn_phong(c.noh, dist.phong_exponent_from_beckmann_alpha(alpha)),
              dist.d_ggx_anisotropic(c.noh, c.toh, c.boh, at, ab), dist.d_ggx_anisotropic(c.noh, c.toh, c.boh, bx, by),
              dist.d_beckmann_anisotropic(c.noh, c.toh, c.boh, at, ab)):
        _finite_in(d, lo=0.0)
    lambdas = {
        "ggx": (mk.lambda_ggx(c.nol, alpha), mk.lambda_ggx(c.nov, alpha)),
        "beckmann": (mk.lambda_beckmann(c.nol, alpha), mk.lambda_beckmann(c.nov, alpha)),
        "ggx-aniso": (mk.lambda_ggx_anisotropic(c.nol, c.tol, c.bol, at, ab),
                      mk.lambda_ggx_anisotropic(c.nov, c.tov, c.bov, at, ab)),
        "beckmann-aniso": (mk.lambda_beckmann_anisotropic(c.nol, c.tol, c.bol, at, ab),
                           mk.lambda_beckmann_anisotropic(c.nov, c.tov, c.bov, at, ab)),
    }
    for lam_l, lam_v in lambdas.values():
        _finite_in(lam_l, lo=0.0)
        _finite_in(lam_v, lo=0.0)
        _finite_in(mk.g1_smith(lam_v), 0.0, 1.0)
        _finite_in(mk.g2_separable(lam_l, lam_v), 0.0, 1.0)
        _finite_in(mk.g2_height_correlated(lam_l, lam_v), 0.0, 1.0)
    for g in (mk.g1_ggx(c.nov, alpha), mk.g1_beckmann(c.nov, alpha),
              mk.g1_schlick_ggx(c.nov, mk.k_ue4_direct(r)), mk.g1_schlick_ggx(c.nov, mk.k_ue4_ibl(r)),
              mk.g2_schlick_ggx(c.nol, c.nov, mk.k_schlick_from_alpha(alpha)),
              mk.g2_kelemen(c.nol, c.nov, c.voh)):
        _finite_in(g, 0.0, 1.0)
    for visibility in (mk.v_smith_ggx_height_correlated(c.nol, c.nov, alpha),
                       mk.visibility(mk.g2_height_correlated(*lambdas["ggx"]), c.nol, c.nov),
                       mk.v_kelemen(c.voh), mk.v_neubelt(c.nol, c.nov)):
        _finite_in(visibility, lo=0.0)


@PROPERTY
@given(cos=st.lists(st.one_of(cosines, st.floats(-1.0, 1.0)), min_size=COUNT, max_size=COUNT),
       f0=unit, f90=unit, r=roughness, metallic=unit,
       eta=st.floats(1e-3, 50.0), k=st.floats(0.0, 50.0))
def test_fresnel_and_diffuse_terms_in_range(cos, f0, f90, r, metallic, eta, k):
    c = np.asarray(cos)
    for f in (fr.f_schlick(c, f0), fr.f_schlick(c, f0, f90), fr.f_schlick_pow4(c, f0, f90),
              fr.f_schlick_ue4_sg(c, f0), fr.f_schlick_roughness(c, f0, r), fr.f_dielectric(c, eta),
              fr.f_conductor(c, eta, k), fr.f90_filament(3.0 * f0)):
        _finite_in(f, 0.0, 1.0)
    _finite_in(fr.f0_from_ior(eta), 0.0, 1.0)
    _finite_in(fr.f0_from_reflectance(f0), 0.0, 0.16)
    _finite_in(fr.f0_metallic(f90, metallic, f0), min(f0, f90), max(f0, f90))
    _finite_in(df.lambert(c), 0.0, 1.0 / np.pi)
    loh = np.abs(c)
    _finite_in(df.burley(c, c[::-1], loh, r), 0.0, 2.5**2 / np.pi)
    _finite_in(df.kd_ibl(c, f0, r, metallic), 0.0, 1.0)
