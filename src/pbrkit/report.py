"""Reports users run from the command line: the white-furnace albedo (``pbrkit furnace``)."""

from __future__ import annotations

import csv
import io
import json
import time
from pathlib import Path

import numpy as np

from ._atomic import atomic_path, write_bytes, write_text
from .furnace import albedo_monte_carlo, albedo_quadrature, furnace_lobes

__all__ = ["furnace_report", "texel_centres"]


def texel_centres(n):
    """(i + 0.5) / n for i in 0..n-1, the texel-centre grid of CONVENTIONS.md."""
    return (np.arange(n) + 0.5) / n


def furnace_report(out_dir, n_mu=32, roughness=None, samples=256, seed=0, lobes=None, progress=None):
    """Compute E(mu, r) for every furnace lobe by quadrature and Monte Carlo and
    write ``furnace.csv``, ``furnace.npy``, ``furnace.json`` and ``furnace.png``.

    ``furnace.npy`` is float64 of shape (lobes, mu, roughness, 3) holding the
    quadrature value, the Monte Carlo estimate and its standard error; the
    axes are listed in ``furnace.json``.  ``progress(name)`` is called per lobe.
    Returns the summary dictionary written to ``furnace.json`` (which holds no
    timings, so that the same options give the same bytes) and the timings.
    """
    out_dir = Path(out_dir)
    if n_mu < 2 or n_mu > 4096:
        raise ValueError(f"n_mu must be in [2, 4096]; got {n_mu}")
    if samples < 2 or samples > 1 << 20:
        raise ValueError(f"samples must be in [2, 1048576]; got {samples}")
    mu = texel_centres(n_mu)
    roughness = np.linspace(0.0, 1.0, 11) if roughness is None else np.asarray(roughness, dtype=float)
    all_lobes = furnace_lobes()
    names = list(all_lobes) if lobes is None else list(lobes)
    for name in names:
        if name not in all_lobes:
            raise ValueError(f"unknown lobe {name!r}; known: {', '.join(all_lobes)}")
    data = np.empty((len(names), mu.size, roughness.size, 3))
    timings = {}
    for k, name in enumerate(names):
        brdf = all_lobes[name]
        t0 = time.perf_counter()
        data[k, ..., 0] = albedo_quadrature(brdf, mu, roughness)
        t1 = time.perf_counter()
        data[k, ..., 1], data[k, ..., 2] = albedo_monte_carlo(brdf, mu, roughness, n_samples=samples, seed=seed + k)
        timings[name] = {"quadrature_s": t1 - t0, "monte_carlo_s": time.perf_counter() - t1}
        if progress is not None:
            progress(name)

    # z-score of MC against quadrature; the standard error gets a floor of 2e-4 because
    # near-mirror cells have rare zero-weight samples (tails reflecting below the horizon)
    # that a finite run may miss, so their sample variance understates the error.
    z = np.abs(data[..., 0] - data[..., 1]) / np.sqrt(data[..., 2] ** 2 + 2e-4 ** 2)
    summary = {
        "description": "White-furnace directional albedo E(mu, r) = integral of f (n.l) dl with F = 1",
        "lobes": names,
        "mu": mu.tolist(),
        "roughness": roughness.tolist(),
        "npy_axes": ["lobe", "mu", "roughness", "[quadrature, monte_carlo, monte_carlo_stderr]"],
        "quadrature": "Gauss-Legendre over the half vector, GGX-CDF theta map, analytic horizon limits",
        "monte_carlo": f"visible-normal GGX importance sampling, {samples} samples per cell, seed {seed}",
        "per_lobe": {
            name: {
                "min_albedo": float(data[k, ..., 0].min()),
                "max_albedo": float(data[k, ..., 0].max()),
                "max_energy_loss": float(1.0 - data[k, ..., 0].min()),
                "max_abs_mc_minus_quadrature": float(np.abs(data[k, ..., 0] - data[k, ..., 1]).max()),
                "max_z_score": float(z[k].max()),
            }
            for k, name in enumerate(names)
        },
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["lobe", "mu", "roughness", "albedo_quadrature", "albedo_monte_carlo", "monte_carlo_stderr"])
    for k, name in enumerate(names):
        for i, m in enumerate(mu):
            for j, r in enumerate(roughness):
                q, mc, se = data[k, i, j]
                writer.writerow([name, f"{m:.6f}", f"{r:.6f}", f"{q:.8f}", f"{mc:.8f}", f"{se:.8f}"])
    write_text(out_dir / "furnace.csv", buffer.getvalue())
    npy = io.BytesIO()
    np.save(npy, data)
    write_bytes(out_dir / "furnace.npy", npy.getvalue())
    write_text(out_dir / "furnace.json", json.dumps(summary, indent=2) + "\n")
    plot_albedo(out_dir / "furnace.png", names, mu, roughness, data[..., 0],
                title="White furnace: single-scattering albedo E(mu) with F = 1")
    return summary, timings


def plot_albedo(path, names, mu, roughness, albedo, title):
    """One panel per lobe, E against mu, one curve per roughness (viridis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = min(6, len(names))
    rows = (len(names) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.3 * rows), sharex=True, sharey=True,
                             squeeze=False)
    colors = plt.cm.viridis(np.linspace(0.0, 1.0, len(roughness)))
    for k, name in enumerate(names):
        ax = axes.flat[k]
        for j, r in enumerate(roughness):
            ax.plot(mu, albedo[k, :, j], color=colors[j], lw=1.2, label=f"r={r:.2f}")
        ax.set_title(name, fontsize=8)
        ax.set_ylim(0.0, max(1.05, float(np.nanmax(albedo)) * 1.02))
        ax.axhline(1.0, color="0.6", lw=0.6, ls="--")
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("mu = n.v", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("E(mu)", fontsize=8)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower right", fontsize=7, ncol=2)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png", metadata={"Software": None})
    plt.close(fig)
