"""Chi-square goodness-of-fit machinery for samplers (functions, not tests).

The method of Mitsuba's ``chi2`` test module and pbrt-v4's sampling tests:
draw many samples, histogram them over a partition of the domain, compute the
expected count of every cell by integrating the claimed pdf over the cell
numerically (here a composite tensor-product Gauss-Legendre rule), pool cells
whose expected count is below 5, and compare with Pearson's statistic.  A
sample landing in a cell whose expected count is exactly 0 fails outright.

Partition: a tensor grid in two coordinates (a, b), e.g. (theta, phi) on the
sphere or (r, phi) on the disk.  Edges are placed at quantiles of the pdf's
own marginals (found on a fine evaluation grid, refined once around the bulk
of the mass), so sharp lobes (alpha = 0.05) are resolved by many cells while
broad ones get a near-uniform grid.  The edges depend only on the pdf, never
on the samples, so the statistic is chi-square distributed under the null
hypothesis.  Known discontinuities of the pdf (the horizon, a support
boundary) are passed as fixed edges so the quadrature stays accurate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

__all__ = [
    "Chi2Result",
    "sidak_alpha",
    "pearson_chi2",
    "cell_integrals",
    "quantile_edges",
    "histogram2d",
    "chi2_test_2d",
    "directions_to_spherical",
    "sphere_chi2_test",
    "disk_chi2_test",
    "hemisphere_chi2_with_failures",
]

_TWO_PI = 2.0 * np.pi


@dataclass
class Chi2Result:
    statistic: float
    dof: int
    p_value: float
    total_probability: float  # integral of the pdf over the whole domain (should be 1)
    n_samples: int
    n_cells: int
    observed: np.ndarray
    expected: np.ndarray

    def __str__(self):
        return (f"chi2 = {self.statistic:.1f}, dof = {self.dof}, p = {self.p_value:.3g}, "
                f"integral of pdf = {self.total_probability:.6f}, cells = {self.n_cells}")


def sidak_alpha(alpha, num_tests):
    """Per-test significance level for a family-wise level ``alpha`` over ``num_tests``
    independent tests (Sidak 1967): 1 - (1 - alpha)^(1 / num_tests)."""
    return 1.0 - (1.0 - alpha) ** (1.0 / num_tests)


def pearson_chi2(observed, expected, min_expected=5.0):
    """Pearson's chi-square test with pooling of low-expectation cells.

    Cells are sorted by expected count; all cells with expected < ``min_expected``
    (and, if their total is still below ``min_expected``, the next smallest
    cells) form one pooled cell.  Returns (statistic, dof, p_value).  Any
    observation in a cell with expected count exactly 0 gives p = 0.
    """
    obs = np.asarray(observed, dtype=np.float64).ravel()
    exp = np.asarray(expected, dtype=np.float64).ravel()
    if np.any((exp <= 0.0) & (obs > 0.0)):
        return np.inf, 0, 0.0
    order = np.argsort(exp, kind="stable")
    obs = obs[order]
    exp = exp[order]
    n_low = int(np.searchsorted(exp, min_expected, side="left"))
    cumulative = np.cumsum(exp)
    if n_low > 0 and cumulative[n_low - 1] < min_expected:
        # extend the pool until it reaches min_expected (or covers everything)
        n_low = min(int(np.searchsorted(cumulative, min_expected, side="left")) + 1, exp.size)
    statistic = 0.0
    bins = 0
    if n_low > 0:
        pool_exp = exp[:n_low].sum()
        pool_obs = obs[:n_low].sum()
        if pool_exp > 0.0:
            statistic += (pool_obs - pool_exp) ** 2 / pool_exp
            bins += 1
    rest_exp = exp[n_low:]
    rest_obs = obs[n_low:]
    statistic += float(np.sum((rest_obs - rest_exp) ** 2 / rest_exp))
    bins += rest_exp.size
    dof = bins - 1
    if dof < 1:
        raise ValueError("too few cells with enough expected samples for a chi-square test")
    return statistic, dof, float(stats.chi2.sf(statistic, dof))


def _composite_rule(edges, nodes, panels):
    """Nodes, weights and owning cell of a composite Gauss-Legendre rule with
    ``panels`` equal panels of ``nodes`` points in every interval of ``edges``."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    edges = np.asarray(edges, dtype=np.float64)
    n_cells = edges.size - 1
    t = np.linspace(0.0, 1.0, panels + 1)
    lo = edges[:-1, None] + (edges[1:] - edges[:-1])[:, None] * t[None, :-1]  # (cells, panels)
    hi = edges[:-1, None] + (edges[1:] - edges[:-1])[:, None] * t[None, 1:]
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    pts = mid[..., None] + half[..., None] * x  # (cells, panels, nodes)
    wts = half[..., None] * w
    return pts.ravel(), wts.ravel(), n_cells, panels * nodes


