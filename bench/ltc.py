"""Benchmark: the published LTC table (Heitz, Dupuy, Hill, Neubelt 2016, as
three.js ships it) scored against ground truth on random rectangular lights.

    python bench/ltc.py [--count 400] [--seed 0] [--seeds 5] [--three PATH]
                        [--fit [--size 64] [--polygons 64]] [--distribution ggx|beckmann] [--masking ...]

Reads ``LTC_MAT_1`` / ``LTC_MAT_2`` from three's npm package
(``tests/engines/node_modules/three``, ``npm ci --prefix tests/engines``, or
``--three``), draws the test set of :func:`pbrkit.ltc.score.random_rect_lights`
(roughness uniform in [0.1, 1], 15% of the lights straddling the horizon),
computes the converged reference of the lobe (GGX with height-correlated Smith
by default, or ``--distribution`` / ``--masking``: :func:`pbrkit.ltc.score.lobe_rect_integrals`;
Schlick F) and the shader's LTC evaluation (three.js's ``LTC_Evaluate``), and
prints:

- the relative errors |ltc - ref| / ref (lights with ref > 1e-3 E(n.v, r))
  as median / mean / 95th percentile, and the mean absolute error over the
  directional albedo, for F = 1 and for f0 = 0.04;
- the same figures for ``--seeds`` other draws of the set, to show how much a
  400-light mean moves from draw to draw;
- the issue's figures for the published table (issue 11: median 8%, mean 29%,
  p95 100%, abs / albedo 1.25%) beside them, and the time taken;
- pbrkit's bundled tables (``pbrkit ltc --clipping exact --fresnel``, what
  ``pbrkit render`` shades area lights with), exact clipping, with one table
  and Fresnel-aware, at f0 = 1, 0.2 and 0.04 (default lobe only);
- with ``--fit``: pbrkit's fit (:func:`pbrkit.ltc.fit.fit_table`, the table
  ``pbrkit ltc`` writes, for the same lobe) timed on this machine, and scored
  on the same sets beside the published table.

Without three's package the published table's rows are left out (with
``--fit``; without it there is nothing to score).  For a lobe other than the
default, the published table (fitted for GGX) is scored against that lobe's
integrals: what using it instead would cost.
"""

from __future__ import annotations

import argparse
import time

from pbrkit.ltc.fit import DISTRIBUTIONS, MASKINGS
from pbrkit.ltc.score import (
    RELATIVE_THRESHOLD,
    lobe_codes,
    lobe_name,
    lobe_rect_integrals,
    published_table,
    published_table_path,
    random_rect_lights,
    score_table,
)

ISSUE = {"relative_median": 0.08, "relative_mean": 0.29, "relative_p95": 1.00, "abs_over_albedo_mean": 0.0125}


