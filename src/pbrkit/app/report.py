"""Reports users run from the command line: the white-furnace albedo (``pbrkit furnace``)."""

from __future__ import annotations

import csv
import io
import json
import time
from pathlib import Path

import numpy as np

from ..albedo.furnace import albedo_monte_carlo, albedo_quadrature, furnace_lobes
from ..albedo.tables import texel_centres
from ..core import checks
from ..core.atomic import write_bytes, write_text
from .figures import colors, new_figure, save_figure

__all__ = ["furnace_report", "compensation_report"]


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
    n_mu = checks.integer(n_mu, "n_mu", 2, 4096)
    samples = checks.integer(samples, "samples", 2, 1 << 20)
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

    # Fraction of cells where MC lies within 3 standard errors of the quadrature.  Below
    # 99.7 % is expected at small sample counts: GGX tails reflect rare samples below the
    # horizon (weight 0), so a short run that misses them understates its own error.
    within = np.abs(data[..., 0] - data[..., 1]) <= 3.0 * data[..., 2] + 1e-9
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
                "fraction_within_3_stderr": float(within[k].mean()),
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
    cols = min(6, len(names))
    rows = (len(names) + cols - 1) // cols
    fig, axes = new_figure(rows, cols, figsize=(2.6 * cols, 2.3 * rows), sharex=True, sharey=True, squeeze=False)
    palette = colors(len(roughness))
    for k, name in enumerate(names):
        ax = axes.flat[k]
        for j, r in enumerate(roughness):
            ax.plot(mu, albedo[k, :, j], color=palette[j], lw=1.2, label=f"r={r:.2f}")
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
    save_figure(fig, path, dpi=110)


def compensation_report(out_dir, method, table_size=128):
    """White furnace with multiple-scattering compensation, and coloured metals.

    Writes ``compensation.csv`` / ``.npy`` / ``.json`` / ``.png`` to ``out_dir``:
    the F = 1 GGX (height-correlated) albedo without and with ``method``
    compensation on the texel grid of a ``table_size`` DFG table (where the
    runtime lookup is exact), the error of bilinear lookups between texels,
    and the RGB albedo and saturation of gold and copper against roughness.
    Returns the summary written to ``compensation.json``.
    """
    from ..albedo.compensation import compensated_albedo, white_furnace_compensated
    from ..albedo.tables import DEFAULT_NODES
    from ..brdf.fresnel import CONDUCTORS, f_conductor

    out_dir = Path(out_dir)
    fine = tuple(4 * x for x in DEFAULT_NODES)
    grid = texel_centres(table_size)
    single = white_furnace_compensated("none", grid, grid, table_size, fine)
    comp = white_furnace_compensated(method, grid, grid, table_size, fine)
    between = (np.arange(table_size - 1) + 1.0) / table_size
    comp_between = white_furnace_compensated(method, between, between, table_size, fine)

    roughness = np.linspace(0.0, 1.0, 41)
    metals = {}
    for name in ("gold", "copper"):
        eta, k = (np.asarray(x) for x in CONDUCTORS[name])
        f0 = f_conductor(1.0, eta, k)
        metals[name] = {m: compensated_albedo(m, [0.5], roughness, f0, table_size)[0]
                        for m in ("none", "kulla-conty", "filament")}

    summary = {
        "description": "White furnace of a GGX (height-correlated Smith) surface with F = 1, "
                       f"with and without '{method}' multiple-scattering compensation",
        "method": method,
        "table_size": table_size,
        "grid": "texel centres of the DFG table: n.v = (i + 0.5) / N, r = (j + 0.5) / N",
        "max_abs_error_on_texel_grid": float(np.abs(comp - 1.0).max()),
        "max_energy_loss_without_compensation": float(np.abs(single - 1.0).max()),
        "between_texels": {
            "grid": "n.v, r = k / N, k = 1..N-1 (bilinear lookups)",
            "max_abs_error": float(np.abs(comp_between - 1.0).max()),
            "median_abs_error": float(np.median(np.abs(comp_between - 1.0))),
        },
        "metals_at_nv_0.5": {
            name: {m: {"roughness": roughness.tolist(), "albedo_rgb": a.tolist(),
                       "saturation": _saturation(a).tolist()} for m, a in d.items()}
            for name, d in metals.items()
        },
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["nv", "roughness", "albedo_single_scattering", f"albedo_{method}"])
    for i, m in enumerate(grid):
        for j, r in enumerate(grid):
            writer.writerow([f"{m:.6f}", f"{r:.6f}", f"{single[i, j]:.8f}", f"{comp[i, j]:.8f}"])
    write_text(out_dir / "compensation.csv", buffer.getvalue())
    npy = io.BytesIO()
    np.save(npy, np.stack([single, comp]))
    write_bytes(out_dir / "compensation.npy", npy.getvalue())
    write_text(out_dir / "compensation.json", json.dumps(summary, indent=2) + "\n")
    _plot_compensation(out_dir / "compensation.png", method, grid, single, comp, roughness, metals)
    return summary


def _saturation(rgb):
    rgb = np.asarray(rgb)
    top = rgb.max(axis=-1)
    return (top - rgb.min(axis=-1)) / np.maximum(top, 1e-12)


def _plot_compensation(path, method, grid, single, comp, roughness, metals):
    fig, axes = new_figure(1, 4, figsize=(17, 4))
    picks = np.linspace(0, grid.size - 1, 6).astype(int)
    for c, j in zip(colors(picks.size), picks):
        axes[0].plot(grid, single[:, j], color=c, ls="--", lw=1)
        axes[0].plot(grid, comp[:, j], color=c, lw=1.5, label=f"r={grid[j]:.2f}")
    axes[0].set_title(f"F = 1: single scattering (dashed) vs {method}", fontsize=9)
    axes[0].set_xlabel("n.v")
    axes[0].set_ylabel("albedo")
    axes[0].set_ylim(0.0, 1.1)
    axes[0].legend(fontsize=7)
    styles = {"none": ":", "kulla-conty": "-", "filament": "--"}
    for ax, (name, d) in zip(axes[1:3], metals.items()):
        for m, a in d.items():
            for ch, col in enumerate(("tab:red", "tab:green", "tab:blue")):
                ax.plot(roughness, a[:, ch], color=col, ls=styles[m], lw=1.2,
                        label=m if ch == 0 else None)
        ax.set_title(f"{name}: RGB albedo at n.v = 0.5", fontsize=9)
        ax.set_xlabel("roughness")
        ax.set_ylim(0.0, 1.05)
        ax.legend(fontsize=7)
    for name, d in metals.items():
        for m, a in d.items():
            axes[3].plot(roughness, _saturation(a), ls=styles[m], label=f"{name} {m}")
    axes[3].set_title("saturation (max - min) / max", fontsize=9)
    axes[3].set_xlabel("roughness")
    axes[3].legend(fontsize=7)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
