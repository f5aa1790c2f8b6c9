"""``pbrkit explore --static -o DIR``: every view of the explorer as PNG and SVG
(Matplotlib), for reports and papers.

:func:`static_figures` draws the views of :mod:`pbrkit.explore.views` for one
BRDF (and optionally a second, drawn beside it and compared); :func:`write_static`
writes them, with ``explore.json`` (the BRDFs, the angles and a few numbers read
off the views), into a folder committed all at once
(:func:`pbrkit.core.atomic.atomic_directory`).  The bytes are deterministic: PNGs
carry no "Software" chunk, SVGs no date and a fixed ``svg.hashsalt``.
"""

from __future__ import annotations

import io
import json
import math

import numpy as np

from . import views as V

__all__ = ["VIEW_NAMES", "static_figures", "write_static", "figure_bytes", "check_finite"]

#: The views written (each as NAME.png and NAME.svg); ``compare`` only with a second BRDF.
VIEW_NAMES = ("incidence_plane", "lobe_3d", "theta_h_slice", "theta_d_slice", "half_diff_image", "albedo",
              "sphere_point", "sphere_environment", "terms", "compare")
_DPI = 100
_COLOURS = ("tab:blue", "tab:red")
_SVG_SALT = "pbrkit-explore"
_DEG30, _DEG45, _DEG90, _DEG135 = (math.radians(x) for x in (30.0, 45.0, 90.0, 135.0))


def figure_bytes(fig):
    """(PNG bytes, SVG bytes) of a Matplotlib figure, deterministic (no date, no
    software version, fixed hash salt); the figure is closed."""
    import matplotlib

    from ..io.figures import figure_png

    with matplotlib.rc_context({"svg.hashsalt": _SVG_SALT, "svg.fonttype": "path"}):
        buffer = io.BytesIO()
        fig.savefig(buffer, format="svg", dpi=_DPI, metadata={"Date": None, "Creator": None})
        svg = buffer.getvalue()
    return figure_png(fig, _DPI), svg


