"""Multiple-scattering compensation: energy restored, F_avg, and colour."""

import json

import numpy as np
import pytest
from quadrature import gauss_legendre
from reference_brdf import (
    GOLD_ETA_K,
    RULE,
    fresnel_conductor,
    fresnel_schlick,
    ggx_albedo,
)
from typer.testing import CliRunner

from pbrkit.albedo.compensation import compensated_albedo, white_furnace_compensated
from pbrkit.albedo.lut import lookup_table
from pbrkit.albedo.tables import (
    average_albedo,
    f_avg_conductor,
    f_avg_numeric,
    f_avg_schlick,
    filament_energy_compensation,
    kulla_conty_ms,
    kulla_conty_tables,
    specular_integrals,
    texel_centres,
)
from pbrkit.cli import app
from pbrkit.brdf.fresnel import CONDUCTORS, f_conductor

# pbrkit's GGX albedo integrals (the DFG tables and specular_integrals) are converged
# to 1e-4 (README, `pbrkit lut` benchmark: max error 7.2e-5); the reference rule of
# tests/support/reference_brdf.py is within 1.4e-6 of a much denser one.
ALBEDO_ACCURACY = 1e-4


def reference_albedos(n, f0=()):
    """E (F = 1) and the Schlick albedos for each f0, shape (n, n) and (n, n, len(f0)),
    indexed [mu, r] on the texel centres of size n, by the independent quadrature."""
    axis = texel_centres(n)
    e = np.empty((n, n))
    s = np.empty((n, n, len(f0)))
    for a, mu in enumerate(axis):
        for b, r in enumerate(axis):
            e[a, b], s[a, b] = ggx_albedo(mu, r, f0, RULE)
    return e, s


@pytest.mark.parametrize("method", ["kulla-conty", "filament"])
def test_white_furnace_is_one_on_the_table_grid(method):
    n = 32
    grid = texel_centres(n)
    single = white_furnace_compensated("none", grid, grid, n)
    e = white_furnace_compensated(method, grid, grid, n, nodes=(48, 96, 24))
    assert np.abs(single - 1.0).max() > 0.5  # there was energy to restore
    assert np.abs(e - 1.0).max() < 1e-3


def test_kulla_conty_lobe_integrates_to_the_missing_energy():
    # integral of f_ms(mu_o, mu_i) (n.l) dl = 1 - E(mu_o), with E from the converged
    # quadrature and the hemisphere integral done directly in (cos theta, phi).
    r = 0.7
    x, w = np.polynomial.legendre.leggauss(200)
    mu_i = 0.5 * (x + 1.0)
    w_i = 0.5 * w
    e_i = specular_integrals(mu_i, [r]).sum(-1)[0]
    e_avg = average_albedo([r])[0]
    for mu_o in (0.2, 0.6, 1.0):
        e_o = specular_integrals([mu_o], [r]).sum(-1)[0, 0]
        integral = 2.0 * np.pi * np.sum(kulla_conty_ms(e_o, e_i, e_avg) * mu_i * w_i)
        assert integral == pytest.approx(1.0 - e_o, abs=1e-6)


def test_f_avg_closed_form_and_conductors():
    # F_avg = 2 integral F(mu) mu dmu; Schlick's integrand is a polynomial of degree 6, so
    # 4-point Gauss-Legendre is exact: (20 f0 + 1) / 21.
    f0 = np.array([0.04, 0.5, 0.9])
    mu, w = gauss_legendre(0.0, 1.0, 4)
    exact = 2.0 * np.sum(w[:, None] * mu[:, None] * fresnel_schlick(mu[:, None], f0[None, :]), axis=0)
    np.testing.assert_allclose(f_avg_schlick(f0), exact, atol=1e-14)
    numeric = f_avg_numeric(lambda m: fresnel_schlick(m, f0[None, :]))
    np.testing.assert_allclose(numeric, exact, atol=1e-12)
    # Conductors: against SciPy's adaptive quadrature of the Fresnel equations in real
    # arithmetic (tests/support/reference_brdf.py; pbrkit's f_conductor uses complex numbers).
    from scipy.integrate import quad

    eta, k = (np.asarray(v) for v in CONDUCTORS["gold"])
    f_avg = f_avg_conductor(eta, k)
    for c in range(3):
        ref = 2.0 * quad(lambda m, c=c: float(fresnel_conductor(m, eta[c], k[c])) * m, 0.0, 1.0, epsabs=1e-12)[0]
        assert f_avg[c] == pytest.approx(ref, abs=1e-9)


