"""Benchmark: read a MERL file, look it up, and fit each model / objective to it.

    python bench/measured.py [--samples 24000] [--repeat 3] [FILE.binary]

Without a file, a synthetic MERL file is written first from pbrkit's Disney
model (base colour (0.7, 0.5, 0.2), metallic 0.3, roughness 0.45, specular
0.6, clear coat 0.5 with gloss 0.7; the database is not bundled).  Prints the
best-of-``repeat`` wall time (after JIT warm-up) of reading the file, of 10^6
nearest and trilinear lookups, and of each fit (``ggx`` with and without
Fresnel, ``disney``; ``log`` and ``cosine`` objectives), with the fitted
roughness and the fit's relative L2 error.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from _timing import best_and_median

from pbrkit import Material, models
from pbrkit.measured import fit_measured, merl_table, read_merl, write_merl


def random_hemisphere(rng, n):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    return d


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="?", help="a MERL .binary file (default: a synthetic one)")
    parser.add_argument("--samples", type=int, default=24000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = args.file
        if path is None:
            material = Material.from_ue4(base_color=[0.7, 0.5, 0.2], metallic=0.3, roughness=0.45, specular=0.6,
                                         clearcoat=0.5, clearcoat_gloss=0.7)
            path = Path(tmp) / "synthetic-disney.binary"
            write_merl(path, merl_table(lambda l, v, n: models.disney(l, v, n, material)))
        t_read = best_and_median(lambda: read_merl(path), args.repeat)[0]
        measured = read_merl(path)
        rng = np.random.default_rng(0)
        l, v = random_hemisphere(rng, 1_000_000), random_hemisphere(rng, 1_000_000)
        print(f"{measured.name}: read {t_read:.3f} s")
        for interpolation in ("nearest", "trilinear"):
            t = best_and_median(lambda i=interpolation: measured.evaluate(l, v, interpolation=i), args.repeat)[0]
            print(f"  10^6 {interpolation} lookups: {t:.3f} s")
        fit_measured(measured, "ggx", samples=200)  # JIT warm-up (cached)
        fit_measured(measured, "disney", samples=200)
        for model, fresnel in (("ggx", True), ("ggx", False), ("disney", True)):
            for weighting in ("log", "cosine"):
                def run(model=model, fresnel=fresnel, weighting=weighting):
                    return fit_measured(measured, model, fresnel, weighting, samples=args.samples)

                t = best_and_median(run, args.repeat)[0]
                fit = run()
                print(f"  fit {model:6s} fresnel={fresnel!s:5s} {weighting:6s}: {t:6.2f} s  "
                      f"roughness {fit.parameters['roughness']:.4f}  relative L2 {fit.error['relative_l2']:.2e}  "
                      f"({fit.samples} bins, {fit.evaluations} evaluations)")


if __name__ == "__main__":
    main()
