"""Reports users run from the command line: the white-furnace albedo (``pbrkit furnace``).

Each report computes everything first, renders its figures to PNG bytes in
memory, and only then writes its files, all in one
:func:`pbrkit.core.atomic.atomic_group` (:func:`pbrkit.core.atomic.write_files`): a failure
part-way (a full disk, Ctrl-C, SIGTERM) leaves none of them, and files of an
earlier run are left as they were.  :func:`furnace_files` and
:func:`compensation_files` return the files without writing them, so that a
caller can commit the furnace and the compensation outputs as one group.
"""

from __future__ import annotations

import csv
import io
import json
import time

import numpy as np

from ..albedo.furnace import (
    agreement,
    albedo_monte_carlo,
    albedo_quadrature,
    furnace_lobes,
)
from ..albedo.tables import texel_centres
from ..core import checks
from ..core.atomic import write_files
from ..io.figures import colors, new_figure, save_figure

__all__ = ["furnace_report", "furnace_files", "compensation_report", "compensation_files",
           "plot_albedo", "albedo_families", "curve_roughness"]


def _npy_bytes(array):
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def furnace_report(out_dir, n_mu=32, roughness=None, samples=256, seed=0, lobes=None, progress=None):
    """Compute E(mu, r) for every furnace lobe by quadrature and Monte Carlo and
    write ``furnace.csv``, ``furnace.npy``, ``furnace.json`` and ``furnace.png``
    together (:func:`write_files`: all of them or none).

    ``furnace.npy`` is float64 of shape (lobes, mu, roughness, 3) holding the
    quadrature value, the Monte Carlo estimate and its standard error; the
    axes are listed in ``furnace.json``.  ``progress(name)`` is called per lobe.
    With lobes of more than one family (:func:`albedo_families`) it also writes one
    figure per family, ``furnace_<family>.png`` (``furnace_ggx.png``,
    ``furnace_models.png`` ...).  Returns the summary dictionary written to
    ``furnace.json`` (which holds no timings, so that the same options give the
    same bytes) and the timings.
    """
    summary, timings, files = furnace_files(n_mu, roughness, samples, seed, lobes, progress)
    write_files(out_dir, files)
    return summary, timings


def furnace_files(n_mu=32, roughness=None, samples=256, seed=0, lobes=None, progress=None):
    """What :func:`furnace_report` writes, without writing it: ``(summary,
    timings, files)`` with ``files`` {file name: bytes} for :func:`write_files`."""
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
                # ~99.7 % for an unbiased estimator with an honest standard error
                "fraction_within_3_stderr": agreement(data[k, ..., 0], data[k, ..., 1], data[k, ..., 2]),
            }
            for k, name in enumerate(names)
        },
    }
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["lobe", "mu", "roughness", "albedo_quadrature", "albedo_monte_carlo", "monte_carlo_stderr"])
    for k, name in enumerate(names):
        for i, m in enumerate(mu):
            for j, r in enumerate(roughness):
                q, mc, se = data[k, i, j]
                writer.writerow([name, f"{m:.6f}", f"{r:.6f}", f"{q:.8f}", f"{mc:.8f}", f"{se:.8f}"])
    files = {"furnace.csv": buffer.getvalue().encode("utf-8"),
             "furnace.npy": _npy_bytes(data),
             "furnace.json": (json.dumps(summary, indent=2) + "\n").encode("utf-8")}
    title = "White furnace: single-scattering albedo E(mu), F = 1"
    files["furnace.png"] = plot_albedo(None, names, mu, roughness, data[..., 0], title=title)
    families = albedo_families(names)
    if len(families) > 1:
        for family, members in families.items():
            rows = [names.index(name) for name in members]
            files[f"furnace_{family}.png"] = plot_albedo(None, members, mu, roughness, data[rows, ..., 0],
                                                         title=f"{title}: {FAMILY_TITLES.get(family, family)}")
    return summary, timings, files


#: Titles of the furnace figures, one per family of lobes (:func:`albedo_families`).
FAMILY_TITLES = {
    "ggx": "GGX D, each masking term",
    "beckmann": "Beckmann D, each masking term",
    "blinn-phong": "Blinn-Phong D, each masking term",
    "models": "the engines' models",
}


def albedo_families(names):
    """The furnace lobes grouped into the families their figures show, in order of first
    appearance: ``cook_torrance`` lobes ``"D/G"`` by distribution D (``ggx``,
    ``beckmann``, ``blinn-phong``), the models (``ue4``, ``filament``, ...) under ``models``."""
    families = {}
    for name in names:
        families.setdefault(name.split("/", 1)[0] if "/" in name else "models", []).append(name)
    return families


def curve_roughness(roughness, curves=6):
    """Indices of at most ``curves`` roughness values, evenly spread over ``roughness``
    (first and last included): the curves a furnace panel draws."""
    roughness = np.asarray(roughness, dtype=float)
    if roughness.size <= curves:
        return np.arange(roughness.size)
    targets = np.linspace(roughness.min(), roughness.max(), curves)
    return np.unique([int(np.argmin(np.abs(roughness - t))) for t in targets])


