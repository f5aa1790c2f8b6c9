"""The files of ``pbrkit ltc``: a fitted table in the published layout, its
per-cell fit error, and with ``--report`` the scores of pbrkit's table and of the
published one (Heitz et al. 2016, as three.js ships it) on the same test set with
the same shader evaluation (:mod:`pbrkit.ltc.statistics`), and two kinds of per-cell
error maps side by side: the polygon-integral error on the fit's lights
(:func:`pbrkit.ltc.fit.cell_errors`) and the lobe error, how far each cell's LTC
is from the BRDF lobe it approximates, by Monte Carlo
(:func:`pbrkit.ltc.lobe_error.lobe_error_map`)."""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["FORMAT", "TEST_LIGHTS", "score_fit", "write_fit"]

FORMAT = "pbrkit LTC fit"
#: Lights of the report's test set (:func:`pbrkit.ltc.lights.random_rect_lights`, seed 0).
TEST_LIGHTS = 400


def _round(summary):
    return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in summary.items()}


def _lobe(fit):
    return getattr(fit, "distribution", "ggx"), getattr(fit, "masking", "height-correlated")


def score_fit(fit, published=None, lights=TEST_LIGHTS, seed=0, fresnel=None):
    """Scores (:func:`pbrkit.ltc.statistics.score_table`, F = 1 and f0 = 0.04 on
    ``lights`` of the test set, and the mixes of metals and dielectrics of the
    tuning and report sets, :func:`pbrkit.ltc.statistics.score_set`, labelled
    ``tuning mix`` / ``report mix``) of the fit
    and, given ``published`` = (ltc1, ltc2), of that table on the same lights,
    both against the converged integrals of the lobe the fit is for
    (``fit.distribution``, ``fit.masking``; the published table is GGX's, so for
    another lobe its score says what using it instead would cost); and the
    published table's per-cell error on the fit's own lights
    (:func:`pbrkit.ltc.fit.cell_errors`, when the sizes match).  With ``fresnel``
    (the fit of the f Fc lobe, ``pbrkit ltc --fresnel-aware``) pbrkit's Fresnel-aware
    evaluation (:func:`pbrkit.ltc.shader.ltc_fresnel_rect`) is scored too, as
    ``pbrkit, Fresnel-aware``.

    ``lobe_error_maps``: the per-cell lobe error (N, N) of pbrkit's table and,
    when given and the sizes match, of the published one
    (:func:`pbrkit.ltc.lobe_error.lobe_error_map`: relative L2 distance between
    the LTC and the lobe f cos / E over the sphere, by Monte Carlo, against the
    fit's lobe with E = the fit's ``ltc_2`` norm, its converged albedo, for both
    tables), and ``lobe_error`` their summaries (median, p95, max) and how they
    were computed."""
    from .fit import cell_errors
    from .lobe_error import SAMPLES, lobe_error_map, lobe_error_summary
    from .lights import random_rect_lights
    from .reference import lobe_rect_integrals
    from .lights import REPORT_SET, TUNING_SET
    from .statistics import score_set, score_table, set_integrals

    distribution, masking = _lobe(fit)
    mixes = {"tuning mix": set_integrals(TUNING_SET, distribution, masking),
             "report mix": set_integrals(REPORT_SET, distribution, masking)}
    test = random_rect_lights(lights, seed)
    pair = lobe_rect_integrals(test.nov, test.roughness, test.corners, distribution, masking)
    tables = {"pbrkit": (fit.ltc1, fit.ltc2, None)}
    if fresnel is not None:
        tables["pbrkit, Fresnel-aware"] = (fit.ltc1, fit.ltc2, fresnel.ltc1)
    if published is not None:
        tables["published"] = (*published, None)
    scores = {}
    for name, (t1, t2, fresnel1) in tables.items():
        scores[name] = {}
        own = name.startswith("pbrkit") and getattr(fit, "clipping", "sphere") == "exact"
        evaluation = "exact" if own else "shader"
        for label, f0 in (("F=1", 1.0), ("f0=0.04", 0.04)):
            ref = f0 * pair[:, 0] + (1.0 - f0) * pair[:, 1]
            scores[name][label] = _round(score_table(t1, t2, test, f0=f0, reference=ref, evaluation=evaluation,
                                                     distribution=distribution, masking=masking,
                                                     fresnel_ltc1=fresnel1).summary)
        for label, integrals in mixes.items():
            summary = score_set(t1, t2, integrals, evaluation, fresnel1, distribution, masking).summary
            by_f0 = {f"{f:g}": _round(s) for f, s in summary.pop("by_f0").items()}
            scores[name][label] = {**_round(summary), "by_f0": by_f0}
    maps = {"pbrkit": fit.error}
    if fresnel is not None:
        maps["pbrkit f Fc lobe"] = fresnel.error
    if published is not None and np.shape(published[0])[:2] == fit.ltc1.shape[:2]:
        maps["published"] = cell_errors(fit, published[0])
    albedo = np.asarray(fit.ltc2, dtype=np.float64)[..., 0] if getattr(fit, "ltc2", None) is not None else None
    lobe_maps = {"pbrkit": lobe_error_map(fit.ltc1, distribution, masking, albedo=albedo)}
    if published is not None and np.shape(published[0])[:2] == fit.ltc1.shape[:2]:
        lobe_maps["published"] = lobe_error_map(published[0], distribution, masking, albedo=albedo)
    lobe = {"measure": "relative L2 distance over the sphere between the LTC's D and the lobe f cos / E (F = 1), "
                       "sqrt(int (D - f cos / E)^2 / int (f cos / E)^2), per cell",
            "estimator": "Monte Carlo: the same scrambled Sobol points in every cell, from a mixture of the lobe's "
                         "VNDF sampling, the LTC and the uniform sphere (pbrkit.ltc.lobe_error.lobe_error_map)",
            "samples": SAMPLES, "seed": 0}
    lobe.update({name: lobe_error_summary(m) for name, m in lobe_maps.items()})
    sets = {label: {"lights": spec["count"], "seed": spec["seed"], "f0": list(spec["f0"])}
            for label, spec in (("tuning mix", TUNING_SET), ("report mix", REPORT_SET))}
    return {"test_set": {"lights": int(lights), "seed": int(seed), "generator": "pbrkit.ltc.lights.random_rect_lights",
                         "mixes": sets},
            "brdf": {"distribution": distribution, "masking": masking},
            "scores": scores, "lobe_error": lobe, "cell_error_maps": maps, "lobe_error_maps": lobe_maps}


