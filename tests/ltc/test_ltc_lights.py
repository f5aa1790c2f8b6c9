"""The LTC test lights (:mod:`pbrkit.ltc.lights`): deterministic draws, their
distribution, the two mixed sets kept apart."""

import numpy as np
import pytest

from pbrkit.ltc import lights as light_sets


def test_random_rect_lights():
    a = light_sets.random_rect_lights(200, seed=4)
    b = light_sets.random_rect_lights(200, seed=4)
    np.testing.assert_array_equal(a.corners, b.corners)
    assert not np.array_equal(a.corners, light_sets.random_rect_lights(200, seed=5).corners)
    assert len(a) == 200 and a.corners.shape == (200, 4, 3)
    assert a.roughness.min() >= 0.1 and a.roughness.max() <= 1.0
    assert a.nov.min() >= 0.05 and a.nov.max() <= 1.0
    # every light faces the shading point (three.js winding) and is a rectangle of the drawn size
    c = a.corners
    lit = np.cross(c[:, 1] - c[:, 0], c[:, 3] - c[:, 0])
    assert np.all(np.einsum("ij,ij->i", lit, -c[:, 0]) > 0.0)
    np.testing.assert_allclose(np.linalg.norm(c[:, 0] - c[:, 1], axis=1), 2 * a.half_size[:, 0])
    np.testing.assert_allclose(np.linalg.norm(c[:, 2] - c[:, 1], axis=1), 2 * a.half_size[:, 1])
    np.testing.assert_allclose(np.einsum("ij,ij->i", c[:, 0] - c[:, 1], c[:, 2] - c[:, 1]), 0.0, atol=1e-12)
    assert 0.1 < a.crossing.mean() < 0.4
    with pytest.raises(ValueError, match="unknown test-set parameter"):
        light_sets.random_rect_lights(10, seed=0, size=3)




def test_the_tuning_and_report_sets_are_apart_and_cover_the_mix():
    """The set defaults are chosen on and the set they are reported on: other
    seeds and other ranges, deterministic, each f0 on an equal share of the
    lights; the report set holds dielectrics (0.04), 0.5 and metals (1),
    lights straddling the horizon, smooth (r < 0.15) and rough (r > 0.9) lobes,
    small (< 0.1 rad) and large (> 0.8 rad) lights."""
    tune, tune_f0 = light_sets.test_set(light_sets.TUNING_SET)
    report, report_f0 = light_sets.test_set(light_sets.REPORT_SET)
    again, again_f0 = light_sets.test_set(light_sets.REPORT_SET)
    np.testing.assert_array_equal(report.corners, again.corners)
    np.testing.assert_array_equal(report_f0, again_f0)
    assert light_sets.TUNING_SET["seed"] != light_sets.REPORT_SET["seed"]
    assert light_sets.TUNING_SET["ranges"] != light_sets.REPORT_SET["ranges"]
    assert len(tune) == light_sets.TUNING_SET["count"] and len(report) == light_sets.REPORT_SET["count"]
    for f0, values in ((tune_f0, (0.04, 1.0)), (report_f0, (0.04, 0.5, 1.0))):
        assert sorted(set(f0.tolist())) == list(values)
        assert all(np.count_nonzero(f0 == v) == f0.size // len(values) for v in values)
    assert report.crossing.mean() > 0.15
    assert np.any(report.roughness < 0.15) and np.any(report.roughness > 0.9)
    angular = np.arctan(report.half_size / report.distance[:, None]).max(axis=1)
    assert np.any(angular < 0.1) and np.any(angular > 0.8)
    # no light of one set is a light of the other
    assert not np.isin(report.corners[:, 0, 0], tune.corners[:, 0, 0]).any()
