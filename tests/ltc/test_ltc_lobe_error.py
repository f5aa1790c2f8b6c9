"""The lobe error of LTC tables (:mod:`pbrkit.ltc.lobe_error`): the Monte Carlo
estimator against deterministic quadrature over the sphere, a fitted table
against deliberately wrong ones, determinism, and the files ``pbrkit ltc
--report`` writes with it."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.brdf.material import Material
from pbrkit.brdf.models import cook_torrance
from pbrkit.ltc.distribution import inverse_from_texel, ltc_evaluate
from pbrkit.ltc.fit import cell_view
from pbrkit.ltc.lobe_error import lobe_error, lobe_error_map, lobe_error_summary
from pbrkit.ltc.reference import directional_albedo
from pbrkit.rendering.area_lights import bundled_ltc_table


@pytest.fixture(scope="module")
def bundled():
    return bundled_ltc_table()


def _gauss_legendre(lo, hi, panels, order=6):
    """Composite Gauss-Legendre nodes and weights on [lo, hi]."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(lo, hi, panels + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def _quadrature_lobe_error(texel, nov, roughness, panels=96):
    """sqrt(int (D - f cos / E)^2 / int (f cos / E)^2) over the sphere by a
    composite Gauss-Legendre rule in (theta, phi), split at the horizon (the
    lobe's kink), with the lobe of :func:`pbrkit.brdf.models.cook_torrance`
    (GGX, height-correlated Smith, F = 1) and E its converged albedo: nothing
    of the Monte Carlo estimator (its samples, pdfs or mixture) is used."""
    albedo = float(directional_albedo(nov, roughness))
    m_inv = inverse_from_texel(np.asarray(texel, dtype=float))
    v = np.array([math.sqrt(1.0 - nov * nov), 0.0, nov])
    material = Material(base_color=np.ones(3), metallic=1.0, roughness=roughness)
    num = den = 0.0
    for lo, hi, n_theta in ((0.0, 0.5 * math.pi, panels), (0.5 * math.pi, math.pi, panels // 2)):
        theta, w_theta = _gauss_legendre(lo, hi, n_theta)
        phi, w_phi = _gauss_legendre(0.0, 2.0 * math.pi, 2 * n_theta)
        t, p = np.meshgrid(theta, phi, indexing="ij")
        w = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
        dw = (w_theta * np.sin(theta))[:, None] * w_phi[None, :]
        d = ltc_evaluate(m_inv, w)
        lobe = 0.0
        if lo == 0.0:
            f = cook_torrance(w, v, np.array([0.0, 0.0, 1.0]), material, fresnel="none", diffuse="none")[..., 0]
            lobe = f * np.maximum(w[..., 2], 0.0) / albedo
        num += np.sum((d - lobe) ** 2 * dw)
        den += np.sum(lobe * lobe * dw)
    return math.sqrt(num / den)


def test_monte_carlo_matches_quadrature(bundled):
    """Fitted texels of four cells (alpha 0.016 to 0.51, n.v 0.21 to 0.97) and the
    identity texel (the clamped cosine) in a fifth (alpha 0.40, n.v 0.77): the
    map's values and the quadrature agree to 2% (measured: 0.1% or better; the
    quadrature is converged to 1e-6 relative against the same rule with twice
    the panels)."""
    ltc1, _ = bundled
    cells = [(40, 20), (10, 45), (56, 30), (30, 8)]
    texels = [ltc1[t, a] for t, a in cells] + [np.array([1.0, 0.0, 0.0, 1.0])]
    views = [cell_view(t, a, 64) for t, a in cells] + [cell_view(30, 40, 64)]
    nov, r = np.array(views).T
    mc = lobe_error(np.array(texels), nov, r)
    table_map = lobe_error_map(ltc1)  # the same cells through the map
    for k, (t, a) in enumerate(cells):
        assert mc[k] == pytest.approx(table_map[t, a], rel=1e-12)
    for k in range(len(texels)):
        quad = _quadrature_lobe_error(texels[k], nov[k], r[k])
        assert mc[k] == pytest.approx(quad, rel=0.02), (k, mc[k], quad)
    # the cosine is far from a GGX lobe of alpha 0.4 at n.v 0.77 (0.61), the fitted cell close (0.04)
    assert mc[-1] > 0.3 and mc[0] < 0.1


def test_fitted_table_beats_wrong_tables(bundled):
    """pbrkit's bundled table has a median lobe error (0.052) far below the same
    texels with the rows reversed (each cell given another view's matrix: 0.94)
    or the identity everywhere (the clamped cosine: 0.84)."""
    ltc1, ltc2 = bundled
    albedo = ltc2[..., 0]
    fitted = lobe_error_map(ltc1, samples=1024, albedo=albedo)
    reversed_rows = lobe_error_map(ltc1[::-1], samples=1024, albedo=albedo)
    identity = lobe_error_map(np.tile([1.0, 0.0, 0.0, 1.0], (64, 64, 1)), samples=1024, albedo=albedo)
    assert np.median(fitted) < 0.1
    assert np.median(fitted) < 0.5 * np.median(reversed_rows)
    assert np.median(fitted) < 0.5 * np.median(identity)
    assert np.all(np.isfinite(fitted)) and np.all(fitted >= 0.0)
    summary = lobe_error_summary(fitted)
    assert set(summary) == {"median", "p95", "max"} and summary["median"] <= summary["p95"] <= summary["max"]


def test_lobe_error_is_deterministic(bundled):
    """Same inputs, same bytes; another seed changes the values by less than 2%
    (the estimator's noise at the default sample count); the every-ninth-texel
    8 x 8 table has the 64 x 64 table's cells (t / 7 = 9 t / 63)."""
    ltc1, _ = bundled
    small = np.ascontiguousarray(ltc1[::9, ::9])
    first = lobe_error_map(small)
    assert first.shape == (8, 8) and first.dtype == np.float64
    assert first.tobytes() == lobe_error_map(small).tobytes()
    other = lobe_error_map(small, seed=1)
    assert not np.array_equal(first, other)
    np.testing.assert_allclose(other, first, rtol=0.02)
    with pytest.raises(ValueError, match="power of two"):
        lobe_error_map(small, samples=1000)
    with pytest.raises(ValueError, match="masking"):
        lobe_error_map(small, distribution="beckmann", masking="schlick-ggx")


def test_cli_report_writes_the_lobe_error(tmp_path):
    runner = CliRunner()
    out = tmp_path / "ltc"
    result = runner.invoke(app, ["ltc", "-o", str(out), "--size", "4", "--polygons", "4", "--report", "-q"])
    assert result.exit_code == 0, result.output
    lobe = np.load(out / "lobe_error_pbrkit.npy")
    assert lobe.shape == (4, 4) and lobe.dtype == np.float32 and np.all(np.isfinite(lobe))
    assert (out / "report.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the published table (64 x 64, when installed) has no map at size 4
    assert not (out / "lobe_error_published.npy").exists()
    info = json.loads((out / "fit.json").read_text())
    assert "lobe_error_pbrkit.npy" in info["files"] and "report.png" in info["files"]
    assert sorted(info["files"]) == sorted(p.name for p in out.iterdir() if p.name != "fit.json")
    report = json.loads((out / "report.json").read_text())
    assert "lobe_error_maps" not in report and "cell_error_maps" not in report
    assert report["lobe_error"]["pbrkit"]["median"] == pytest.approx(float(np.median(lobe)), rel=1e-5)
    assert "- pbrkit: lobe error median" in (out / "report.md").read_text()


def test_write_fit_puts_both_tables_side_by_side(tmp_path, bundled):
    """With a published map of the same size, both lobe-error files are written and
    listed, and report.png (two rows, two columns) is the same bytes twice."""
    from pbrkit.ltc.report import write_fit

    ltc1, ltc2 = bundled
    small1 = np.ascontiguousarray(ltc1[::9, ::9]).astype(np.float32)
    small2 = np.ascontiguousarray(ltc2[::9, ::9]).astype(np.float32)
    fit = SimpleNamespace(ltc1=small1, ltc2=small2, error=np.full((8, 8), 0.01), polygons=4, seed=0)
    lobe_maps = {"pbrkit": lobe_error_map(small1, samples=256),
                 "published": lobe_error_map(np.tile([1.0, 0.0, 0.0, 1.0], (8, 8, 1)), samples=256)}
    score = {"relative_median": 0.1, "relative_mean": 0.1, "relative_p95": 0.2, "abs_over_albedo_mean": 0.01}
    report = {"test_set": {"lights": 4, "seed": 0}, "brdf": {"distribution": "ggx", "masking": "height-correlated"},
              "scores": {"pbrkit": {"F=1": score}, "published": {"F=1": score}},
              "lobe_error": {name: lobe_error_summary(m) for name, m in lobe_maps.items()},
              "cell_error_maps": {"pbrkit": fit.error, "published": 2 * fit.error}, "lobe_error_maps": lobe_maps}
    pngs = []
    for name in ("a", "b"):
        folder = tmp_path / name
        folder.mkdir()
        write_fit(folder, fit, report)
        pngs.append((folder / "report.png").read_bytes())
        for table, m in lobe_maps.items():
            np.testing.assert_array_equal(np.load(folder / f"lobe_error_{table}.npy"), m.astype(np.float32))
        files = json.loads((folder / "fit.json").read_text())["files"]
        assert {"lobe_error_pbrkit.npy", "lobe_error_published.npy"} <= set(files)
        md = (folder / "report.md").read_text()
        assert "- pbrkit: lobe error median" in md and "- published: lobe error median" in md
    assert pngs[0] == pngs[1]
