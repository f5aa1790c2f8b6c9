"""Benchmark: LTC tables scored against ground truth on the two mixed test sets
of :mod:`pbrkit.ltc.lights`, the one ``pbrkit ltc``'s default was chosen on
(:data:`~pbrkit.ltc.lights.TUNING_SET`) and the one it is reported on
(:data:`~pbrkit.ltc.lights.REPORT_SET`).

    python bench/ltc.py [--three PATH] [--table NAME=DIR ...] [--fit F0[,F0...] ...]
                        [--size 64] [--polygons 64] [--distribution ggx|beckmann] [--masking ...]

Scores, per set, pooled over its lights (each with its own f0) and per f0: the
relative errors |ltc - ref| / ref (lights with ref > 1e-3 E(n.v, r)) as median /
mean / 95th percentile, and the mean absolute error over the directional albedo:

- the published table (Heitz, Dupuy, Hill, Neubelt 2016, as three.js ships it:
  ``LTC_MAT_1`` / ``LTC_MAT_2`` of ``RectAreaLightTexturesLib.js``), read from
  ``--three`` (the file, three's package or a node_modules folder; default the
  pinned npm three of ``tests/engines``, ``npm ci --prefix tests/engines``),
  evaluated as three.js's shader does (sphere clipping);
- each ``--table NAME=DIR``: a folder ``pbrkit ltc -o DIR`` wrote (ltc_1.npy,
  ltc_2.npy, fit.json), evaluated as its fit.json's clipping says (sphere: the
  shader's; exact: pbrkit's, Fresnel-aware with fresnel_ltc_1.npy);
- each ``--fit F0LIST``: a table fitted here (:func:`pbrkit.ltc.fit.fit_table`,
  ``--size`` / ``--polygons``, the sphere clipping, ``--fit-f0 F0LIST``), timed;
- pbrkit's bundled tables (``pbrkit ltc --clipping exact --fresnel-aware``, what
  ``pbrkit render`` shades area lights with; default lobe only).

The references are the converged integrals of the lobe (GGX with
height-correlated Smith by default: :func:`pbrkit.ltc.reference.lobe_rect_integrals`,
Schlick F).  Without three's package the published table's rows are left out.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from pbrkit.ltc.fit import DISTRIBUTIONS, FIT_F0, MASKINGS
from pbrkit.ltc.lights import REPORT_SET, TUNING_SET
from pbrkit.ltc.published import published_table, published_table_path
from pbrkit.ltc.reference import lobe_codes, lobe_name
from pbrkit.ltc.statistics import RELATIVE_THRESHOLD, score_set, set_integrals

THREE = Path(__file__).resolve().parents[1] / "tests" / "engines" / "node_modules" / "three"
SETS = {"tuning": TUNING_SET, "report": REPORT_SET}


def _cells(s):
    return (f"{100 * s['relative_median']:6.1f}% {100 * s['relative_mean']:6.1f}% {100 * s['relative_p95']:6.1f}% "
            f"{100 * s['abs_over_albedo_mean']:6.2f}%")


def _row(label, s):
    by = "  ".join(f"f0={f:g}: {100 * b['relative_mean']:.1f}%" for f, b in s["by_f0"].items())
    return f"{label:34s} {s['scored']:4d} {_cells(s)}   mean by f0: {by}"


def _f0s(text):
    return tuple(float(x) for x in text.split(","))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--three", default=str(THREE), help="three's package, node_modules or its LTC .js file")
    parser.add_argument("--table", action="append", default=[], metavar="NAME=DIR",
                        help="score a folder pbrkit ltc -o DIR wrote (repeatable)")
    parser.add_argument("--fit", action="append", default=[], metavar="F0[,F0...]",
                        help="fit a table here with these --fit-f0 values and score it (repeatable)")
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--polygons", type=int, default=64)
    parser.add_argument("--distribution", default="ggx", choices=DISTRIBUTIONS)
    parser.add_argument("--masking", default="height-correlated", choices=MASKINGS)
    args = parser.parse_args()
    try:
        lobe_codes(args.distribution, args.masking)
        fits = [_f0s(f) for f in args.fit]
        tables = [item.split("=", 1) for item in args.table]
        if any(len(t) != 2 for t in tables):
            raise ValueError("--table: NAME=DIR")
    except ValueError as exc:
        parser.error(str(exc))
    lobe = {"distribution": args.distribution, "masking": args.masking}
    default_lobe = lobe == {"distribution": "ggx", "masking": "height-correlated"}

    # name -> (ltc1, ltc2, evaluation, fresnel_ltc1)
    candidates = {}
    try:
        t1, t2 = published_table(args.three)
        print(f"published table: {published_table_path(args.three)}")
        candidates["published (three.js)"] = (t1, t2, "shader", None)
    except FileNotFoundError as exc:
        print(f"published table not found ({exc}); left out", file=sys.stderr)
    for name, folder in tables:
        folder = Path(folder)
        info = json.loads((folder / "fit.json").read_text())
        options = info["options"]
        fresnel = np.load(folder / "fresnel_ltc_1.npy") if (folder / "fresnel_ltc_1.npy").is_file() else None
        evaluation = "exact" if options["clipping"] == "exact" else "shader"
        candidates[name] = (np.load(folder / "ltc_1.npy"), np.load(folder / "ltc_2.npy"), evaluation, fresnel)
        print(f"{name}: {folder} (fit-f0 {','.join(f'{f:g}' for f in options['fit_f0'])}, "
              f"clipping {options['clipping']}, size {options['size']}, polygons {options['polygons']}"
              f"{', Fresnel-aware' if fresnel is not None else ''})")
    if fits:
        from pbrkit.ltc.fit import fit_table

        fit_table(4, 4, **lobe)  # compile outside the timing
        for f0s in fits:
            fit = fit_table(args.size, args.polygons, fit_f0=f0s, **lobe)
            label = f"fit-f0 {','.join(f'{f:g}' for f in f0s)}" + (" (default)" if f0s == FIT_F0 else "")
            print(f"{label}: {args.size} x {args.size} cells, {args.polygons} lights a cell, fitted in "
                  f"{fit.seconds:.0f} s on this machine")
            candidates[label] = (fit.ltc1, fit.ltc2, "shader", None)
    if default_lobe:
        from pbrkit.rendering.area_lights import bundled_fresnel_table, bundled_ltc_table

        b1, b2 = bundled_ltc_table()
        candidates["bundled exact + Fresnel (pbrkit)"] = (b1, b2, "exact", bundled_fresnel_table())
    if not candidates:
        parser.error("nothing to score: no published table, --table or --fit")

    print(f"lobe: {lobe_name(**lobe)}; relative errors over lights with ref > {RELATIVE_THRESHOLD:g} x albedo")
    for set_name, spec in SETS.items():
        t0 = time.perf_counter()
        integrals = set_integrals(spec, **lobe)
        lights = integrals[0]
        print(f"\n{set_name} set: {spec['count']} lights, seed {spec['seed']}, f0 "
              f"{', '.join(f'{f:g}' for f in spec['f0'])}; {100 * lights.crossing.mean():.0f}% cross the horizon; "
              f"references in {time.perf_counter() - t0:.1f} s")
        print(f"{'table':34s} {'n':>4s} {'median':>7s} {'mean':>7s} {'p95':>7s} {'abs/E':>7s}")
        for name, (t1, t2, evaluation, fresnel) in candidates.items():
            print(_row(name, score_set(t1, t2, integrals, evaluation, fresnel, **lobe).summary))


if __name__ == "__main__":
    main()
