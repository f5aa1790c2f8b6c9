"""``pbrkit ltc``: LTC tables for polygonal area lights (:func:`pbrkit.ltc.fit.fit_table`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import typer

from ..choices import LTC_CLIPPINGS, LTC_FIT_F0
from .console import _Stages, user_errors
from .options import OUT_DIR, _choice, _flag, _quiet_option, _seed_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Fit LTC tables for polygonal area lights, in the layout engines load."
#: The example ``pbrkit ltc --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit ltc -o ltc --size 32 --report"


@user_errors
def ltc(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    size: int = typer.Option(64, "--size", metavar="N",
                             help="Cells per side (64: the published layout engines load)."),
    polygons: int = typer.Option(64, "--polygons", metavar="K", help="Rectangular lights each cell is fitted on."),
    seed: int = _seed_option("Seed of the lights each cell is fitted on."),
    fit_f0: Optional[str] = typer.Option(
        None, "--fit-f0", metavar="F0[,F0...]",
        help=f"Normal reflectances the fit weighs (Schlick F; default {','.join(f'{f:g}' for f in LTC_FIT_F0)}: a "
             "metal's and a dielectric's, the best drop-in for the mix, bench/ltc.md; 1 with --fresnel-aware): 1 alone "
             "is the lobe without Fresnel (as the published table), better for metals, worse for dielectrics."),
    clipping: str = _choice("sphere", "--clipping", LTC_CLIPPINGS, "clipping",
                            "Horizon clipping the table is fitted for: sphere (the shaders' approximation, what "
                            "engines run: the drop-in table) or exact (pbrkit's own evaluation, "
                            "pbrkit.ltc.shader.ltc_exact_rect; same layout)."),
    distribution: str = _choice("ggx", "--distribution", ("ggx", "beckmann"),  # pbrkit.ltc.reference.LTC_DISTRIBUTIONS
                                "distribution",
                                "Microfacet distribution of the lobe the tables are fitted for: ggx or beckmann "
                                "(cook_torrance's; alpha = r^2 for both)."),
    masking: str = _choice("height-correlated", "--masking",
                           ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4"),  # LTC_MASKINGS
                           "masking",
                           "Smith masking-shadowing G2 of the lobe: height-correlated or separable (exact Smith, "
                           "the distribution's own Lambda), or with ggx only schlick-ggx (k = alpha / 2) or "
                           "schlick-ggx-ue4 (k = (r + 1)^2 / 8)."),
    fresnel: bool = _flag(False, ("--fresnel-aware",),
                          "With --clipping exact: also fit the f Fc lobe's matrices (fresnel_ltc_1.*) for pbrkit's "
                          "Fresnel-aware LTC, f0 norm LTC_1 + (1 - f0) fresnel LTC_Fc "
                          "(pbrkit.ltc.shader.ltc_fresnel_rect), far better for dielectrics; the table pbrkit "
                          "renders with is --clipping exact --fresnel-aware."),
    report: bool = _flag(False, ("--report",),
                         "Also score pbrkit's table and the published one (read from npm three, or --published) "
                         "on the same test set, with per-cell error maps."),
    published: Optional[Path] = typer.Option(
        None, "--published", metavar="FILE",
        help="three.js's RectAreaLightTexturesLib.js or three's package folder (default: ./node_modules/three, "
             "where npm install three puts it, if present)."),
    force: bool = _flag(False, ("--force",), "Replace a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Fit Linearly Transformed Cosines tables (Heitz et al. 2016) for GGX with
    height-correlated Smith (or --distribution / --masking), for the polygon
    integrals a shader computes, and write them in the published layout: ltc_1 /
    ltc_2 as .npy, RGBA32F / RGBA16F .dds and .ktx2, and an ES module for three.js."""
    import numpy as np

    from ..core import checks
    from ..core.atomic import atomic_directory, check_output_directory
    from ..ltc.fit import default_fit_f0, fit_table
    from ..ltc.report import score_fit, write_fit
    from ..ltc.reference import lobe_codes

    # flags that contradict each other or would change nothing: refused before any work
    if published is not None and not report:
        raise ValueError("--published: the published table is read only to score against with --report; "
                         "add --report, or drop --published")
    if fresnel and clipping != "exact":
        raise ValueError("--fresnel-aware: the Fresnel-aware LTC is evaluated with the exact horizon clipping; "
                         "add --clipping exact")
    lobe_codes(distribution, masking)  # a pair the fit has no lobe for: one line naming the choices
    size = checks.integer(size, "--size", 2, 256)
    polygons = checks.integer(polygons, "--polygons", 4, 4096)
    try:
        f0s = None if fit_f0 is None else tuple(float(x) for x in fit_f0.split(","))
    except ValueError:
        raise ValueError(f"--fit-f0: a comma-separated list of numbers in [0, 1], got {fit_f0[:60]!r}") from None
    if f0s is not None and not all(0.0 <= f <= 1.0 for f in f0s):  # NaN fails too
        raise ValueError(f"--fit-f0: normal reflectances must be in [0, 1], got {fit_f0[:60]!r}")
    if f0s is None:
        f0s = default_fit_f0(fresnel)
    check_output_directory(out, force)
    table = None
    if report:
        from ..ltc.published import published_table

        try:  # the default place is the command line's choice, not the library's: npm's, in the working directory
            table = published_table(published if published is not None else Path("node_modules"))
        except FileNotFoundError as exc:
            if published is not None:
                raise ValueError(f"{published}: not three.js's LTC tables ({exc})") from None
            print(f"pbrkit ltc: note: the published table is not installed ({exc}); the report scores pbrkit's "
                  "table alone", file=sys.stderr)
    with _Stages("ltc", quiet, 2 * size + 2 if fresnel else size + 2) as stages:
        stages.start(f"fit roughness column 1/{size}")

        def column(done, total):
            if done < total:
                stages.start(f"fit roughness column {done + 1}/{total}", done + 1)

        fit = fit_table(size, polygons, seed, progress=column, fit_f0=f0s, clipping=clipping,
                        distribution=distribution, masking=masking)
        second = None
        if fresnel:  # the f Fc lobe's matrices: pbrkit.ltc.shader.ltc_fresnel_rect
            stages.start(f"fit the f Fc lobe, roughness column 1/{size}", size + 1)

            def fc_column(done, total):
                if done < total:
                    stages.start(f"fit the f Fc lobe, roughness column {done + 1}/{total}", size + done + 1)

            second = fit_table(size, polygons, seed, progress=fc_column, fit_f0=(0.0,), clipping="exact",
                               distribution=distribution, masking=masking)
        stages.start("score" if report else "write", stages.total - 1)
        scores = score_fit(fit, table, fresnel=second) if report else None
        stages.start("write", stages.total)
        with atomic_directory(out, force) as tmp:
            write_fit(tmp, fit, scores, fresnel=second)
    if not quiet:
        seconds = fit.seconds + (second.seconds if second is not None else 0.0)
        print(f"wrote {out}: {size} x {size} LTC tables ({distribution}, {masking}"
              f"{', Fresnel-aware' if second is not None else ''}) fitted in {seconds:.1f} s; "
              f"per-cell error median {np.median(fit.error):.3f}")
        if scores is not None:
            for name, by_f in scores["scores"].items():
                label = "f0=0.04" if "Fresnel" in name else "F=1"
                s = by_f[label]
                print(f"{name} ({label}): relative error median {100 * s['relative_median']:.1f}%, mean "
                      f"{100 * s['relative_mean']:.1f}%, p95 {100 * s['relative_p95']:.1f}%; "
                      f"abs. error / albedo {100 * s['abs_over_albedo_mean']:.2f}%")
