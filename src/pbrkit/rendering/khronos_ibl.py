"""The image-based lighting of glTF's ``KHR_materials_*`` extensions as the Khronos
glTF Sample Viewer evaluates them (KhronosGroup/glTF-Sample-Renderer,
``source/Renderer/shaders/pbr.frag``, ``material_info.glsl`` and ``ibl.glsl``),
for :func:`pbrkit.rendering.realtime.render_realtime` with ``engine="khronos"``:

- KHR_materials_ior and KHR_materials_specular: the dielectric's F0 =
  min(((ior - 1) / (ior + 1))^2 specularColor, 1) and its weight specularWeight =
  specularFactor enter ``getIBLGGXFresnel``: FssEss = w (k_S A + B), k_S = F0 +
  (max(1 - r, F0) - F0)(1 - n.v)^5, E_ms = 1 - (A + B), F_avg = w (F0 + (1 - F0) / 21),
  FmsEms = E_ms FssEss F_avg / (1 - F_avg E_ms) (Fdez-Agüera 2019), and the
  dielectric is mix(diffuse, radiance, FssEss + FmsEms) per channel; the metal
  radiance (FssEss + FmsEms) of F0 = baseColor, w = 1;
- KHR_materials_sheen: ``color = f_sheen + color albedoSheenScaling`` with f_sheen =
  sheenColor x the Charlie LUT (its blue channel, the Khronos IBL sampler's
  ``lut_charlie``) at (n.v, sheenRoughness) x the Charlie-prefiltered radiance
  (``getIBLRadianceCharlie``), albedoSheenScaling = 1 - max3(sheenColor) E(n.v,
  sheenRoughness) (``albedoSheenScalingLUT``);
- KHR_materials_iridescence: the metal ``mix(f_metal_brdf_ibl, radiance
  iridescenceFresnel_metallic, iridescenceFactor)`` and the dielectric
  ``mix(f_dielectric_brdf_ibl, rgb_mix(f_diffuse, radiance,
  iridescenceFresnel_dielectric), iridescenceFactor)``, the thin film's Fresnel at n.v
  over the base colour and over the dielectric's F0 (``evalIridescence``, here
  :func:`pbrkit.brdf.fresnel.f_iridescence`, the same evaluation of the extension's
  README) applied to the bare prefiltered radiance (no split-sum albedo), no film at
  thickness 0; rgb_mix(a, b, t) = (1 - max3(t)) a + t b;
- KHR_materials_transmission and _volume: ``f_diffuse = mix(f_diffuse,
  f_specular_transmission, transmissionFactor)``, f_specular_transmission = (1 - (F0 A +
  B)) x the transmitted light x baseColor (``getIBLVolumeRefraction``; the light is
  :mod:`pbrkit.rendering.transmission_ibl`'s, the environment where the viewer reads its
  transmission framebuffer);
- KHR_materials_clearcoat: ``color = mix(color, clearcoat_brdf, clearcoat
  clearcoatFresnel)`` with clearcoat_brdf the GGX-prefiltered radiance at the coat's
  roughness alone (``getIBLRadianceGGX``: no split-sum albedo) and clearcoatFresnel =
  F_Schlick(F0_c, 1, n.v), F0_c of the *material's* ior (``getClearCoatInfo``; the
  extension's README says 1.5).

What the Sample Viewer does differently from the specification (and from pbrkit's own
engine, :func:`pbrkit.brdf.shading.gltf.ibl_extensions_extras`) is kept on purpose:
this is the engine's evaluation, for comparing pbrkit with the engine's pixels.
"""

from __future__ import annotations

import math

from ..brdf.fresnel import f_iridescence, f_schlick
from ..brdf.lobes.sheen import sheen_albedo_lookup
from ..brdf.shading.registry import COLUMNS
from ..core.jit import dual_use

__all__ = ["sample_viewer_fresnel", "sample_viewer_layers", "sample_viewer_base", "sample_viewer_transmission",
           "sample_viewer_film", "sample_viewer_extensions_ibl"]

_INV_PI = 1.0 / math.pi
_IOR, _SPECULAR, _SPECULAR_COLOR = COLUMNS.ior, COLUMNS.specular, COLUMNS.specular_color
_SHEEN_COLOR, _SHEEN_ROUGHNESS = COLUMNS.sheen_color, COLUMNS.sheen_roughness
_CLEARCOAT = COLUMNS.clearcoat
_IRIDESCENCE, _FILM_IOR = COLUMNS.iridescence, COLUMNS.iridescence_ior
_FILM_THICKNESS = COLUMNS.iridescence_thickness_maximum
_TRANSMISSION = COLUMNS.transmission


@dual_use(inline=True)
def sample_viewer_fresnel(nov, r, f0, weight, a, b):
    """The Sample Viewer's ``getIBLGGXFresnel`` of one channel (module docstring):
    FssEss + FmsEms of F0 ``f0`` and specular weight ``weight`` at perceptual
    roughness r, Karis' (A, B) = (``a``, ``b``)."""
    k_s = f0 + (max(1.0 - r, f0) - f0) * (1.0 - nov) ** 5
    fss_ess = weight * (k_s * a + b)
    e_ms = 1.0 - (a + b)
    f_avg = weight * (f0 + (1.0 - f0) / 21.0)
    return fss_ess + e_ms * fss_ess * f_avg / (1.0 - f_avg * e_ms)


