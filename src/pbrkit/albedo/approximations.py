"""The error of each real-time approximation, as maps over (n.v, roughness).

Every comparison is a difference of *directional albedos* (the integral of
f (n.l) over the hemisphere, computed by :func:`pbrkit.albedo.furnace.albedo_quadrature`
or read from the converged tables), so each error is in the units a user sees:
the fraction of incident light reflected.  ``pbrkit approximations -o DIR``
writes ``approximations.png`` (heat maps with max / mean absolute error) and
``approximations.json``, together (all of them or none,
:func:`pbrkit.core.atomic.write_files`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..brdf.material import Material
from ..brdf.models import cook_torrance, urp_mobile
from .furnace import albedo_quadrature

__all__ = ["Comparison", "COMPARISONS", "approximation_errors", "approximations_report"]


@dataclass(frozen=True)
class Comparison:
    name: str
    title: str
    description: str


COMPARISONS = (
    Comparison("karis-env-brdf-a", "Karis mobile EnvBRDFApprox: A",
               "Karis 2014 analytic fit minus the converged split-sum table (Schlick-GGX k = alpha/2), scale A"),
    Comparison("karis-env-brdf-b", "Karis mobile EnvBRDFApprox: B",
               "Karis 2014 analytic fit minus the converged split-sum table, bias B"),
    Comparison("ue4-sg-vs-schlick", "UE4 spherical-Gaussian Fresnel vs Schlick pow5 (F0 0.04)",
               "albedo with F = f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c) minus albedo with Schlick pow5"),
    Comparison("pow4-vs-pow5", "Schlick pow4 (URP) vs pow5 (F0 0.04)",
               "albedo with (1 - c)^4 minus albedo with (1 - c)^5"),
    Comparison("schlick-vs-exact-dielectric", "Schlick vs exact Fresnel, dielectric IOR 1.5",
               "albedo with Schlick (f0 = 0.04) minus albedo with the exact unpolarised dielectric Fresnel"),
    Comparison("schlick-vs-exact-gold", "Schlick vs exact Fresnel, gold (max over RGB)",
               "albedo with Schlick (f0 = exact normal reflectance) minus the exact conductor Fresnel, "
               "largest |error| over the RGB channels"),
    Comparison("schlick-ggx-ibl-vs-smith", "Schlick-GGX k = alpha/2 vs exact Smith (F = 1)",
               "albedo with separable Schlick-GGX (k = alpha / 2) minus separable exact Smith"),
    Comparison("schlick-ggx-ue4-vs-smith", "Schlick-GGX k = (r+1)^2/8 vs exact Smith (F = 1)",
               "albedo with UE4's direct-light k minus separable exact Smith"),
    Comparison("urp-vs-ggx-f1", "URP mobile specular vs GGX/Smith/Schlick (F0 = 1)",
               "albedo of URP's minimalist Cook-Torrance minus GGX, height-correlated Smith, Schlick"),
    Comparison("urp-vs-ggx-f004", "URP mobile specular vs GGX/Smith/Schlick (F0 = 0.04)",
               "as above with a 0.04 specular colour"),
    Comparison("compensated-vs-single", "Kulla-Conty compensated minus single scattering (F = 1)",
               "energy that multiple-scattering compensation restores (GGX, height-correlated)"),
)


def _ct(**options):
    def lobe(f0):
        def brdf(l, v, n, r):
            m = Material(base_color=np.broadcast_to(f0, (3,)), metallic=1.0, roughness=r)
            return cook_torrance(l, v, n, m, diffuse="none", **options)
        return brdf
    return lobe


def approximation_errors(n=32):
    """``{name: (n_roughness, n_nv) error array}`` on texel-centre grids of size ``n``."""
    from .compensation import compensated_albedo
    from .lut import lookup_table
    from .tables import env_brdf_approx, texel_centres

    axis = texel_centres(n)
    errors = {}
    table = lookup_table("splitsum", n)[0]
    a, b = env_brdf_approx(axis[None, :], axis[:, None])
    errors["karis-env-brdf-a"] = a - table[..., 0]
    errors["karis-env-brdf-b"] = b - table[..., 1]

    def albedo(brdf, nodes=None):
        e = albedo_quadrature(brdf, axis, axis, *(nodes or (32, 16)))  # (mu, r[, C])
        return np.moveaxis(e, 0, 1)  # (r, mu[, C])

    f004 = 0.04
    schlick = albedo(_ct(fresnel="schlick")(f004))[..., 0]
    errors["ue4-sg-vs-schlick"] = albedo(_ct(fresnel="ue4-sg")(f004))[..., 0] - schlick
    errors["pow4-vs-pow5"] = albedo(_ct(fresnel="schlick-pow4")(f004))[..., 0] - schlick

    def dielectric(fresnel):
        def brdf(l, v, nrm, r):
            m = Material(base_color=np.zeros(3), metallic=0.0, roughness=r)  # f0 = 0.04 <-> IOR 1.5
            return cook_torrance(l, v, nrm, m, fresnel=fresnel, diffuse="none")
        return brdf

    errors["schlick-vs-exact-dielectric"] = (albedo(dielectric("schlick"))[..., 0]
                                             - albedo(dielectric("exact-dielectric"))[..., 0])

    def gold(fresnel):
        def brdf(l, v, nrm, r):
            return cook_torrance(l, v, nrm, Material.conductor("gold", roughness=r), fresnel=fresnel,
                                 diffuse="none")
        return brdf

    diff = albedo(gold("schlick")) - albedo(gold("exact-conductor"))
    pick = np.argmax(np.abs(diff), axis=-1)[..., None]
    errors["schlick-vs-exact-gold"] = np.take_along_axis(diff, pick, axis=-1)[..., 0]

    smith = albedo(_ct(masking="separable", fresnel="none")(1.0))[..., 0]
    errors["schlick-ggx-ibl-vs-smith"] = albedo(_ct(masking="schlick-ggx", fresnel="none")(1.0))[..., 0] - smith
    errors["schlick-ggx-ue4-vs-smith"] = (albedo(_ct(masking="schlick-ggx-ue4", fresnel="none")(1.0))[..., 0]
                                          - smith)

    def urp(f0):
        def brdf(l, v, nrm, r):
            return urp_mobile(l, v, nrm, Material(base_color=np.broadcast_to(f0, (3,)), metallic=1.0,
                                                  roughness=r))
        return brdf

    for f0, key in ((1.0, "urp-vs-ggx-f1"), (f004, "urp-vs-ggx-f004")):
        full = albedo(_ct(fresnel="schlick")(f0))[..., 0]
        errors[key] = albedo(urp(f0), nodes=(128, 32))[..., 0] - full

    single = compensated_albedo("none", axis, axis)[..., 0]
    errors["compensated-vs-single"] = (compensated_albedo("kulla-conty", axis, axis)[..., 0] - single).T
    return errors


def approximations_report(out_dir, n=32):
    """Write ``approximations.png`` and ``approximations.json`` together (the
    figure is rendered in memory first; a failure leaves neither); return the
    summary."""
    from ..core.atomic import write_files
    from .tables import texel_centres

    errors = approximation_errors(n)
    axis = texel_centres(n)
    summary = {
        "description": "Error of real-time approximations as differences of directional albedo",
        "grid": f"{n} x {n} texel centres: n.v = (i + 0.5) / {n} (x), roughness = (j + 0.5) / {n} (y)",
        "comparisons": {},
    }
    for c in COMPARISONS:
        e = errors[c.name]
        j, i = np.unravel_index(np.argmax(np.abs(e)), e.shape)
        summary["comparisons"][c.name] = {
            "title": c.title,
            "description": c.description,
            "max_abs_error": float(np.abs(e).max()),
            "mean_abs_error": float(np.abs(e).mean()),
            "signed_error_at_max": float(e[j, i]),
            "at": {"nv": float(axis[i]), "roughness": float(axis[j])},
        }
    files = {"approximations.png": _plot(errors, summary),
             "approximations.json": (json.dumps(summary, indent=2) + "\n").encode("utf-8")}
    write_files(Path(out_dir), files)
    return summary


def _plot(errors, summary):
    """The heat maps as PNG bytes."""
    from ..io.figures import figure_png, new_figure

    cols = 4
    rows = (len(COMPARISONS) + cols - 1) // cols
    fig, axes = new_figure(rows, cols, figsize=(4.2 * cols, 3.6 * rows), squeeze=False)
    for ax, c in zip(axes.flat, COMPARISONS):
        e = errors[c.name]
        limit = max(float(np.abs(e).max()), 1e-12)
        im = ax.imshow(e, origin="lower", extent=(0, 1, 0, 1), cmap="RdBu_r", vmin=-limit, vmax=limit,
                       aspect="auto", interpolation="nearest")
        s = summary["comparisons"][c.name]
        ax.set_title(f"{c.title}\nmax {s['max_abs_error']:.2e}, mean {s['mean_abs_error']:.2e}", fontsize=8)
        ax.set_xlabel("n.v", fontsize=8)
        ax.set_ylabel("roughness", fontsize=8)
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    for ax in axes.flat[len(COMPARISONS):]:
        ax.axis("off")
    fig.suptitle("Albedo error of real-time approximations (approximation minus reference)", fontsize=11)
    fig.tight_layout()
    return figure_png(fig, dpi=100)