def cell_integrals(density, edges_a, edges_b, nodes=(16, 16), panels=(3, 3)):
    """Integral of ``density(a, b)`` over every cell of the tensor grid, shape
    (len(edges_a) - 1, len(edges_b) - 1), by a composite tensor-product
    Gauss-Legendre rule (``panels`` sub-intervals of ``nodes`` points per cell
    and axis).  ``density`` must be vectorised and include the Jacobian of
    the coordinates (e.g. pdf * sin(theta) in (theta, phi))."""
    xa, wa, na, ka = _composite_rule(edges_a, nodes[0], panels[0])
    xb, wb, nb, kb = _composite_rule(edges_b, nodes[1], panels[1])
    values = np.broadcast_to(np.asarray(density(xa[:, None], xb[None, :]), dtype=np.float64), (xa.size, xb.size))
    if not np.all(np.isfinite(values)):
        raise AssertionError("the pdf returned NaN or Inf at a quadrature node")
    weighted = values * wa[:, None] * wb[None, :]
    return weighted.reshape(na, ka, nb, kb).sum(axis=(1, 3))


def _marginals(density, bounds_a, bounds_b, grid):
    a = bounds_a[0] + (np.arange(grid[0]) + 0.5) * (bounds_a[1] - bounds_a[0]) / grid[0]
    b = bounds_b[0] + (np.arange(grid[1]) + 0.5) * (bounds_b[1] - bounds_b[0]) / grid[1]
    values = np.broadcast_to(np.asarray(density(a[:, None], b[None, :]), dtype=np.float64), (a.size, b.size))
    values = np.where(np.isfinite(values), np.maximum(values, 0.0), 0.0)
    return a, values.sum(axis=1), b, values.sum(axis=0)


def _quantiles(centres, mass, lo, hi, probabilities):
    """Interpolated quantiles of a histogram with bin ``centres`` spanning [lo, hi]."""
    step = (hi - lo) / centres.size
    edges = np.concatenate([[lo], centres + 0.5 * step])
    cdf = np.concatenate([[0.0], np.cumsum(mass)])
    if cdf[-1] <= 0.0:
        return np.linspace(lo, hi, len(probabilities) + 2)[1:-1]
    cdf /= cdf[-1]
    return np.interp(probabilities, cdf, edges)


def _tail_edges(window, bounds):
    """Edges outside the window at geometrically growing distances (width * (2^k - 1)),
    so that the cells next to a narrow lobe stay narrow where its tail decays."""
    width = max(window[1] - window[0], 1e-6 * (bounds[1] - bounds[0]))
    steps = width * (2.0 ** np.arange(1, 64) - 1.0)
    below = window[0] - steps
    above = window[1] + steps
    return np.concatenate([below[below > bounds[0]], above[above < bounds[1]]])


def quantile_edges(density, bounds_a, bounds_b, bins=(10, 20), fixed_a=(), fixed_b=(), grid=(512, 256),
                   tail=5e-4):
    """Cell edges in a and b at equal-probability quantiles of the density's marginals.

    A first pass on a ``grid`` over the whole domain finds, per axis, the window
    holding all but ``tail`` of the mass at either end; a second pass on a grid
    over that window places edges at the quantiles k / bins (k = 1 .. bins - 1)
    and, to resolve the tails, at 10 * tail and 1 - 10 * tail.  Outside the
    window, edges at geometrically growing distances follow the tails.  The
    domain bounds, the window ends and the ``fixed`` edges (discontinuities of
    the density) are always edges.
    """
    a, ma, b, mb = _marginals(density, bounds_a, bounds_b, grid)
    windows = []
    for centres, mass, bounds in ((a, ma, bounds_a), (b, mb, bounds_b)):
        step = (bounds[1] - bounds[0]) / centres.size
        lo, hi = _quantiles(centres, mass, bounds[0], bounds[1], [tail, 1.0 - tail])
        windows.append((max(bounds[0], lo - 2 * step), min(bounds[1], hi + 2 * step)))
    a, ma, b, mb = _marginals(density, windows[0], windows[1], grid)
    edges = []
    for centres, mass, bounds, window, n, fixed in ((a, ma, bounds_a, windows[0], bins[0], fixed_a),
                                                    (b, mb, bounds_b, windows[1], bins[1], fixed_b)):
        levels = np.concatenate([[10 * tail], np.arange(1, n) / n, [1.0 - 10 * tail]])
        interior = _quantiles(centres, mass, window[0], window[1], levels)
        e = np.concatenate([[bounds[0], bounds[1], window[0], window[1]], interior,
                            _tail_edges(window, bounds), [f for f in fixed if bounds[0] < f < bounds[1]]])
        e = np.unique(e)
        keep = np.concatenate([[True], np.diff(e) > 1e-9 * (bounds[1] - bounds[0])])
        e = e[keep]
        e[-1] = bounds[1]
        edges.append(e)
    return edges[0], edges[1]