@dual_use(inline=True)
def sample_viewer_layers(nov, r, diffuse, base, metallic, f0, weight, a, b, radiance):
    """One channel of the Sample Viewer's metallic-roughness IBL (pbr.frag) over the
    diffuse radiance ``diffuse`` (f_diffuse): the dielectric mix(f_diffuse, radiance,
    W(F0, weight)), the metal radiance W(base, 1), mixed by metallic (W
    :func:`sample_viewer_fresnel`)."""
    w_d = sample_viewer_fresnel(nov, r, f0, weight, a, b)
    dielectric = diffuse * (1.0 - w_d) + radiance * w_d
    metal = radiance * sample_viewer_fresnel(nov, r, base, 1.0, a, b)
    return dielectric + (metal - dielectric) * metallic


@dual_use(inline=True)
def sample_viewer_base(nov, r, base, metallic, f0, weight, a, b, radiance, irradiance):
    """:func:`sample_viewer_layers` over the Lambertian f_diffuse = base E / pi."""
    return sample_viewer_layers(nov, r, base * irradiance * _INV_PI, base, metallic, f0, weight, a, b, radiance)


@dual_use(inline=True)
def sample_viewer_transmission(diffuse, transmission, f0, a, b, transmitted, base):
    """One channel of the Sample Viewer's f_diffuse with KHR_materials_transmission:
    mix(f_diffuse, f_specular_transmission, transmissionFactor), f_specular_transmission
    = (1 - (F0 A + B)) x the transmitted light x baseColor (``getIBLVolumeRefraction``, f90
    1; the light from :mod:`pbrkit.rendering.transmission_ibl`)."""
    return diffuse + ((1.0 - (f0 * a + b)) * transmitted * base - diffuse) * transmission


@dual_use(inline=True)
def sample_viewer_film(nov, r, diffuse, base, metallic, f0, weight, a, b, radiance, k, film_d, film_d_max,
                       film_m):
    """One channel of pbr.frag's MATERIAL_IRIDESCENCE branch: the metal mix(W(base, 1)
    radiance, radiance film_m, k) and the dielectric mix(mix(f_diffuse, radiance, W(F0,
    weight)), rgb_mix(f_diffuse, radiance, film_d), k), mixed by metallic; film_d and film_m
    the film's Fresnel at n.v over F0 and over the base colour (this channel's, and
    ``film_d_max`` the largest channel of film_d: rgb_mix(a, b, t) = (1 - max3 t) a + t b)."""
    w_d = sample_viewer_fresnel(nov, r, f0, weight, a, b)
    dielectric = diffuse * (1.0 - w_d) + radiance * w_d
    metal = radiance * sample_viewer_fresnel(nov, r, base, 1.0, a, b)
    dielectric = dielectric + ((1.0 - film_d_max) * diffuse + film_d * radiance - dielectric) * k
    metal = metal + (radiance * film_m - metal) * k
    return dielectric + (metal - dielectric) * metallic


@dual_use(inline=True)
def sample_viewer_extensions_ibl(params, q, base, metallic, r, nov, a, b, radiance, irradiance, coat_radiance,
                                 sheen_radiance, charlie_lut, c, base0, base1, base2, transmitted, coat_nov):
    """Channel ``c`` of the Sample Viewer's IBL of a glTF material with extensions
    (module docstring): parameters from row ``q`` of the packed table ``params``,
    ``base`` the channel's base colour, the prefiltered ``radiance`` (GGX at r),
    ``irradiance`` E (the diffuse is base E / pi), the coat's and the sheen's
    prefiltered radiance, and ``charlie_lut`` the Charlie LUT's value at (n.v,
    sheenRoughness); (``base0``, ``base1``, ``base2``) the whole base colour (the film's
    Fresnel over it); ``transmitted`` the light through the surface
    (:mod:`pbrkit.rendering.transmission_ibl`); ``coat_nov`` the view's cosine to the coat's
    normal (``clampedDot(clearcoatNormal, v)``, the clearcoatFresnel's)."""
    ior = params[q, _IOR]
    f0_ior = ((ior - 1.0) / (ior + 1.0)) ** 2
    f0 = min(f0_ior * params[q, _SPECULAR_COLOR + c], 1.0)
    k = params[q, _IRIDESCENCE]
    t = params[q, _TRANSMISSION]
    diffuse = base * irradiance * _INV_PI
    if t > 0.0:
        diffuse = sample_viewer_transmission(diffuse, t, f0, a, b, transmitted, base)
    color = sample_viewer_layers(nov, r, diffuse, base, metallic, f0, params[q, _SPECULAR], a, b, radiance)
    if k > 0.0 and params[q, _FILM_THICKNESS] > 0.0:  # pbr.frag's MATERIAL_IRIDESCENCE branch
        d = f_iridescence(nov, params[q, _FILM_IOR], params[q, _FILM_THICKNESS],
                          min(f0_ior * params[q, _SPECULAR_COLOR], 1.0),
                          min(f0_ior * params[q, _SPECULAR_COLOR + 1], 1.0),
                          min(f0_ior * params[q, _SPECULAR_COLOR + 2], 1.0))
        m = f_iridescence(nov, params[q, _FILM_IOR], params[q, _FILM_THICKNESS], base0, base1, base2)
        color = sample_viewer_film(nov, r, diffuse, base, metallic, f0, params[q, _SPECULAR], a, b, radiance, k,
                                   d[c], max(d[0], max(d[1], d[2])), m[c])
    s0, s1, s2 = params[q, _SHEEN_COLOR], params[q, _SHEEN_COLOR + 1], params[q, _SHEEN_COLOR + 2]
    if s0 > 0.0 or s1 > 0.0 or s2 > 0.0:
        e = sheen_albedo_lookup(nov, params[q, _SHEEN_ROUGHNESS])
        color = params[q, _SHEEN_COLOR + c] * charlie_lut * sheen_radiance + color * (1.0 - max(s0, max(s1, s2)) * e)
    t = params[q, _CLEARCOAT] * f_schlick(coat_nov, f0_ior, 1.0)
    return color + (coat_radiance - color) * t