def test_filament_compensation_against_independent_albedo():
    # Filament sec. 4.7.2: the compensated albedo is S (1 + F0 (1 / E - 1)) with S the
    # single-scattering albedo (GGX, height-correlated Smith, Schlick F0) and E its white
    # (F = 1) albedo, here both integrated independently; pbrkit reads E from the DFG
    # table, exactly at the table's texel centres.  Coloured F0: gold's normal
    # reflectance (RGB) and 0.5.
    n = 8
    axis = texel_centres(n)
    eta, k = (np.asarray(v) for v in GOLD_ETA_K)
    gold = np.minimum(fresnel_conductor(1.0, eta, k), 1.0)
    f0 = np.concatenate([gold, [0.5]])
    e, s = reference_albedos(n, f0)
    expected = s * (1.0 + f0 * (1.0 / e[..., None] - 1.0))
    got = np.concatenate([compensated_albedo("filament", axis, axis, gold, table_size=n),
                          compensated_albedo("filament", axis, axis, 0.5, table_size=n)], axis=-1)
    # Errors dS, dE <= ALBEDO_ACCURACY move S (1 + F0 (1/E - 1)) by at most
    # (dS + F0 S dE / E) / E <= 2 ALBEDO_ACCURACY / E (S <= E, F0 <= 1).
    tolerance = 2.0 * ALBEDO_ACCURACY / e.min()
    np.testing.assert_allclose(got, expected, rtol=0, atol=tolerance)
    # The compensation matters here (up to +0.57, gold's red at n.v = r = 15/16), far above the tolerance.
    assert (expected - s).max() > 0.2

    # F0 = 1: E (1 + (1 / DFG2 - 1)) = 1 exactly when DFG2 is the true albedo E.  With E
    # integrated independently and pbrkit's table and compensation factor:
    dfg2 = lookup_table("dfg", n)[0][..., 1].T  # [mu, r]
    assert np.abs(e * filament_energy_compensation(1.0, dfg2) - 1.0).max() < ALBEDO_ACCURACY / e.min()
    assert np.abs(e - 1.0).max() > 0.5  # single scattering alone is far from 1
    white = compensated_albedo("filament", axis, axis, 1.0, table_size=n)[..., 0]
    assert np.abs(white - 1.0).max() < ALBEDO_ACCURACY / e.min()


def test_coloured_metals_keep_their_saturation():
    # Seed 002 / Kulla-Conty: the multiple-scattering energy is tinted by F_avg, so a rough
    # gold surface gets brighter without losing saturation (it gains some).
    eta, k = (np.asarray(v) for v in CONDUCTORS["gold"])
    f0 = f_conductor(1.0, eta, k)
    r = np.array([0.6, 0.8, 1.0])

    def saturation(a):
        return (a.max(-1) - a.min(-1)) / a.max(-1)

    none = compensated_albedo("none", [0.5], r, f0)[0]
    for method in ("kulla-conty", "filament"):
        comp = compensated_albedo(method, [0.5], r, f0)[0]
        assert np.all(comp.sum(-1) > none.sum(-1))
        assert np.all(saturation(comp) >= saturation(none) - 1e-9)


def test_cli_compensation(tmp_path):
    result = CliRunner().invoke(app, ["furnace", "-o", str(tmp_path), "--mu-count", "4", "--roughness-count", "2",
                                      "--samples", "16", "--lobe", "ggx/height-correlated",
                                      "--compensation", "filament", "--quiet"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "compensation.json").read_text())
    assert summary["max_abs_error_on_texel_grid"] < 1e-3
    assert (tmp_path / "compensation.png").exists() and np.load(tmp_path / "compensation.npy").shape == (2, 128, 128)
    bad = CliRunner().invoke(app, ["furnace", "-o", str(tmp_path / "x"), "--compensation", "magic"])
    assert bad.exit_code == 1 and not (tmp_path / "x").exists()


def test_kulla_conty_tables_against_independent_integration():
    # E(mu, r) of the table and E_avg(r) = 2 integral E(mu) mu dmu (Kulla & Conty 2017,
    # eqs. 4 and 6), with E from the independent quadrature and 16-point Gauss-Legendre in
    # mu (16, 24 and 32 points agree to 3e-8).
    n = 8
    e, e_avg = kulla_conty_tables(n)
    assert e.shape == (n, n) and e_avg.shape == (n,)
    e_ref, _ = reference_albedos(n)
    np.testing.assert_allclose(e, e_ref.T, rtol=0, atol=ALBEDO_ACCURACY)  # table layout [j (r), i (mu)]
    mu, w = gauss_legendre(0.0, 1.0, 16)
    for j, r in enumerate(texel_centres(n)):
        direct = 2.0 * sum(wk * mk * ggx_albedo(mk, r, (), RULE)[0] for mk, wk in zip(mu, w))
        assert e_avg[j] == pytest.approx(direct, abs=ALBEDO_ACCURACY)
