"""Benchmark: the time of every view of ``pbrkit explore`` (the data of
:mod:`pbrkit.explore.views`, and the app's update of each group of plots), at the
default sizes, against the issue's goal of "well under 100 ms" per update.

    python bench/explore.py [--repeat 15] [--models disney,gltf,cook_torrance] [--app]

For each model: the median and best of ``repeat`` calls of each view after a
warm-up call (Numba's kernels compiled and cached, the environment baked), with
the compiled kernels on one thread (what the app and ``--static`` use,
:func:`pbrkit.explore.views.view_threads`) and on Numba's default count, whose
ratio shows what thread launches cost on this machine (they dominate on a loaded
two-core machine).  ``--app`` also times the Panel application's update of each
group of plots after a slider move (views plus the ColumnDataSource updates,
:attr:`pbrkit.explore.app.Explorer.timings`), without a browser.  A measured
BRDF (a MERL table sampled from GGX, :func:`pbrkit.measured.merl.merl_table`) is
timed too; its albedo and environment sphere are computed once per BRDF and
cached (the first call is reported as ``first``).
"""

from __future__ import annotations

import argparse
import math
import time

import numba
import numpy as np
from _timing import best_and_median

from pbrkit.explore import views as V

VIEWS = {
    "incidence_plane": lambda b: V.incidence_plane(b, math.radians(45.0)),
    "lobe_3d": lambda b: V.lobe_3d(b, math.radians(45.0)),
    "theta_h_slice": lambda b: V.theta_h_slice(b, math.radians(30.0)),
    "theta_d_slice": lambda b: V.theta_d_slice(b, 0.0),
    "half_diff_image": lambda b: V.half_diff_image(b),
    "directional_albedo": lambda b: V.directional_albedo(b),
    "lit_sphere_point": lambda b: V.lit_sphere_point(b, math.radians(45.0), math.radians(135.0)),
    "lit_sphere_environment": lambda b: V.lit_sphere_environment(b),
    "terms": lambda b: V.terms(b, math.radians(45.0)),
}


def time_views(brdf, repeat, threads):
    rows = {}
    with V.view_threads(threads):
        for name, fn in VIEWS.items():
            fn(brdf)  # warm-up: compile, bake, fill caches
            best, median = best_and_median(lambda fn=fn: fn(brdf), repeat)
            rows[name] = (best, median)
    return rows


def time_albedo_uncached(brdf, repeat):
    """directional_albedo with its roughness-dependent curves recomputed (a roughness slider move)."""
    def run():
        V._white_albedo.cache_clear()
        V._compensated_albedo.cache_clear()
        V.directional_albedo(brdf)

    with V.view_threads(1):
        run()
        return best_and_median(run, repeat)


def time_app(model, repeat):
    from pbrkit.explore.app import Explorer

    e = Explorer(model=model, roughness=0.4, second="filament")
    moves = {"roughness": e.params["roughness"], "base colour R": e.base[0], "theta_v": e.theta_v,
             "theta_d": e.theta_d, "theta_l (light)": e.light_theta, "phi_v": e.phi_v}
    out = {}
    for name, widget in moves.items():
        totals = []
        groups = {}
        for k in range(repeat):
            lo, hi = widget.start, widget.end
            widget.value = lo + (hi - lo) * (0.2 + 0.6 * ((k * 0.37) % 1.0))
            totals.append(sum(e.timings.values()) if name in ("roughness", "base colour R") else
                          sum(e.timings[g] for g in e.DEPENDS[_group_of(e, widget)]))
            for g, t in e.timings.items():
                groups.setdefault(g, []).append(t)
        out[name] = (float(np.median(totals)), {g: float(np.median(t)) for g, t in groups.items()})
        e.timings.clear()
    return out


def _group_of(e, widget):
    for group, widgets in (("plane", [e.theta_v]), ("lobe", [e.phi_v]), ("slices", [e.theta_d]),
                           ("spheres", [e.light_theta])):
        if widget in widgets:
            return group
    return "all"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--models", default="disney,gltf,cook_torrance")
    parser.add_argument("--app", action="store_true", help="also time the Panel app's updates")
    args = parser.parse_args()
    print(f"Numba threads: {numba.config.NUMBA_NUM_THREADS} ; "
          f"times in ms, median (best) of {args.repeat}")
    brdfs = {m: V.model_brdf(m, (0.8, 0.4, 0.2), 0.0, 0.4, **({"clearcoat": 0.5} if m == "disney" else {}))
             for m in args.models.split(",")}
    for name, brdf in brdfs.items():
        one = time_views(brdf, args.repeat, 1)
        many = time_views(brdf, args.repeat, numba.config.NUMBA_NUM_THREADS)
        print(f"\n{name}")
        print(f"  {'view':24s} {'1 thread':>18s} {'default threads':>18s} {'ratio':>7s}")
        for view in VIEWS:
            b1, m1 = one[view]
            bn, mn = many[view]
            print(f"  {view:24s} {1e3 * m1:9.2f} ({1e3 * b1:6.2f}) {1e3 * mn:9.2f} ({1e3 * bn:6.2f}) "
                  f"{mn / max(m1, 1e-12):7.2f}")
        b, m = time_albedo_uncached(brdf, max(3, args.repeat // 3))
        print(f"  {'albedo, new roughness':24s} {1e3 * m:9.2f} ({1e3 * b:6.2f})")

    from pbrkit.measured.merl import MerlBRDF, merl_table

    ggx = V.model_brdf("cook_torrance", (0.6, 0.3, 0.2), 0.0, 0.3, diffuse="lambert")
    measured = MerlBRDF(merl_table(lambda l, v, n: ggx.evaluate(l, v, n)), "ggx-table")
    print("\nmeasured (MERL table of cook_torrance GGX, r = 0.3)")
    with V.view_threads(1):
        for view in ("directional_albedo", "lit_sphere_environment"):
            t0 = time.perf_counter()
            VIEWS[view](measured)
            print(f"  {view:24s} first {time.perf_counter() - t0:.2f} s (cached afterwards)")
    one = time_views(measured, args.repeat, 1)
    for view in VIEWS:
        if view in ("terms",):
            continue
        b1, m1 = one[view]
        print(f"  {view:24s} {1e3 * m1:9.2f} ({1e3 * b1:6.2f})")

    if args.app:
        print("\napp updates after a slider move (views + ColumnDataSource updates), median ms; A disney, B filament")
        for name, (total, groups) in time_app("disney", max(5, args.repeat // 2)).items():
            detail = ", ".join(f"{g} {1e3 * t:.1f}" for g, t in sorted(groups.items()))
            print(f"  {name:18s} {1e3 * total:8.1f}   ({detail})")


if __name__ == "__main__":
    main()
