"""The approximations report: each map measures the error it names."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.albedo.approximations import COMPARISONS, approximation_errors
from pbrkit.app.cli import app


@pytest.fixture(scope="module")
def errors():
    return approximation_errors(8)


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


def test_cli_writes_report(tmp_path):
    result = CliRunner().invoke(app, ["approximations", "-o", str(tmp_path), "--size", "6", "--quiet"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "approximations.json").read_text())
    assert set(summary["comparisons"]) == {c.name for c in COMPARISONS}
    assert (tmp_path / "approximations.png").read_bytes()[:4] == b"\x89PNG"
    bad = CliRunner().invoke(app, ["approximations", "-o", str(tmp_path / "x"), "--size", "1"])
    assert bad.exit_code == 1 and not (tmp_path / "x").exists()
