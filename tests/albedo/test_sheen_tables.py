"""The sheen tables of the bake (pbrkit.albedo.sheen_tables): E_sheen and the
Ashikhmin-visibility albedo at the texel centres against an independent quadrature
over the light direction (tests/support/sheen_reference.py's transcription of the
KHR_materials_sheen formulas, a tensor Gauss-Legendre rule checked against scipy
in tests/microfacet/test_charlie.py; the Ashikhmin visibility transcribed here), to 1e-3; the layouts the Khronos
Sample Viewer reads (lut_charlie .b, lut_sheen_E .r); refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from quadrature import graded_gauss_legendre
from scipy import integrate
from sheen_reference import reference_sheen_albedo, spec_d

from pbrkit.albedo.sheen_tables import SHEEN_NODES, charlie_lut, sheen_albedo_texels, sheen_e_lut, sheen_lut

N = 16
#: (column i, row j) texels checked: grazing, middle and normal n.v at smooth and rough sheen
TEXELS = [(0, 3), (2, 8), (7, 7), (12, 2), (15, 15), (5, 12), (1, 14)]


def _centre(k, n=N):
    return (k + 0.5) / n


def reference_ashikhmin_albedo(mu, r):
    """integral of D_spec V_A (n.l) dl, V_A = 1 / (4 (n.l + n.v - n.l n.v)) (Ashikhmin and
    Premoze 2007, as the Khronos IBL Sampler's V_Ashikhmin without its clamp), by the same
    tensor rule over the light direction as sheen_reference.reference_sheen_albedo."""
    ct, wt = graded_gauss_legendre(0.0, 1.0, 24, 24, grade=2.0)
    ph, wp = graded_gauss_legendre(0.0, np.pi, 24, 16)
    ct, ph = np.meshgrid(ct, ph, indexing="ij")
    w = np.outer(wt, wp)
    st = np.sqrt(1.0 - ct * ct)
    sv = math.sqrt(1.0 - mu * mu)
    hx, hy, hz = st * np.cos(ph) + sv, st * np.sin(ph), ct + mu
    noh = hz / np.sqrt(hx * hx + hy * hy + hz * hz)
    f = spec_d(noh, r) / (4.0 * (ct + mu - ct * mu))
    return 2.0 * float(np.sum(f * ct * w))


def test_ashikhmin_reference_against_scipy():
    mu, r = 0.4, 0.6

    def integrand(phi, ct):
        st = math.sqrt(1.0 - ct * ct)
        sv = math.sqrt(1.0 - mu * mu)
        h = np.array([st * math.cos(phi) + sv, st * math.sin(phi), ct + mu])
        return spec_d(h[2] / np.linalg.norm(h), r) / (4.0 * (ct + mu - ct * mu)) * ct

    value, _ = integrate.dblquad(integrand, 0.0, 1.0, 0.0, math.pi, epsabs=1e-10, epsrel=1e-9)
    assert reference_ashikhmin_albedo(mu, r) == pytest.approx(2.0 * value, rel=1e-6)


def test_sheen_table_is_e_sheen_at_the_texel_centres():
    e = sheen_albedo_texels(N, "sheen", cache=False)
    assert e.dtype == np.float32 and e.shape == (N, N)
    for i, j in TEXELS:
        assert e[j, i] == pytest.approx(reference_sheen_albedo(_centre(i), _centre(j)), abs=1e-3), (i, j)


def test_ashikhmin_table_at_the_texel_centres():
    e = sheen_albedo_texels(N, "ashikhmin", cache=False)
    for i, j in TEXELS:
        assert e[j, i] == pytest.approx(reference_ashikhmin_albedo(_centre(i), _centre(j)), abs=1e-3), (i, j)


def test_layouts_the_sample_viewer_reads():
    pair, spec = sheen_lut(N)
    assert pair.shape == (N, N, 2) and spec.description()["channels"] == ["E_sheen", "E_ashikhmin"]
    np.testing.assert_array_equal(pair[..., 0], sheen_albedo_texels(N, "sheen"))
    np.testing.assert_array_equal(pair[..., 1], sheen_albedo_texels(N, "ashikhmin"))
    charlie, spec = charlie_lut(N)  # lut_charlie: the viewer reads .b
    assert charlie.shape == (N, N, 3) and not charlie[..., :2].any()
    np.testing.assert_array_equal(charlie[..., 2], pair[..., 0])
    assert spec.description()["axes"]["row j"].startswith("sheen roughness r = (j + 0.5) / N")
    e, spec = sheen_e_lut(N)  # lut_sheen_E: the viewer reads .r
    assert e.shape == (N, N, 2) and not e[..., 1].any()
    np.testing.assert_array_equal(e[..., 0], pair[..., 0])
    assert spec.description()["integration"]["theta_nodes_per_segment"] == SHEEN_NODES[0]


def test_deterministic_and_cached_alike():
    a = sheen_albedo_texels(8, cache=False)
    b = sheen_albedo_texels(8)
    assert a.tobytes() == b.tobytes() == sheen_albedo_texels(8).tobytes()


def test_refusals():
    with pytest.raises(ValueError, match="table size"):
        sheen_albedo_texels(1)
    with pytest.raises(ValueError, match="unknown sheen visibility 'smith'"):
        sheen_albedo_texels(8, "smith")