#: The report's maps: the keys of :func:`score_fit`'s dict, each plotted as a row.
_MAP_KINDS = ("cell_error_maps", "lobe_error_maps")


def _plot(path, maps, lobe_maps=None):
    """report.png: a row of polygon-integral error maps (``maps``, linear colours up
    to the 99th percentile) and, with ``lobe_maps``, a row of lobe-error maps
    (logarithmic colours from 1e-3: the error spans 1e-3 for smooth symmetric
    cells to over 10 where an LTC is far sharper than its lobe), one column per
    table, the same table in the same column.  Deterministic (no metadata)."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    rows = [maps] + ([lobe_maps] if lobe_maps else [])
    names = list(maps) + [k for k in (lobe_maps or {}) if k not in maps]
    fig, axes = plt.subplots(len(rows), len(names), figsize=(4.2 * len(names), 3.6 * len(rows)), squeeze=False)
    top = max(float(np.percentile(m, 99)) for m in maps.values())
    if lobe_maps:
        high = max(float(np.max(m)) for m in lobe_maps.values())
        lobe_norm = LogNorm(vmin=1e-3, vmax=10.0 ** max(0, math.ceil(math.log10(max(high, 1e-3)))))
    for row, kind in enumerate(rows):
        for col, name in enumerate(names):
            ax = axes[row, col]
            if name not in kind:
                ax.axis("off")
                continue
            m = np.asarray(kind[name], dtype=np.float64)
            if row == 0:
                im = ax.imshow(m, origin="lower", vmin=0.0, vmax=top, cmap="magma", extent=(0, 1, 0, 1))
                ax.set_title(f"{name}: median {np.median(m):.3f}", fontsize=9)
            else:
                im = ax.imshow(np.maximum(m, 1e-3), origin="lower", norm=lobe_norm, cmap="viridis",
                               extent=(0, 1, 0, 1))
                ax.set_title(f"{name}: lobe error median {np.median(m):.3f}, p95 {np.percentile(m, 95):.3f}",
                             fontsize=9)
            ax.set_xlabel("roughness a / (N - 1)")
            ax.set_ylabel("sqrt(1 - cos theta_v)")
            fig.colorbar(im, ax=ax, fraction=0.046)
    title = ["per-cell RMS error of polygon integrals (relative, floor 1% of albedo)"]
    if lobe_maps:
        title = ["top: " + title[0], "bottom: per-cell lobe error, relative L2 distance between the LTC and "
                 "f cos / E over the sphere (Monte Carlo; log scale)"]
    width = 50 * len(names)  # characters that fit above the columns at fontsize 9
    fig.suptitle("\n".join(textwrap.fill(line, width) for line in title), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90, metadata={"Software": None})
    plt.close(fig)


def write_fit(folder, fit, report=None, fresnel=None):
    """Write the fit into ``folder`` (an existing, empty temporary directory of
    :func:`pbrkit.core.atomic.atomic_directory`): the drop-in tables
    (:func:`pbrkit.io.ltc_files.write_ltc_tables`), ``fit_error.npy`` (float32
    (N, N)), ``fit.json`` (options, layout, error summary; no timings, so the
    same options give the same bytes) and, with ``report`` (:func:`score_fit`),
    ``report.json``, ``report.md`` and ``report.png`` (summaries in the JSON, the
    maps in the picture), and the lobe-error maps as ``lobe_error_pbrkit.npy`` /
    ``lobe_error_published.npy`` (float32 (N, N)); with ``fresnel`` (the fit of
    the f Fc lobe) its matrices as ``fresnel_ltc_1.*``
    (:func:`pbrkit.io.ltc_files.write_fresnel_table`) and its error in ``fit.json``."""
    from pathlib import Path

    from ..io.ltc_files import (
        FRESNEL_FILES,
        LTC_FILES,
        write_fresnel_table,
        write_ltc_tables,
    )
    from .fit import EPSILON, MAX_THETA
    from .reference import lobe_name

    folder = Path(folder)
    n = fit.ltc1.shape[0]
    distribution, masking = _lobe(fit)
    f0s = [float(f) for f in getattr(fit, "fit_f0", (1.0,))]
    clipping = getattr(fit, "clipping", "sphere")
    weights = "F = 1" if f0s == [1.0] else "Schlick F of f0 = " + ", ".join(f"{f:g}" for f in f0s)
    command = (f"pbrkit ltc --size {n} --polygons {fit.polygons} --seed {fit.seed} --fit-f0 "
               f"{','.join(f'{f:g}' for f in f0s)} --clipping {clipping} --distribution {distribution} "
               f"--masking {masking}")
    write_ltc_tables(folder, fit.ltc1, fit.ltc2, note=f"fitted by pbrkit ({command})",
                     brdf=f"{lobe_name(distribution, masking)} (cook_torrance; matrices fitted at {weights}; "
                          "Schlick F by ltc_2)")
    np.save(folder / "fit_error.npy", fit.error.astype(np.float32), allow_pickle=False)
    info = {
        "format": FORMAT,
        "options": {"size": n, "polygons": int(fit.polygons), "seed": int(fit.seed), "epsilon": EPSILON,
                    "fit_f0": f0s, "clipping": clipping, "distribution": distribution, "masking": masking},
        "brdf": {"distribution": distribution, "masking": masking,
                 "roughness": "alpha = r^2 (pbrkit.brdf.distributions.alpha_from_roughness: at least 1e-3), for "
                              "GGX and Beckmann alike",
                 "lobe": f"{lobe_name(distribution, masking)}, matrices fitted at {weights}; Schlick F through ltc_2 "
                         "(norm, fresnel)"},
        "layout": {"ltc_1": "(m00, m20, m02, m22) / m11 of M^-1, row t, column a",
                   "ltc_2": "(norm = A + B, fresnel = B, 0, sphere form factor)",
                   "column": f"perceptual roughness a / {n - 1}, alpha = r^2",
                   "row": f"sqrt(1 - cos theta_v) = t / {n - 1} (theta_v at most {math.degrees(MAX_THETA):.2f} deg)",
                   "sampling": "texel centres: uv = p (N - 1) / N + 0.5 / N, bilinear"},
        "fit_error": {"median": round(float(np.median(fit.error)), 6),
                      "p95": round(float(np.percentile(fit.error, 95)), 6),
                      "max": round(float(np.max(fit.error)), 6)},
        "files": list(LTC_FILES) + ["fit_error.npy"],
    }
    if fresnel is not None:
        write_fresnel_table(folder, fresnel.ltc1)
        info["fresnel"] = {
            "lobe": "f Fc, Fc = (1 - v.h)^5 (the Schlick F's second lobe: f F = f0 f + (1 - f0) f Fc), fitted as "
                    "--fit-f0 0 with the exact clipping; evaluated by pbrkit.ltc.shader.ltc_fresnel_rect",
            "fit_error": {"median": round(float(np.median(fresnel.error)), 6),
                          "p95": round(float(np.percentile(fresnel.error, 95)), 6),
                          "max": round(float(np.max(fresnel.error)), 6)}}
        info["files"] += list(FRESNEL_FILES)
    if report is not None:
        (folder / "report.json").write_text(json.dumps(
            {k: v for k, v in report.items() if k not in _MAP_KINDS}, indent=2) + "\n", encoding="utf-8")
        lobe_maps = report.get("lobe_error_maps") or {}
        for name, m in lobe_maps.items():
            np.save(folder / f"lobe_error_{name}.npy", np.asarray(m, dtype=np.float32), allow_pickle=False)
        lines = ["# LTC tables: pbrkit's fit and the published one", "",
                 f"Test set: {report['test_set']['lights']} rectangular lights (seed {report['test_set']['seed']}), "
                 "scored with three.js's shader evaluation against converged integrals of the lobe the table is "
                 f"fitted for: {lobe_name(distribution, masking)}.", "",
                 "Mixes: the tuning set (pbrkit.ltc.lights.TUNING_SET, f0 = 0.04 and 1, what pbrkit ltc's "
                 "default was chosen on) and the report set (REPORT_SET, f0 = 0.04, 0.5 and 1, other seed and "
                 "ranges), each light with its own f0.", "",
                 "| table | lights | median | mean | p95 | abs. error / albedo |", "|---|---|---|---|---|---|"]
        for name, by_f in report["scores"].items():
            for label, s in by_f.items():
                lines.append(f"| {name} | {label} | {100 * s['relative_median']:.1f}% | "
                             f"{100 * s['relative_mean']:.1f}% | {100 * s['relative_p95']:.1f}% | "
                             f"{100 * s['abs_over_albedo_mean']:.2f}% |")
        if lobe_maps:
            lines += ["", ("Lobe error per cell: the relative L2 distance over the sphere between the LTC and the lobe "
                           "f cos / E it approximates (F = 1), by Monte Carlo (pbrkit.ltc.lobe_error; 0 is exact, "
                           "1 or more where the two do not overlap)."), ""]
            for name in lobe_maps:
                s = report["lobe_error"][name]
                lines.append(f"- {name}: lobe error median {s['median']:.4f}, p95 {s['p95']:.4f}")
        (folder / "report.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
        _plot(folder / "report.png", report["cell_error_maps"], lobe_maps)
        info["files"] += ["report.json", "report.md", "report.png"] + [f"lobe_error_{name}.npy" for name in lobe_maps]
    (folder / "fit.json").write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")
    return folder
