"""The published LTC tables (:mod:`pbrkit.ltc.published`, three.js's npm
package found by the tests, never by the library): layout and norm, scores in
the expected range on a small set, untrusted input, and no default path."""

import re

import numpy as np
import pytest
from published_ltc import THREE, THREE_REASON

from pbrkit.albedo.tables import specular_integrals
from pbrkit.ltc import lights as light_sets
from pbrkit.ltc import statistics
from pbrkit.ltc.published import published_table


@pytest.mark.skipif(THREE_REASON is not None, reason=THREE_REASON or "")
def test_published_table_layout_and_norm():
    """three's LTC_MAT_1 / LTC_MAT_2 as (64, 64, 4) [t, a] arrays: row t = 0 is
    n.v = 1, where M^-1 is diagonal, and the stored norm follows the converged
    directional albedo within the published fit's sampling error (the issue: up
    to 6.6% at grazing)."""
    t1, t2 = published_table(THREE)
    assert t1.shape == t2.shape == (64, 64, 4) and t1.dtype == t2.dtype == np.float32
    np.testing.assert_allclose(t1[0, :, 1:3], 0.0, atol=1e-6)
    a = np.arange(64) / 63.0
    for t in (0, 20, 40, 56):
        nov = 1.0 - (t / 63.0) ** 2
        e = specular_integrals([nov], a[4:], "height-correlated")[:, 0].sum(axis=-1)
        np.testing.assert_allclose(t2[t, 4:, 0], e, rtol=0.07)


@pytest.mark.skipif(THREE_REASON is not None, reason=THREE_REASON or "")
def test_published_table_scores_in_expected_range():
    """On 80 lights of the test set (seed 0) the published table's relative
    errors are in the range bench/ltc.py reports for 400 (median ~10-15%, a
    heavy tail where the LTC gives 0), far from a broken lookup (100%)."""
    lights = light_sets.random_rect_lights(80, seed=0)
    t1, t2 = published_table(THREE)
    result = statistics.score_table(t1, t2, lights, f0=1.0)
    s = result.summary
    assert s["scored"] >= 50
    assert 0.03 < s["relative_median"] < 0.3
    assert 0.1 < s["relative_mean"] < 0.8
    assert 0.001 < s["abs_over_albedo_mean"] < 0.03
    # where the light holds much of the lobe and the view is not grazing, the published fit is good
    near = (result.reference > 0.1 * result.albedo) & (lights.nov > 0.5)
    assert np.count_nonzero(near) >= 5
    assert np.nanmedian(result.relative[near]) < 0.1


def test_published_table_reads_its_file_as_untrusted_input(tmp_path):
    """A path given for the published tables: a device is refused without being read,
    numbers that are not numbers are refused naming the array, never quoting the file."""
    from pbrkit.core.errors import InputError

    link = tmp_path / "RectAreaLightTexturesLib.js"
    link.symlink_to("/dev/zero")
    with pytest.raises(InputError, match="not a regular file"):
        published_table(link)
    bad = tmp_path / "lib.js"
    bad.write_text("const LTC_MAT_1 = [ 1, SECRET, 3 ]; const LTC_MAT_2 = [1];")
    with pytest.raises(ValueError, match="LTC_MAT_1 holds something other than numbers") as caught:
        published_table(bad)
    assert "SECRET" not in str(caught.value)


def test_the_library_names_no_place_for_the_published_tables():
    """The published tables' path is the caller's: the library has no default
    and no library module looks into a node_modules folder or the repository's
    tests (the command line alone picks ``pbrkit ltc --report``'s default)."""
    from pathlib import Path

    import pbrkit
    from pbrkit.ltc.published import published_table_path

    with pytest.raises(TypeError, match="no default"):
        published_table(None)
    with pytest.raises(TypeError, match="no default"):
        published_table_path(None)
    root = Path(pbrkit.__file__).parent
    place = re.compile(r"""["']node_modules|["']tests/engines|tests/engines/node_modules|Path\.cwd\(\)""")
    offenders = [str(f.relative_to(root)) for f in root.rglob("*.py")
                 if f.parts[len(root.parts)] not in ("app", "cli") and place.search(f.read_text(encoding="utf-8"))]
    assert offenders == []


def test_a_folder_without_the_tables_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="looked in"):
        published_table(tmp_path)