def plot_albedo(path, names, mu, roughness, albedo, title, curves=6):
    """One figure: a panel per lobe (at most 3 across, legible at a web page's
    width), E(mu) against mu = n.v with one curve per roughness for at most
    ``curves`` roughness values (:func:`curve_roughness`), all panels on the same
    axes, and one legend below them giving the roughness of each curve.  With
    ``path`` None the PNG bytes are returned instead of written."""
    import matplotlib

    picks = curve_roughness(roughness, curves)
    cols = min(3, len(names))
    rows = (len(names) + cols - 1) // cols
    top = max(1.05, float(np.nanmax(albedo[..., picks])) * 1.04)
    style = {"font.size": 11, "axes.titlesize": 12, "axes.labelsize": 11, "xtick.labelsize": 10,
             "ytick.labelsize": 10, "legend.fontsize": 11, "legend.title_fontsize": 11, "figure.titlesize": 13}
    with matplotlib.rc_context(style):
        fig, axes = new_figure(rows, cols, figsize=(max(3.8 * cols, 6.4), 2.9 * rows + 1.3), sharex=True, sharey=True,
                               squeeze=False, layout="constrained")
        palette = colors(len(picks), "viridis")
        for k, name in enumerate(names):
            ax = axes.flat[k]
            ax.axhline(1.0, color="0.55", lw=0.9, ls="--")
            for c, j in zip(palette, picks):
                ax.plot(mu, albedo[k, :, j], color=c, lw=2.0, label=f"{roughness[j]:.2g}")
            ax.set_title(name.replace("/", " / "))
            ax.set_xlim(0.0, 1.0)
            ax.set_ylim(0.0, top)
            ax.grid(alpha=0.3)
        for ax in axes.flat[len(names):]:
            ax.axis("off")
        for k in range(len(names)):
            ax = axes.flat[k]
            if k + cols >= len(names):  # lowest panel of its column
                ax.set_xlabel("mu = n.v")
                ax.xaxis.set_tick_params(labelbottom=True)
            if k % cols == 0:
                ax.set_ylabel("E(mu)")
        handles, labels = axes.flat[0].get_legend_handles_labels()
        handles.append(matplotlib.lines.Line2D([], [], color="0.55", lw=0.9, ls="--"))
        labels.append("E = 1 (no loss)")
        fig.legend(handles, labels, loc="outside lower center", ncol=len(labels) if cols > 1 else 4,
                   title="perceptual roughness r of each curve", frameon=False, handlelength=1.6,
                   columnspacing=1.2)
        fig.suptitle(title)
        return save_figure(fig, path, dpi=100)


def compensation_report(out_dir, method, table_size=128):
    """White furnace with multiple-scattering compensation, and coloured metals.

    Writes ``compensation.csv`` / ``.npy`` / ``.json`` / ``.png`` to ``out_dir``
    together (:func:`write_files`: all of them or none): the F = 1 GGX
    (height-correlated) albedo without and with ``method`` compensation on
    the texel grid of a ``table_size`` DFG table (where the
    runtime lookup is exact), the error of bilinear lookups between texels,
    and the RGB albedo and saturation of gold and copper against roughness.
    Returns the summary written to ``compensation.json``.
    """
    summary, files = compensation_files(method, table_size)
    write_files(out_dir, files)
    return summary


def compensation_files(method, table_size=128):
    """What :func:`compensation_report` writes, without writing it: ``(summary,
    files)`` with ``files`` {file name: bytes} for :func:`write_files`."""
    from ..albedo.compensation import compensated_albedo, white_furnace_compensated
    from ..albedo.tables import DEFAULT_NODES
    from ..brdf.fresnel import CONDUCTORS, f_conductor

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
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["nv", "roughness", "albedo_single_scattering", f"albedo_{method}"])
    for i, m in enumerate(grid):
        for j, r in enumerate(grid):
            writer.writerow([f"{m:.6f}", f"{r:.6f}", f"{single[i, j]:.8f}", f"{comp[i, j]:.8f}"])
    files = {"compensation.csv": buffer.getvalue().encode("utf-8"),
             "compensation.npy": _npy_bytes(np.stack([single, comp])),
             "compensation.json": (json.dumps(summary, indent=2) + "\n").encode("utf-8"),
             "compensation.png": _plot_compensation(method, grid, single, comp, roughness, metals)}
    return summary, files


def _saturation(rgb):
    rgb = np.asarray(rgb)
    top = rgb.max(axis=-1)
    return (top - rgb.min(axis=-1)) / np.maximum(top, 1e-12)


def _plot_compensation(method, grid, single, comp, roughness, metals):
    """The compensation figure as PNG bytes."""
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
    return save_figure(fig, None, dpi=100)