def histogram2d(a, b, edges_a, edges_b):
    """Counts of the points (a, b) in the cells of the tensor grid (values outside
    the edges are put in the nearest cell)."""
    na = len(edges_a) - 1
    nb = len(edges_b) - 1
    ia = np.clip(np.searchsorted(edges_a, a, side="right") - 1, 0, na - 1)
    ib = np.clip(np.searchsorted(edges_b, b, side="right") - 1, 0, nb - 1)
    return np.bincount((ia * nb + ib).ravel(), minlength=na * nb).reshape(na, nb)


def chi2_test_2d(a, b, density, bounds_a, bounds_b, bins=(10, 20), fixed_a=(), fixed_b=(), min_expected=5.0,
                 nodes=(16, 16), panels=(3, 3)):
    """Chi-square test of samples with coordinates (a, b) against ``density(a, b)``
    (the pdf with respect to da db, Jacobian included)."""
    a = np.asarray(a, dtype=np.float64).ravel()
    b = np.asarray(b, dtype=np.float64).ravel()
    edges_a, edges_b = quantile_edges(density, bounds_a, bounds_b, bins, fixed_a, fixed_b)
    outside = (a < bounds_a[0]) | (a > bounds_a[1]) | (b < bounds_b[0]) | (b > bounds_b[1]) | ~np.isfinite(a + b)
    if np.any(outside):
        n_cells = (edges_a.size - 1) * (edges_b.size - 1)
        return Chi2Result(np.inf, 0, 0.0, np.nan, a.size, n_cells, np.zeros(0), np.zeros(0))
    probabilities = cell_integrals(density, edges_a, edges_b, nodes, panels)
    observed = histogram2d(a, b, edges_a, edges_b)
    expected = probabilities * a.size
    statistic, dof, p = pearson_chi2(observed, expected, min_expected)
    return Chi2Result(statistic, dof, p, float(probabilities.sum()), a.size, observed.size, observed, expected)


def directions_to_spherical(w):
    """(theta, phi) of unit vectors (..., 3): theta from +z in [0, pi] (by atan2, accurate
    near the poles), phi from +x in [0, 2 pi)."""
    w = np.asarray(w, dtype=np.float64)
    x, y, z = w[..., 0], w[..., 1], w[..., 2]
    theta = np.arctan2(np.hypot(x, y), z)
    phi = np.mod(np.arctan2(y, x), _TWO_PI)
    return theta, phi


def sphere_chi2_test(directions, pdf, bins=(10, 20), fixed_theta=(), **kwargs):
    """Chi-square test of unit ``directions`` (..., 3) against the solid-angle ``pdf(x, y, z)``.

    Cells are in (theta, phi) over the whole sphere; the density integrated is
    pdf * sin(theta).  ``fixed_theta`` lists polar angles where the pdf is
    discontinuous (e.g. pi / 2 for a hemisphere)."""
    theta, phi = directions_to_spherical(directions)

    def density(t, p):
        st = np.sin(t)
        return pdf(st * np.cos(p), st * np.sin(p), np.cos(t)) * st

    return chi2_test_2d(theta, phi, density, (0.0, np.pi), (0.0, _TWO_PI), bins, fixed_theta, (), **kwargs)


def disk_chi2_test(points, pdf, bins=(10, 20), **kwargs):
    """Chi-square test of points (..., 2) on the unit disk against the area ``pdf(x, y)``,
    with cells in (r, phi) and density pdf * r."""
    points = np.asarray(points, dtype=np.float64)
    x, y = points[..., 0], points[..., 1]
    r = np.hypot(x, y)
    phi = np.mod(np.arctan2(y, x), _TWO_PI)

    def density(rr, p):
        return pdf(rr * np.cos(p), rr * np.sin(p)) * rr

    return chi2_test_2d(r, phi, density, (0.0, 1.0), (0.0, _TWO_PI), bins, (), (), **kwargs)


def hemisphere_chi2_with_failures(wi, n_total, pdf):
    """Chi-square test of the successful samples ``wi`` out of ``n_total`` against the
    solid-angle ``pdf(x, y, z)`` over the upper hemisphere, with the failures as one
    more cell (expected n_total (1 - integral of the pdf)).  Returns (p value,
    integral of the pdf, fraction of successful samples)."""
    theta, phi = directions_to_spherical(wi)

    def density(t, p):
        st = np.sin(t)
        return pdf(st * np.cos(p), st * np.sin(p), np.cos(t)) * st

    bounds_t, bounds_p = (0.0, 0.5 * np.pi), (0.0, 2.0 * np.pi)
    edges_t, edges_p = quantile_edges(density, bounds_t, bounds_p, (10, 20))
    probabilities = cell_integrals(density, edges_t, edges_p)
    observed = histogram2d(theta, phi, edges_t, edges_p).ravel()
    integral = float(probabilities.sum())
    observed = np.append(observed, n_total - theta.size)
    expected = np.append(probabilities.ravel(), max(1.0 - integral, 0.0)) * n_total
    _, _, p_value = pearson_chi2(observed, expected)
    return p_value, integral, theta.size / n_total
