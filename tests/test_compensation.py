"""Multiple-scattering compensation: energy restored, F_avg, and colour."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.albedo.compensation import compensated_albedo, white_furnace_compensated
from pbrkit.albedo.tables import (
    average_albedo,
    f_avg_conductor,
    f_avg_numeric,
    f_avg_schlick,
    kulla_conty_ms,
    kulla_conty_tables,
    specular_integrals,
    texel_centres,
)
from pbrkit.app.cli import app
from pbrkit.brdf.fresnel import CONDUCTORS, f_conductor, f_schlick


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
    f0 = np.array([0.04, 0.5, 0.9])
    numeric = f_avg_numeric(lambda mu: f_schlick(mu, f0[None, :]))
    np.testing.assert_allclose(f_avg_schlick(f0), numeric, atol=1e-12)
    # Conductors: against SciPy's adaptive quadrature of 2 integral F(mu) mu dmu.
    from scipy.integrate import quad

    eta, k = (np.asarray(v) for v in CONDUCTORS["gold"])
    f_avg = f_avg_conductor(eta, k)
    for c in range(3):
        ref = 2.0 * quad(lambda mu: float(f_conductor(mu, eta[c], k[c])) * mu, 0.0, 1.0, epsabs=1e-12)[0]
        assert f_avg[c] == pytest.approx(ref, abs=1e-9)


def test_filament_compensation_divides_by_dfg2_for_white():
    n = 16
    grid = texel_centres(n)
    single = white_furnace_compensated("none", grid, grid, n)
    filament = white_furnace_compensated("filament", grid, grid, n)
    np.testing.assert_allclose(filament, single / single, atol=2e-3)


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
    result = CliRunner().invoke(app, ["furnace", "-o", str(tmp_path), "--mu", "4", "--roughness", "2",
                                      "--samples", "16", "--lobe", "ggx/height-correlated",
                                      "--compensation", "filament", "--quiet"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "compensation.json").read_text())
    assert summary["max_abs_error_on_texel_grid"] < 1e-3
    assert (tmp_path / "compensation.png").exists() and np.load(tmp_path / "compensation.npy").shape == (2, 128, 128)
    bad = CliRunner().invoke(app, ["furnace", "-o", str(tmp_path / "x"), "--compensation", "magic"])
    assert bad.exit_code == 1 and not (tmp_path / "x").exists()


def test_kulla_conty_tables_against_direct_integration():
    e, e_avg = kulla_conty_tables(8)
    assert e.shape == (8, 8) and e_avg.shape == (8,)
    # E_avg = 2 integral E(mu) mu dmu, here by a composite midpoint rule on 2000 points
    mu = (np.arange(2000) + 0.5) / 2000
    for j, r in enumerate(texel_centres(8)):
        direct = 2.0 * np.mean(specular_integrals(mu, [r]).sum(-1)[0] * mu)
        assert e_avg[j] == pytest.approx(direct, abs=2e-5)
    np.testing.assert_allclose(e, specular_integrals(texel_centres(8), texel_centres(8)).sum(-1), atol=1e-6)
