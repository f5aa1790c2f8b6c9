"""Benchmark: evaluate the UE4 model on N random (l, v) pairs with per-pair materials.

    python bench/models.py [--pairs 10000000] [--repeat 3]

Prints the best-of-``repeat`` wall time of the compiled kernel (after JIT
warm-up; the model's single composition, :mod:`pbrkit.brdf.shading.ue4`) and, as the
baseline measured in the same run, of the same terms composed with plain NumPy
array operations (what a NumPy user would write from pbrkit's terms), and
their ratio.  The target (issue 2) is <= 1 s for 10^7 pairs on
the 2-core development machine.
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import best_and_median

from pbrkit import Material
from pbrkit.brdf.diffuse import lambert
from pbrkit.brdf.distributions import alpha_from_roughness, d_ggx
from pbrkit.brdf.fresnel import f0_metallic, f_schlick_ue4_sg
from pbrkit.brdf.masking import g2_schlick_ggx, k_ue4_direct, visibility
from pbrkit.brdf.models import frame_cosines, ue4


def ue4_numpy(l, v, n, material):
    """The baseline: UE4 (Karis 2013) composed from pbrkit's terms with NumPy arrays."""
    c = frame_cosines(l, v, n)
    r = material.roughness
    specular = (d_ggx(c.noh, alpha_from_roughness(r))
                * visibility(g2_schlick_ggx(c.nol, c.nov, k_ue4_direct(r)), c.nol, c.nov))[..., None]
    metallic = np.asarray(material.metallic)[..., None]
    f0 = f0_metallic(material.base_color, metallic, np.asarray(material.dielectric_f0)[..., None])
    lit = ((c.nol > 0.0) & (c.nov > 0.0))[..., None]
    diffuse = material.base_color * (1.0 - metallic) * lambert(c.nol)[..., None]
    return np.where(lit, diffuse + specular * f_schlick_ue4_sg(c.voh[..., None], f0), 0.0)


def random_hemisphere(rng, n):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    return d


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    n = args.pairs
    l = random_hemisphere(rng, n)
    v = random_hemisphere(rng, n)
    normal = np.broadcast_to(np.array([0.0, 0.0, 1.0]), (n, 3))
    material = Material(base_color=rng.random((n, 3)), metallic=rng.random(n), roughness=rng.random(n))

    ue4(l[:16], v[:16], normal[:16], Material(base_color=rng.random((16, 3))))  # JIT warm-up (cached)
    t_numba = best_and_median(lambda: ue4(l, v, normal, material), args.repeat)[0]
    t_numpy = best_and_median(lambda: ue4_numpy(l, v, normal, material), args.repeat - 2)[0]
    a = ue4(l[:100_000], v[:100_000], normal[:100_000], Material(
        base_color=material.base_color[:100_000], metallic=material.metallic[:100_000],
        roughness=material.roughness[:100_000]))
    b = ue4_numpy(l[:100_000], v[:100_000], normal[:100_000], Material(
        base_color=material.base_color[:100_000], metallic=material.metallic[:100_000],
        roughness=material.roughness[:100_000]))
    print(f"ue4 model, {n:,} (l, v) pairs with per-pair materials")
    print(f"  numba kernel : {t_numba:8.3f} s  ({n / t_numba / 1e6:7.1f} M pairs/s)")
    print(f"  numpy        : {t_numpy:8.3f} s  ({n / t_numpy / 1e6:7.1f} M pairs/s)")
    print(f"  speed-up     : {t_numpy / t_numba:8.1f} x   (max |numba - numpy| = {np.abs(a - b).max():.1e})")


if __name__ == "__main__":
    main()
