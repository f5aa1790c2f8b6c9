"""Benchmark: the 128 x 128 DFG / split-sum table.

    python bench/lut.py [--size 128] [--repeat 7]

Prints, measured in one run:
- the in-process time of the default (converged) table after JIT warm-up;
- the time of a fresh process's first table, Numba compilation included, with
  the on-disk cache as it is and with an empty cache;
- the baseline: a plain 1024-sample Hammersley Monte Carlo table (GGX NDF
  importance sampling, the estimator of Karis 2013 and Filament's cmgen), also
  compiled with Numba, and the max error of both tables against a converged
  reference (6x the quadrature nodes).  Targets (issue 3): <= 0.15 s in-process,
  <= 3 s for the first call, every texel within 1e-3 of the reference.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

import numba
import numpy as np
from _timing import best_and_median

from pbrkit.albedo.lut import DEFAULT_NODES, lookup_table
from pbrkit.albedo.tables import texel_centres
from pbrkit.core.jit import parallel_kernel
from pbrkit.microfacet.ggx import v_smith_ggx_height_correlated, warp_ggx_ndf
from pbrkit.microfacet.roughness import alpha_from_roughness
from pbrkit.sampling.low_discrepancy import hammersley


@parallel_kernel
def _hammersley_dfg(mu, alpha, points, out):
    for index in numba.prange(alpha.size * mu.size):
        j = index // mu.size
        i = index % mu.size
        m = mu[i]
        vx = np.sqrt(1.0 - m * m)
        acc1 = 0.0
        acc2 = 0.0
        for k in range(points.shape[0]):
            hx, hy, hz = warp_ggx_ndf(points[k, 0], points[k, 1], alpha[j])
            voh = vx * hx + m * hz
            nol = 2.0 * voh * hz - m
            if nol <= 0.0 or voh <= 0.0:
                continue
            # f cos / pdf with pdf(l) = D (n.h) / (4 v.h): 4 V (n.l)(v.h) / (n.h)
            g = 4.0 * v_smith_ggx_height_correlated(nol, m, alpha[j]) * nol * voh / hz
            fc = (1.0 - voh) ** 5
            acc1 += g * fc
            acc2 += g
        out[j, i, 0] = acc1 / points.shape[0]
        out[j, i, 1] = acc2 / points.shape[0]


def hammersley_table(size, samples=1024):
    axis = texel_centres(size)
    out = np.zeros((size, size, 2))
    _hammersley_dfg(axis, alpha_from_roughness(axis), hammersley(samples), out)
    return out.astype(np.float32)


def first_call_in_new_process(size, cache_dir=None):
    code = ("import time; t = time.perf_counter(); from pbrkit.albedo.lut import lookup_table; "
            f"lookup_table('dfg', {size}); print(time.perf_counter() - t)")
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    n = args.size

    lookup_table("dfg", 8)
    hammersley_table(8)
    t_ours, t_ours_med = best_and_median(lambda: lookup_table("dfg", n), args.repeat)
    t_split, _ = best_and_median(lambda: lookup_table("splitsum", n), args.repeat)
    t_mc, t_mc_med = best_and_median(lambda: hammersley_table(n), args.repeat)

    ours = lookup_table("dfg", n)[0]
    mc = hammersley_table(n)
    ref = lookup_table("dfg", n, nodes=tuple(6 * x for x in DEFAULT_NODES))[0]
    err_ours = np.abs(ours - ref).max()
    err_mc = np.abs(mc - ref).max()

    warm_first = first_call_in_new_process(n)
    with tempfile.TemporaryDirectory() as cache:
        cold_first = first_call_in_new_process(n, cache)

    print(f"{n} x {n} DFG table, {numba.get_num_threads()} threads")
    print(f"  pbrkit quadrature (default)   : {t_ours:.4f} s best, {t_ours_med:.4f} s median   "
          f"max error {err_ours:.1e}")
    print(f"  pbrkit split-sum (A, B)       : {t_split:.4f} s best")
    print(f"  1024-sample Hammersley MC     : {t_mc:.4f} s best, {t_mc_med:.4f} s median   "
          f"max error {err_mc:.1e}")
    print(f"  speed ratio MC / quadrature   : {t_mc / t_ours:.1f} x; error ratio {err_mc / err_ours:.0f} x")
    print(f"  first call in a new process   : {warm_first:.2f} s with the Numba cache, "
          f"{cold_first:.2f} s with an empty cache (import and compilation included)")


if __name__ == "__main__":
    main()