def _line(label, s):
    text = (f"{label:34s} {s['scored']:4d} {100 * s['relative_median']:7.1f}% {100 * s['relative_mean']:7.1f}% "
            f"{100 * s['relative_p95']:7.1f}% {100 * s['abs_over_albedo_mean']:8.2f}%")
    if "ltc_zero_share" in s:
        text += f"   (LTC = 0 on {100 * s['ltc_zero_share']:.1f}% of the scored lights)"
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--seeds", type=int, default=5, help="further draws (seeds seed+1 ...) to show the spread")
    parser.add_argument("--three", default=None, help="three's package, node_modules or RectAreaLightTexturesLib.js")
    parser.add_argument("--fit", action="store_true", help="also fit pbrkit's table and score it")
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--polygons", type=int, default=64)
    parser.add_argument("--distribution", default="ggx", choices=DISTRIBUTIONS)
    parser.add_argument("--masking", default="height-correlated", choices=MASKINGS)
    args = parser.parse_args()
    try:
        lobe_codes(args.distribution, args.masking)
    except ValueError as exc:
        parser.error(str(exc))
    lobe = {"distribution": args.distribution, "masking": args.masking}

    try:
        t1, t2 = published_table(args.three)
        print(f"published table: {published_table_path(args.three)}")
    except FileNotFoundError as exc:
        if not args.fit:
            raise
        t1 = t2 = None
        print(f"published table not found ({exc}); scoring pbrkit's fit alone")
    print(f"lobe: {lobe_name(**lobe)}")
    print(f"relative errors over lights with ref > {RELATIVE_THRESHOLD:g} x albedo\n")
    print(f"{'set':34s} {'n':>4s} {'median':>8s} {'mean':>8s} {'p95':>8s} {'abs/E':>9s}")
    if t1 is not None and lobe == {"distribution": "ggx", "masking": "height-correlated"}:
        print(_line("issue 11 (published table)", {"scored": args.count, **ISSUE}))

    lights = random_rect_lights(args.count, args.seed)
    lobe_rect_integrals(lights.nov[:2], lights.roughness[:2], lights.corners[:2], **lobe)  # compile outside
    t0 = time.perf_counter()
    pair = lobe_rect_integrals(lights.nov, lights.roughness, lights.corners, **lobe)
    t_ref = time.perf_counter() - t0
    if t1 is not None:
        for f0 in (1.0, 0.04):
            reference = f0 * pair[:, 0] + (1.0 - f0) * pair[:, 1]
            s = score_table(t1, t2, lights, f0=f0, reference=reference, **lobe).summary
            print(_line(f"seed {args.seed}, F = 1" if f0 == 1.0 else f"seed {args.seed}, f0 = {f0:g}", s))
    if lobe == {"distribution": "ggx", "masking": "height-correlated"}:
        # the tables pbrkit renders area lights with: --clipping exact, and --fresnel's second one
        from pbrkit.rendering.area_lights import bundled_fresnel_table, bundled_ltc_table

        b1, b2 = bundled_ltc_table()
        fc = bundled_fresnel_table()
        for f0 in (1.0, 0.2, 0.04):
            reference = f0 * pair[:, 0] + (1.0 - f0) * pair[:, 1]
            for label, fresnel in (("bundled, exact", None), ("bundled, Fresnel-aware", fc)):
                s = score_table(b1, b2, lights, f0=f0, reference=reference, evaluation="exact",
                                fresnel_ltc1=fresnel, **lobe).summary
                print(_line(f"{label}, f0 = {f0:g}", s))
    print(f"\nreference: {args.count} lights in {t_ref:.2f} s ({1e3 * t_ref / args.count:.1f} ms a light, tol 1e-6)"
          f"; {100 * lights.crossing.mean():.0f}% of the lights cross the horizon\n")

    fit = None
    if args.fit:
        from pbrkit.ltc.fit import fit_table

        fit_table(4, 4, **lobe)  # compile outside the timing
        fit = fit_table(args.size, args.polygons, **lobe)
        print(f"pbrkit fit ({args.distribution}, {args.masking}): {args.size} x {args.size} cells, {args.polygons} "
              f"lights a cell: {fit.seconds:.1f} s on this machine")
        for f0 in (1.0, 0.04):
            reference = f0 * pair[:, 0] + (1.0 - f0) * pair[:, 1]
            s = score_table(fit.ltc1, fit.ltc2, lights, f0=f0, reference=reference, **lobe).summary
            print(_line(f"pbrkit, seed {args.seed}, F = 1" if f0 == 1.0 else f"pbrkit, seed {args.seed}, f0 = {f0:g}",
                        s))
        print()

    rows = []
    for seed in range(args.seed + 1, args.seed + 1 + args.seeds):
        other = random_rect_lights(args.count, seed)
        reference = lobe_rect_integrals(other.nov, other.roughness, other.corners, **lobe)[:, 0]
        if t1 is not None:
            s = score_table(t1, t2, other, f0=1.0, reference=reference, **lobe).summary
            rows.append(s)
            print(_line(f"seed {seed}, F = 1", s))
        if fit is not None:
            print(_line(f"pbrkit, seed {seed}, F = 1", score_table(fit.ltc1, fit.ltc2, other, f0=1.0,
                                                                  reference=reference, **lobe).summary))
    if rows:
        keys = ("relative_median", "relative_mean", "relative_p95", "abs_over_albedo_mean")
        spread = {k: (min(r[k] for r in rows), max(r[k] for r in rows)) for k in keys}
        print("spread over those draws: " + ", ".join(f"{k} {100 * a:.2f}-{100 * b:.2f}%"
                                                        for k, (a, b) in spread.items()))


if __name__ == "__main__":
    main()