def _legend(ax, **kwargs):
    """A legend when the axes have labelled artists (Matplotlib warns otherwise)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**kwargs)


def _pairs(a, b):
    return [(brdf, colour) for brdf, colour in zip((a, b), _COLOURS) if brdf is not None]


def _incidence(a, b, theta_v):
    from ..io.figures import pyplot

    plt = pyplot()
    fig = plt.figure(figsize=(5.5, 4.0))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(-90)
    ax.set_thetamax(90)
    top = 1e-6
    for brdf, colour in _pairs(a, b):
        p = V.incidence_plane(brdf, theta_v)
        ax.plot(p["theta_l"], p["value"], color=colour, label=brdf.name)
        top = max(top, float(np.max(p["value"])))
    ax.plot([theta_v, theta_v], [0.0, top], "k--", linewidth=1, label="view")
    ax.set_title(f"f cos θl in the plane of incidence, θv = {math.degrees(theta_v):.1f}°", fontsize=10)
    _legend(ax, loc="lower left", fontsize=7, bbox_to_anchor=(-0.1, -0.12))
    return fig


def _lobe(a, b, theta_v):
    from ..io.figures import pyplot

    plt = pyplot()
    fig = plt.figure(figsize=(5.5, 4.5))
    ax = fig.add_subplot(projection="3d")
    top = 1e-6
    for brdf, colour in _pairs(a, b):
        lobe = V.lobe_3d(brdf, theta_v)
        p = lobe["points"]
        ax.plot_wireframe(p[..., 0], p[..., 1], p[..., 2], color=colour, linewidth=0.5, label=brdf.name)
        top = max(top, float(np.max(lobe["radius"])))
        v = lobe["v"]
    ax.plot([0, top * v[0]], [0, top * v[1]], [0, top * v[2]], "k--", linewidth=1)
    ax.set_xlim(-top, top)
    ax.set_ylim(-top, top)
    ax.set_zlim(0, top)
    ax.set_box_aspect((2, 2, 1))
    ax.view_init(elev=25, azim=-60)
    ax.set_title(f"3D lobe: f cos θl, θv = {math.degrees(theta_v):.1f}°", fontsize=10)
    _legend(ax, fontsize=7, loc="upper left")
    return fig


def _slices(a, b, which, fixed, phi_d):
    from ..io.figures import new_figure

    fig, ax = new_figure(figsize=(5.5, 4.0))
    for brdf, colour in _pairs(a, b):
        if which == "theta_h":
            s = V.theta_h_slice(brdf, fixed, phi_d)
        else:
            s = V.theta_d_slice(brdf, fixed, phi_d)
        ax.semilogy(np.degrees(s[which]), np.maximum(s["value"], 1e-6), color=colour, label=brdf.name)
    other = "θd" if which == "theta_h" else "θh"
    ax.set_xlabel(("θh" if which == "theta_h" else "θd") + " (degrees)")
    ax.set_ylabel("f (luminance, 1/sr)")
    ax.set_title(f"{'θh' if which == 'theta_h' else 'θd'} slice, {other} = {math.degrees(fixed):.1f}°, "
                 f"φd = {math.degrees(phi_d):.0f}°", fontsize=10)
    _legend(ax, fontsize=7)
    return fig


def _images(a, b, phi_d):
    from ..io.figures import new_figure

    pairs = _pairs(a, b)
    fig, axes = new_figure(1, len(pairs), figsize=(4.2 * len(pairs), 3.8), squeeze=False)
    for ax, (brdf, _) in zip(axes[0], pairs):
        img = V.half_diff_image(brdf, phi_d)
        shown = np.where(img["valid"], img["log_value"], np.nan)
        im = ax.imshow(shown, origin="lower", extent=(0, 90, 0, 90), vmin=-3, vmax=2, cmap="viridis")
        ax.set_xlabel("θh (degrees)")
        ax.set_ylabel("θd (degrees)")
        ax.set_title(f"log10 f: {brdf.name}", fontsize=8)
    fig.colorbar(im, ax=list(axes[0]), shrink=0.8)
    return fig


def _albedo(a, b, compensation):
    from ..io.figures import new_figure

    fig, ax = new_figure(figsize=(5.5, 4.0))
    for k, (brdf, colour) in enumerate(_pairs(a, b)):
        e = V.directional_albedo(brdf, compensation=compensation)
        x = np.degrees(e["theta_v"])
        ax.plot(x, e["value"], color=colour, label=f"{brdf.name} (luminance)")
        if e["white"] is not None and k == 0:
            ax.plot(x, e["white"], color="gray", label=f"{brdf.name}, F = 1")
            ax.plot(x, e["compensated"], "g--", label=f"GGX F = 1, {compensation} compensation")
    ax.axhline(1.0, color="k", linestyle=":", linewidth=1, label="1 (furnace)")
    ax.set_ylim(0.0, max(1.1, 1.05 * max(float(np.max(line.get_ydata())) for line in ax.get_lines())))
    ax.set_xlabel("θv (degrees)")
    ax.set_ylabel("E(θv)")
    ax.set_title("directional albedo", fontsize=10)
    _legend(ax, fontsize=7, loc="lower left")
    return fig


def _spheres(a, b, kind, light_theta, light_phi, exposure):
    from ..io.figures import new_figure

    pairs = _pairs(a, b)
    fig, axes = new_figure(1, len(pairs), figsize=(3.6 * len(pairs), 3.8), squeeze=False)
    for ax, (brdf, _) in zip(axes[0], pairs):
        if kind == "point":
            radiance = V.lit_sphere_point(brdf, light_theta, light_phi)["radiance"]
        else:
            radiance = V.lit_sphere_environment(brdf)["radiance"]
        ax.imshow(V.display_rgba(radiance, exposure), interpolation="nearest")
        ax.set_axis_off()
        ax.set_title(brdf.name, fontsize=8)
    title = (f"point light at θ = {math.degrees(light_theta):.0f}°, φ = {math.degrees(light_phi):.0f}°"
             if kind == "point" else "environment (bundled, baked)")
    fig.suptitle(title, fontsize=10)
    return fig


def _terms(a, b, theta_v):
    from ..io.figures import new_figure

    fig, axes = new_figure(1, 3, figsize=(13.0, 3.8))
    for brdf, colour in _pairs(a, b):
        t = V.terms(brdf, theta_v)
        if t is None:
            continue
        axes[0].semilogy(np.degrees(t["theta_h"]), np.maximum(t["D"], 1e-6), color=colour, label=brdf.name)
        axes[1].plot(np.degrees(t["theta_l"]), t["G"], color=colour, label=brdf.name)
        for c, style in zip(range(3), ("-", "--", ":")):
            axes[2].plot(np.degrees(t["theta_d"]), t["F"][:, c], color=colour, linestyle=style,
                         label=f"{brdf.name} {'RGB'[c]}")
    for ax, title, xl in zip(axes, ("D(θh)", f"G2(θl), θv = {math.degrees(theta_v):.1f}°", "F(θd)"),
                             ("θh", "θl", "θd")):
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(f"{xl} (degrees)")
        _legend(ax, fontsize=6)
        if not ax.get_lines():
            ax.text(0.5, 0.5, "no separate terms\n(a measured BRDF or a GGX fit)", ha="center", va="center",
                    transform=ax.transAxes)
    axes[1].set_ylim(0.0, 1.05)
    axes[2].set_ylim(0.0, 1.05)
    return fig


def _compare(a, b, theta_v, phi_d, light_theta):
    from ..io.figures import new_figure
    from ..core.color import luminance

    c = V.compare(a, b, theta_v, phi_d, light_theta)
    fig, axes = new_figure(1, 3, figsize=(13.0, 3.8))
    axes[0].plot(np.degrees(c["plane_a"]["theta_l"]), c["value_difference"], color="purple")
    axes[0].set_xlabel("θl (degrees)")
    axes[0].set_title("B − A: f cos θl (luminance)", fontsize=10)
    im = axes[1].imshow(c["log_ratio"], origin="lower", extent=(0, 90, 0, 90), vmin=-1, vmax=1, cmap="RdBu")
    fig.colorbar(im, ax=axes[1], shrink=0.8)
    axes[1].set_xlabel("θh (degrees)")
    axes[1].set_ylabel("θd (degrees)")
    axes[1].set_title("log10 (B / A)", fontsize=10)
    d = luminance(c["sphere_difference"])
    scale = max(float(np.max(np.abs(d))), 1e-6)
    im = axes[2].imshow(d, vmin=-scale, vmax=scale, cmap="RdBu", interpolation="nearest")
    fig.colorbar(im, ax=axes[2], shrink=0.8)
    axes[2].set_axis_off()
    axes[2].set_title("B − A: point-lit sphere", fontsize=10)
    fig.suptitle(f"A = {a.name}; B = {b.name}", fontsize=9)
    return fig


def static_figures(brdf, second=None, theta_v=_DEG45, light_theta=_DEG45, light_phi=_DEG135, theta_h=0.0,
                   theta_d=_DEG30, phi_d=_DEG90, exposure=0.0, compensation="filament", progress=None):
    """{view name: Matplotlib figure} of :data:`VIEW_NAMES` (``compare`` only with
    ``second``); ``progress(name)`` is called before each view."""
    makers = {
        "incidence_plane": lambda: _incidence(brdf, second, theta_v),
        "lobe_3d": lambda: _lobe(brdf, second, theta_v),
        "theta_h_slice": lambda: _slices(brdf, second, "theta_h", theta_d, phi_d),
        "theta_d_slice": lambda: _slices(brdf, second, "theta_d", theta_h, phi_d),
        "half_diff_image": lambda: _images(brdf, second, phi_d),
        "albedo": lambda: _albedo(brdf, second, compensation),
        "sphere_point": lambda: _spheres(brdf, second, "point", light_theta, light_phi, exposure),
        "sphere_environment": lambda: _spheres(brdf, second, "environment", light_theta, light_phi, exposure),
        "terms": lambda: _terms(brdf, second, theta_v),
    }
    if second is not None:
        makers["compare"] = lambda: _compare(brdf, second, theta_v, phi_d, light_theta)
    figures = {}
    with V.view_threads(1):
        for name, make in makers.items():
            if progress is not None:
                progress(name)
            figures[name] = make()
    return figures


def _summary(brdf, second, angles, compensation, extra):
    """The JSON record of a static export: the BRDFs, the angles (degrees) and a
    few numbers read off the views (albedo at normal and grazing view, the peak of
    the incidence-plane curve)."""

    def describe(b):
        if b is None:
            return None
        out = {"name": b.name}
        if isinstance(b, V.ModelBRDF):
            s = b.spec
            out.update(model=s.model, distribution=s.distribution, masking=s.masking, fresnel=s.fresnel,
                       diffuse=s.diffuse, base_color=list(s.base_color), metallic=s.metallic,
                       roughness=s.roughness, roughness_remap="alpha = roughness^2",
                       **{k: getattr(s, k) for k in V.MODEL_PARAMETERS[s.model]},
                       **{k: [float(x) for x in getattr(s, k)] for k in V.COLOUR_PARAMETERS[s.model]})
        e = V.directional_albedo(b, compensation=compensation)
        p = V.incidence_plane(b, math.radians(angles["theta_v"]))
        out["albedo_luminance"] = {"theta_v_min": float(e["value"][0]), "theta_v_max": float(e["value"][-1]),
                                   "at_theta_v_degrees": [float(np.degrees(e["theta_v"][0])),
                                                          float(np.degrees(e["theta_v"][-1]))]}
        k = int(np.argmax(p["value"]))
        out["incidence_plane_peak"] = {"theta_l_degrees": float(np.degrees(p["theta_l"][k])),
                                       "f_cos_luminance": float(p["value"][k])}
        return out

    record = {"first": describe(brdf), "second": describe(second), "angles_degrees": angles,
              "compensation": compensation, "views": {}}
    record.update(extra or {})
    return record


def check_finite(record, where=""):
    """Raise a one-line ValueError naming the entry (``explore.json:
    second.albedo_luminance.theta_v_max``) of the first NaN or infinite number in
    ``record`` (nested dicts and lists): the JSON written is strict (RFC 8259 has
    no NaN or Infinity; ``json.dumps(allow_nan=False)``)."""
    if isinstance(record, dict):
        for key, value in record.items():
            check_finite(value, f"{where}.{key}" if where else str(key))
    elif isinstance(record, (list, tuple)):
        for k, value in enumerate(record):
            check_finite(value, f"{where}[{k}]")
    elif isinstance(record, (float, np.floating)) and not math.isfinite(float(record)):
        raise ValueError(f"explore.json: {where} is not finite ({float(record)}); the BRDF's values are too large "
                         f"to summarise")


def write_static(out, brdf, second=None, force=False, progress=None, extra=None, **angles):
    """Write every view of :func:`static_figures` as ``NAME.png`` and ``NAME.svg``
    and ``explore.json`` into the folder ``out`` (absent or empty unless
    ``force``), all at once; ``extra`` (a dict, e.g. a fit's parameters and error)
    is recorded in the JSON.  Angles in radians as :func:`static_figures` takes
    them.  Returns the names of the files written."""
    from ..core.atomic import atomic_directory, check_output_directory, write_bytes

    check_output_directory(out, force)
    compensation = angles.pop("compensation", "filament")
    defaults = {"theta_v": 45.0, "light_theta": 45.0, "light_phi": 135.0, "theta_h": 0.0, "theta_d": 30.0,
                "phi_d": 90.0}
    degrees = {k: round(math.degrees(angles[k]), 6) if k in angles else v for k, v in defaults.items()}
    degrees["exposure_ev"] = float(angles.get("exposure", 0.0))
    with V.view_threads(1):
        record = _summary(brdf, second, degrees, compensation, extra)
    check_finite(record)  # before drawing: strict JSON (RFC 8259 has no NaN or Infinity)
    figures = static_figures(brdf, second, compensation=compensation, progress=progress, **angles)
    files = {}
    for name, fig in figures.items():
        png, svg = figure_bytes(fig)
        files[f"{name}.png"] = png
        files[f"{name}.svg"] = svg
    if progress is not None:
        progress("write")
    record["views"] = {name: [f"{name}.png", f"{name}.svg"] for name in figures}
    files["explore.json"] = (json.dumps(record, indent=2, sort_keys=True, allow_nan=False) + "\n").encode("utf-8")
    with atomic_directory(out, force) as tmp:
        for name, data in files.items():
            write_bytes(tmp / name, data)
    return sorted(files)
