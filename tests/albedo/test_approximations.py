"""The approximations report: each map measures the error it names.

The maps of :func:`pbrkit.albedo.approximations.approximation_errors` and the
figures the user guide prints for them (docs/guide/tables.md) are checked against albedo differences
recomputed here without pbrkit: the GGX, Smith, Schlick-GGX, Fresnel, Karis and
URP formulas of ``tests/support/reference_brdf.py`` (written from the papers),
integrated with the rules of ``tests/support/quadrature.py``, on the report's grid
(texel centres (i + 0.5) / n in n.v and in roughness).
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from reference_brdf import GOLD_ETA_K, RULE, albedo_maps
from typer.testing import CliRunner

from pbrkit.albedo.approximations import COMPARISONS, approximation_errors
from pbrkit.cli import app
from pbrkit.brdf.fresnel import CONDUCTORS

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide" / "tables.md"

# How far pbrkit's maps may be from the reference, per comparison (absolute albedo).
# The reference rule is within 1.4e-6 of much denser rules, 1.7e-4 for URP (see
# reference_brdf.RULE).  pbrkit's side: Karis' maps subtract the split-sum table,
# converged to < 1e-4 (docs/benchmarks.md, bench/lut.py: max error 7.2e-5); the other maps are
# differences of two furnace quadratures, each converged to 1e-4 (docs/guide/tables.md, `pbrkit
# furnace`); URP's kinked term uses more nodes there and gets the same 1e-4 budget
# on top of the reference's 1.7e-4.  Measured: <= 6.6e-5 (Karis), <= 1.4e-6 (the
# Fresnel and masking maps), <= 1.6e-4 (URP).
MAP_TOLERANCE = {name: 2e-4 for name in (c.name for c in COMPARISONS)}
MAP_TOLERANCE.update({"urp-vs-ggx-f1": 5e-4, "urp-vs-ggx-f004": 5e-4})
# Accuracy of the reference's own max / mean (bounded by its worst cell).
REFERENCE_ACCURACY = {name: 1e-5 for name in MAP_TOLERANCE}
REFERENCE_ACCURACY.update({"urp-vs-ggx-f1": 2e-4, "urp-vs-ggx-f004": 2e-5})

# The guide table's rows (matched by a phrase of the first column) -> the report's
# comparisons, in the order of the " / "-separated figures.
TABLE_ROWS = {
    "EnvBRDFApprox": ("karis-env-brdf-a", "karis-env-brdf-b"),
    "SG Fresnel": ("ue4-sg-vs-schlick",),
    "pow4 vs pow5": ("pow4-vs-pow5",),
    "Schlick vs exact": ("schlick-vs-exact-dielectric", "schlick-vs-exact-gold"),
    "Schlick-GGX": ("schlick-ggx-ibl-vs-smith", "schlick-ggx-ue4-vs-smith"),
    "URP mobile": ("urp-vs-ggx-f1", "urp-vs-ggx-f004"),
}
COMPARISONS_IN_TABLE = tuple(name for names in TABLE_ROWS.values() for name in names)


def guide_table():
    """(grid size, {comparison: (max text, mean text)}) from the guide's `pbrkit approximations` table."""
    section = GUIDE.read_text().split("## The approximations report", 1)[1].split("\n## ", 1)[0]
    section = section.split("\n### ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("|")]
    header = [c.strip() for c in rows[0].strip("|").split("|")]
    grid = re.search(r"\b(\d+)\^2 grid", header[0])
    assert grid and "max" in header[1] and "mean" in header[2], header
    figures = {}
    for line in rows[2:]:
        label, max_text, mean_text = (c.strip() for c in line.strip("|").split("|"))
        keys = [k for k in TABLE_ROWS if k in label]
        assert len(keys) == 1, f"table row {label!r} matches {keys} (update TABLE_ROWS)"
        names = TABLE_ROWS[keys[0]]
        maxima, means = max_text.split(" / "), mean_text.split(" / ")
        assert len(maxima) == len(means) == len(names), label
        for name, mx, mn in zip(names, maxima, means):
            assert name not in figures, f"{name} listed twice"
            figures[name] = (mx.strip(), mn.strip())
    return int(grid.group(1)), figures


def assert_printed(value, text, accuracy, what):
    """``text`` is ``value`` rounded to the decimals printed, up to the reference's accuracy."""
    half_unit = 0.5 * 10.0 ** -len(text.partition(".")[2])
    assert abs(value - float(text)) <= half_unit + accuracy, f"{what}: guide {text}, independent {value:.6f}"


@pytest.fixture(scope="module")
def errors():
    return approximation_errors(8)


@pytest.fixture(scope="module")
def guide_grid_reference():
    n, _ = guide_table()
    return n, albedo_maps(n, RULE)


def test_every_comparison_is_present_and_finite(errors):
    assert set(errors) == {c.name for c in COMPARISONS}
    for name, e in errors.items():
        assert e.shape == (8, 8) and np.all(np.isfinite(e)), name


def test_known_signs_and_sizes(errors):
    # pow4 decays slower than pow5, so it always reflects more.
    assert np.all(errors["pow4-vs-pow5"] >= -1e-9)
    # Schlick-GGX with k = alpha / 2 never exceeds exact Smith G1 (helper-checked bound).
    assert np.all(errors["schlick-ggx-ibl-vs-smith"] <= 1e-9)
    # UE4's SG Fresnel is a close fit to pow5: a few 1e-3 in albedo at most.
    assert np.abs(errors["ue4-sg-vs-schlick"]).max() < 5e-3
    # URP's specular doubles the albedo of a near-mirror (2 / (1 + 2 alpha) vs 1).
    assert errors["urp-vs-ggx-f1"][0, -1] > 0.8
    # Compensation only adds energy, most where roughness is high.
    c = errors["compensated-vs-single"]
    assert np.all(c >= -1e-9) and c[-1].max() > 0.5


def test_reference_gold_is_the_reports_gold():
    # The same complex IOR data on both sides (the formulas are independent, the metal is not).
    assert np.array_equal(np.asarray(CONDUCTORS["gold"]), np.asarray(GOLD_ETA_K))


def test_error_maps_match_independent_quadrature(errors):
    """Every map of the guide's table on the 8 x 8 texel grid, cell by cell."""
    reference = albedo_maps(8, RULE)
    assert set(reference) == set(COMPARISONS_IN_TABLE)
    for name, ref in reference.items():
        worst = np.abs(errors[name] - ref).max()
        assert worst <= MAP_TOLERANCE[name], f"{name}: |pbrkit - reference| up to {worst:.2e}"
    # The maps are not trivially small: the test compares errors of visible size.
    assert min(np.abs(ref).max() for ref in reference.values()) > 1e-3


def test_guide_table_covers_the_report():
    n, figures = guide_table()
    assert n == 32
    assert set(figures) == set(COMPARISONS_IN_TABLE)
    assert set(COMPARISONS_IN_TABLE) == {c.name for c in COMPARISONS} - {"compensated-vs-single"}


@pytest.mark.slow
def test_guide_figures_match_independent_quadrature(guide_grid_reference):
    """The guide's max / mean absolute errors are the independent ones, to the printed digits."""
    _, reference = guide_grid_reference
    _, figures = guide_table()
    for name, (max_text, mean_text) in figures.items():
        e = np.abs(reference[name])
        assert_printed(e.max(), max_text, REFERENCE_ACCURACY[name], f"{name} max")
        assert_printed(e.mean(), mean_text, REFERENCE_ACCURACY[name], f"{name} mean")


@pytest.mark.slow
def test_report_maps_match_independent_quadrature_on_the_guide_grid(guide_grid_reference):
    """The report's own maps on the guide's grid (32 x 32, whose smoothest row sits at
    the alpha = 1e-3 clamp), cell by cell."""
    n, reference = guide_grid_reference
    errors = approximation_errors(n)
    for name, ref in reference.items():
        worst = np.abs(errors[name] - ref).max()
        assert worst <= MAP_TOLERANCE[name], f"{name}: |pbrkit - reference| up to {worst:.2e}"


def test_cli_writes_report(tmp_path):
    n = 6
    result = CliRunner().invoke(app, ["approximations", "-o", str(tmp_path), "--size", str(n), "--quiet"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "approximations.json").read_text())
    assert set(summary["comparisons"]) == {c.name for c in COMPARISONS}
    # The printed figures and the location of each maximum, against the reference.
    reference = albedo_maps(n, RULE)
    axis = (np.arange(n) + 0.5) / n
    for name, ref in reference.items():
        s, tol = summary["comparisons"][name], MAP_TOLERANCE[name]
        assert s["max_abs_error"] == pytest.approx(np.abs(ref).max(), abs=tol), name
        assert s["mean_abs_error"] == pytest.approx(np.abs(ref).mean(), abs=tol), name
        i, j = (int(np.argmin(np.abs(axis - s["at"][key]))) for key in ("nv", "roughness"))
        assert s["at"] == {"nv": pytest.approx(axis[i], abs=1e-12), "roughness": pytest.approx(axis[j], abs=1e-12)}
        assert abs(ref[j, i]) >= np.abs(ref).max() - 2.0 * tol, name  # a maximum (up to near-ties)
        assert s["signed_error_at_max"] == pytest.approx(ref[j, i], abs=tol), name
    assert (tmp_path / "approximations.png").read_bytes()[:4] == b"\x89PNG"
    bad = CliRunner().invoke(app, ["approximations", "-o", str(tmp_path / "x"), "--size", "1"])
    assert bad.exit_code == 1 and not (tmp_path / "x").exists()
