"""The data of every view of ``pbrkit explore``, as NumPy arrays computed by
pbrkit's own models (no plotting library here; :mod:`pbrkit.explore.app` and
:mod:`pbrkit.explore.static` draw them).

A *BRDF* in this module is any object with ``name`` and ``evaluate(l, v, n=None)``
returning f (..., 3) (not f cos) for unit directions in the last axis (l toward
the light, v toward the eye; n the normal, default +z):

- :class:`ModelBRDF`: a pbrkit model (:mod:`pbrkit.brdf.models`) with a
  :class:`pbrkit.rendering.scene.MaterialSpec` (the material, the model and, for
  ``cook_torrance``, its D, G, F and diffuse terms by name), evaluated by
  :func:`pbrkit.brdf.models.evaluate`; perceptual roughness r, alpha = r^2
  (clamped at :data:`pbrkit.microfacet.roughness.ALPHA_MIN`) as in every model,
  with each model's own remaps (UE4's k = (r + 1)^2 / 8, Disney's aspect, ...);
- a measured BRDF, :class:`pbrkit.measured.merl.MerlBRDF`, or a fitted model.

Angles are in radians; directions are in the local frame (normal +z, tangent +x)
unless a view says otherwise.  The views, after Disney's BRDF Explorer
(Burley 2012, "Physically-Based Shading at Disney", sec. 2 and the explorer's
plots):

- :func:`incidence_plane`: f cos theta_l over theta_l in the plane of incidence
  (the polar plot);
- :func:`lobe_3d`: a mesh over the hemisphere of l with radius f cos theta_l;
- :func:`theta_h_slice`, :func:`theta_d_slice`, :func:`half_diff_image`: f in
  Rusinkiewicz's half/difference angles (Rusinkiewicz 1998, "A New Change of
  Variables for Efficient BRDF Representation"; Burley 2012 sec. 2.1),
  directions by :func:`pbrkit.measured.merl.directions_from_half_diff`;
- :func:`directional_albedo`: E(theta_v) by :func:`pbrkit.albedo.furnace.albedo_quadrature`,
  the white furnace of the model's specular lobe (F = 1), the furnace line 1 and
  the compensated white furnace of :func:`pbrkit.albedo.compensation.white_furnace_compensated`;
- :func:`lit_sphere_point`, :func:`lit_sphere_environment`: a sphere under a
  directional light (f cos E) and under the bundled environment (pbrkit's
  real-time renderer, :func:`pbrkit.rendering.realtime.render_realtime`, with a
  cached bake; measured BRDFs: a quadrature over the bake's environment);
- :func:`terms`: D, G and F alone, from the model's own composition in
  :mod:`pbrkit.brdf.bxdf`;
- :func:`compare`: two BRDFs side by side and their difference.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from ..brdf.bxdf import local_cosines
from ..brdf.dispatch import bxdf_fresnel, make_bxdf, specular_lobe, specular_visibility
from ..brdf.shading.registry import MODEL_TERMS, MODELS, PARAMETERS, REGISTERED
from ..brdf.parameters import TEXTURED, Parameter
from ..core.color import linear_to_srgb, luminance, tonemap
from ..core.jit import kernel
from ..microfacet.ggx import d_ggx
from ..microfacet.roughness import alpha_from_roughness

__all__ = [
    "ModelBRDF",
    "model_brdf",
    "MODEL_PARAMETERS",
    "DISNEY_ONLY",
    "PARAMETER_RANGES",
    "COLOUR_PARAMETERS",
    "COLOUR_RANGES",
    "SLIDER_LIMITS",
    "SLIDER_RANGES",
    "EXTRA_LOBES",
    "incidence_plane",
    "lobe_3d",
    "theta_h_slice",
    "theta_d_slice",
    "half_diff_image",
    "directional_albedo",
    "lit_sphere_point",
    "lit_sphere_environment",
    "terms",
    "compare",
    "display_rgba",
    "SPHERE_CAMERA",
    "COMPENSATIONS",
    "applicable_parameters",
    "model_choices",
    "fitted_brdf",
    "view_threads",
]

_HALF_PI = 0.5 * math.pi
_QUARTER_PI = 0.25 * math.pi
_N = np.array([0.0, 0.0, 1.0])

#: Parameters that do not change a BRDF (the explorer's reflection): KHR_materials_volume's
#: and KHR_materials_dispersion's (the medium beneath a transmissive surface) and the thin film's thickness at texture
#: value 0 (no effect without an iridescence thickness texture).
NOT_REFLECTION = ("thickness", "attenuation_distance", "attenuation_color", "iridescence_thickness_minimum",
                  "dispersion")
#: The scalar Material parameters each model reads besides base_color, metallic and
#: roughness (``reflectance``: dielectric f0 = 0.16 reflectance^2; glTF and URP fix f0
#: at 0.04), from the models' declarations: the explorer's sliders.
MODEL_PARAMETERS = {m.name: tuple(p.name for p in m.numbers if p.channels == 1 and p.name not in TEXTURED
                                   and p.name not in NOT_REFLECTION) for m in REGISTERED}
#: Disney's extra parameters (Burley 2012, sec. 5.1), with their declared defaults.
DISNEY_ONLY = {p.name: p.default for p in REGISTERED[[m.name for m in REGISTERED].index("disney")].numbers
               if p.name in MODEL_PARAMETERS["disney"] and all(m.declaration(p.name) is None
                                                               for m in REGISTERED if m.name != "disney")}
#: (low, high, default) of every scalar parameter, the widest declared range
#: (anisotropy: [0, 1] for disney, Burley's aspect, which :func:`applicable_parameters` applies).
PARAMETER_RANGES = {p.name: (p.low, p.high, p.default) for p in PARAMETERS
                    if isinstance(p, Parameter) and p.channels == 1}
#: The colour parameters (three channels) each model reads besides base_color, from the
#: models' declarations: the explorer's R, G, B sliders (``specular_color``, glTF's
#: ``sheen_color``, ...).  Cook-Torrance's ``eta`` and ``k`` (no default: set by the
#: ``conductor`` choice) are not among them.
COLOUR_PARAMETERS = {m.name: tuple(p.name for p in m.numbers if p.channels == 3 and p.name not in TEXTURED
                               and p.default is not None and p.name not in NOT_REFLECTION) for m in REGISTERED}
#: (low, high, default) of every colour parameter (one channel's range; the default RGB).
COLOUR_RANGES = {p.name: (p.low, p.high, tuple(p.default)) for p in PARAMETERS
                 if isinstance(p, Parameter) and p.channels == 3 and p.name in set().union(*COLOUR_PARAMETERS.values())}
#: The explorer's slider ends where the declared range is open (a slider needs a finite
#: end) or has a gap: KHR_materials_ior's ior, declared 0 or >= 1 (0: f0 = 1), from 1
#: (f0 = 0) to 3 (f0 = 0.25; diamond's 2.42 inside); KHR_materials_specular's
#: specular_color, declared [0, inf) (f0 = min(f0(ior) colour, 1) per channel), to 2;
#: KHR_materials_iridescence's film IOR to 2.5 and thickness to 1200 nm (the sample
#: models' range).
#: A value outside a slider's ends is still a valid material (:func:`model_brdf` checks
#: the declared range).
SLIDER_LIMITS = {"ior": (1.0, 3.0), "specular_color": (0.0, 2.0), "iridescence_ior": (1.0, 2.5),
                 "iridescence_thickness_maximum": (0.0, 1200.0)}
#: The end of a slider over any other open range (a parameter declared later).
SLIDER_UNBOUNDED_HIGH = 2.0
#: (low, high) of every scalar and colour parameter's slider: the declared range, or
#: :data:`SLIDER_LIMITS`, always finite.
SLIDER_RANGES = {name: SLIDER_LIMITS.get(name, (lo, hi if math.isfinite(hi) else SLIDER_UNBOUNDED_HIGH))
                 for name, (lo, hi, _) in {**PARAMETER_RANGES, **COLOUR_RANGES}.items()}
#: The parameters of the lobes that :meth:`ModelBRDF.white` removes (Disney's sheen and
#: clear coat, glTF's KHR_materials_sheen and KHR_materials_clearcoat), with their
#: declared defaults (no sheen, no coat).
EXTRA_LOBES = {p.name: p.default for p in PARAMETERS if p.name in ("sheen", "clearcoat", "sheen_color")}
#: Compensations of the albedo view (:mod:`pbrkit.albedo.compensation`).
COMPENSATIONS = ("filament", "kulla-conty")


# ================================================================ threads


@contextlib.contextmanager
def view_threads(count=1):
    """Run the compiled kernels called in this block with ``count`` threads (Numba's
    thread count is per calling thread; restored afterwards).  The views evaluate a
    few thousand directions per call, where a parallel launch costs more than it
    saves, and on a loaded machine far more: the incidence plane took 22 ms with 2
    threads and 0.1 ms with 1 while other processes kept both cores busy
    (bench/explore.py measures both)."""
    import numba

    previous = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(count), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


# ================================================================ the BRDFs


@dataclass(frozen=True)
class ModelBRDF:
    """A pbrkit model with its material: ``spec`` is a
    :class:`pbrkit.rendering.scene.MaterialSpec` (model, terms and parameters, checked
    as a scene's material is); ``label`` names it in plots (default: the model and,
    for cook_torrance, its terms)."""

    spec: object
    label: str | None = None

    @property
    def model(self):
        return self.spec.model

    @property
    def name(self):
        if self.label:
            return self.label
        s = self.spec
        if s.model == "cook_torrance":
            return f"cook_torrance ({s.distribution}, {s.masking}, {s.fresnel}, {s.diffuse})"
        if s.model == "filament" and s.diffuse != "lambert":
            return f"filament ({s.diffuse})"
        return s.model

    @functools.cached_property
    def material(self):
        """The :class:`pbrkit.Material` of ``spec``."""
        return self.spec.material()

    @property
    def term_names(self):
        """The keyword arguments of :func:`pbrkit.brdf.models.evaluate` for the terms."""
        s = self.spec
        return {"distribution": s.distribution, "masking": s.masking, "fresnel": s.fresnel, "diffuse": s.diffuse}

    @property
    def anisotropic(self):
        """Whether the lobe is anisotropic: ``anisotropy`` (Disney, Filament, Cook-Torrance)
        or glTF's KHR_materials_anisotropy ``anisotropy_strength`` away from 0."""
        return float(self.spec.anisotropy) != 0.0 or float(self.spec.anisotropy_strength) != 0.0

    def evaluate(self, l, v, n=None, t=None):
        """f (..., 3) of the model (:func:`pbrkit.brdf.models.evaluate`); ``n`` default +z,
        ``t`` the tangent (default :func:`pbrkit.core.vec.orthonormal_basis`'s, +x for n = +z)."""
        from ..brdf.models import evaluate

        if t is None and n is None and self.anisotropic:
            t = np.array([1.0, 0.0, 0.0])
        return evaluate(self.spec.model, l, v, _N if n is None else n, self.material, t=t, **self.term_names)

    def white(self):
        """The same model with F = 1 and no diffuse, clear coat or sheen (:data:`EXTRA_LOBES`):
        base colour 1, metallic 1 (f0 = 1 and F90 = 1 in every metallic workflow, glTF's
        specular and ior included; cook_torrance: fresnel ``none`` and diffuse ``none``), as :func:`pbrkit.albedo.furnace.furnace_lobes` builds
        its white lobes.  Its albedo is the white furnace of the specular lobe."""
        s = self.spec
        changes = dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, conductor=None, eta=None, k=None, **EXTRA_LOBES)
        if s.model == "cook_torrance":
            changes.update(fresnel="none", diffuse="none")
        return ModelBRDF(dataclasses.replace(s, **changes), label=f"{self.name}, F = 1")


def model_brdf(model="gltf", base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, *, label=None,
               distribution="ggx", masking="height-correlated", fresnel="schlick", diffuse="lambert",
               conductor=None, **parameters):
    """A :class:`ModelBRDF`: ``model`` (:data:`pbrkit.brdf.shading.registry.MODELS`) with the
    metallic-roughness parameters and any other the models declare (``reflectance``,
    ``anisotropy``, ``specular_color``, ``eta`` and ``k``, Disney's extras
    ``subsurface``, ``specular_tint``, ``sheen``, ``sheen_tint``, ``clearcoat``,
    ``clearcoat_gloss``, ...), ``conductor`` (a metal of
    :data:`pbrkit.brdf.fresnel.CONDUCTORS`, for ``fresnel="exact-conductor"``),
    and cook_torrance's terms by name (filament takes ``diffuse``).  Checked as
    a scene's material (:class:`pbrkit.rendering.scene.MaterialSpec`): a parameter
    or term the model does not have raises ValueError naming it."""
    from ..rendering.scene import MaterialSpec

    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; choose one of {', '.join(MODELS)}")
    known = [p.name for p in PARAMETERS if isinstance(p, Parameter) and p.name not in TEXTURED]
    unknown = sorted(set(parameters) - set(known))
    if unknown:
        raise ValueError(f"unknown material parameter {unknown[0]!r}; choose from {', '.join(known)}")
    if model in MODEL_TERMS and model != "filament":
        diffuse = MODEL_TERMS[model][3] or diffuse
    spec = MaterialSpec(name="explore", model=model, base_color=tuple(np.asarray(base_color, dtype=float)),
                        metallic=metallic, roughness=roughness, distribution=distribution, masking=masking,
                        fresnel=fresnel, diffuse=diffuse, conductor=conductor, **parameters)
    return ModelBRDF(spec, label)


def model_choices(model):
    """The term choices ``model`` declares: name -> the names it takes."""
    return {name: c.choices for name, c in REGISTERED[MODELS.index(model)].choices.items()}


def applicable_parameters(model, parameters):
    """The entries of ``parameters`` (name -> value) that ``model`` reads
    (:data:`MODEL_PARAMETERS`, and the RGB triples of :data:`COLOUR_PARAMETERS`), each
    clamped to the model's own range (anisotropy to [0, 1] for disney)."""
    keep = {k: v for k, v in parameters.items() if k in MODEL_PARAMETERS[model] or k in COLOUR_PARAMETERS[model]}
    declared = REGISTERED[MODELS.index(model)]
    for name, value in keep.items():  # the model's own range (Disney's anisotropy)
        p = declared.declaration(name)
        if name in COLOUR_PARAMETERS[model]:
            keep[name] = tuple(min(max(float(x), p.low), p.high) for x in np.broadcast_to(value, (3,)))
        else:
            keep[name] = min(max(float(value), p.low), p.high)
    return keep


class FittedBRDF:
    """A model fitted to a measured BRDF (:class:`pbrkit.measured.fit.FitResult`) as a
    BRDF of this module, evaluated by the result's own ``evaluate``."""

    def __init__(self, result, name):
        self.result = result
        self.name = name

    def evaluate(self, l, v, n=None):
        return self.result.evaluate(l, v, n)


def fitted_brdf(result):
    """The BRDF of a :class:`pbrkit.measured.fit.FitResult`: for a ``disney`` fit the
    :class:`ModelBRDF` of its material (so that every view, the terms and the
    renderer's sphere included, shows it), else (``ggx``: independent RGB diffuse
    and specular colours, which no metallic-roughness material holds) a
    :class:`FittedBRDF`."""
    label = f"{result.model} fit to {result.name or 'the measurement'}"
    if result.model == "disney":
        m = result.material()
        return model_brdf("disney", m.base_color, float(m.metallic), float(m.roughness), label=label,
                          **{k: float(getattr(m, k)) for k in MODEL_PARAMETERS["disney"]})
    return FittedBRDF(result, label)


def _evaluate(brdf, l, v, n=None, t=None):
    """f (..., 3) of any BRDF (module doc); the tangent only for models."""
    if isinstance(brdf, ModelBRDF):
        return brdf.evaluate(l, v, n, t)
    return np.asarray(brdf.evaluate(l, v, n), dtype=np.float64)


def _plane_direction(theta):
    """Local unit direction (sin theta, 0, cos theta) in the plane of incidence (xz); theta < 0 is on -x."""
    theta = np.asarray(theta, dtype=np.float64)
    return np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=-1)


def _centres(count, top=_HALF_PI):
    """``count`` cell centres (i + 0.5) / count * top."""
    return (np.arange(count) + 0.5) / count * top


# ================================================================ the plots


def incidence_plane(brdf, theta_v, count=181):
    """f cos theta_l in the plane of incidence, for the polar plot.

    The view is v = (sin theta_v, 0, cos theta_v); the light sweeps the same
    plane, l = (sin theta_l, 0, cos theta_l) with theta_l in (-pi/2, pi/2)
    (negative on the far side of the normal, where the mirror direction
    theta_l = -theta_v lies).  Returns a dict: ``theta_l`` (count,), ``l``
    (count, 3), ``v`` (3,), ``f`` and ``f_cos`` (count, 3), ``value`` = the Rec.709
    luminance of f cos, and the polar plot's points ``x`` = value sin theta_l,
    ``y`` = value cos theta_l."""
    theta_l = np.linspace(-_HALF_PI, _HALF_PI, count + 2)[1:-1]
    l = _plane_direction(theta_l)
    v = _plane_direction(theta_v)
    f = _evaluate(brdf, l, v[None, :])
    f_cos = f * np.maximum(l[:, 2:3], 0.0)
    value = luminance(f_cos)
    return {"theta_l": theta_l, "l": l, "v": v, "f": f, "f_cos": f_cos, "value": value,
            "x": value * np.sin(theta_l), "y": value * np.cos(theta_l)}


def lobe_3d(brdf, theta_v, phi_v=0.0, n_theta=24, n_phi=48):
    """The 3D lobe: f cos theta_l over the hemisphere of l as radius.

    The view is v = (sin theta_v cos phi_v, sin theta_v sin phi_v, cos theta_v);
    l runs over theta_l in [0, pi/2] (``n_theta`` + 1 rings from the pole to
    the horizon) and phi_l in [0, 2 pi] (``n_phi`` + 1 meridians, the last
    repeating the first so that the mesh closes).  Returns a dict: ``theta``
    (n_theta + 1,), ``phi`` (n_phi + 1,), ``l``, ``f``, ``f_cos`` ((n_theta + 1,
    n_phi + 1, 3)), ``radius`` = luminance of f cos, ``points`` = radius l, ``v``."""
    theta = np.linspace(0.0, _HALF_PI, n_theta + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, n_phi + 1)
    st = np.sin(theta)[:, None]
    l = np.stack(np.broadcast_arrays(st * np.cos(phi)[None, :], st * np.sin(phi)[None, :],
                                     np.cos(theta)[:, None]), axis=-1)
    l[-1, :, 2] = 0.0  # the horizon ring, exactly
    v = np.array([math.sin(theta_v) * math.cos(phi_v), math.sin(theta_v) * math.sin(phi_v), math.cos(theta_v)])
    f = _evaluate(brdf, l, v)
    f_cos = f * np.maximum(l[..., 2:3], 0.0)
    radius = luminance(f_cos)
    return {"theta": theta, "phi": phi, "l": l, "v": v, "f": f, "f_cos": f_cos, "radius": radius,
            "points": radius[..., None] * l}


def _half_diff(brdf, theta_h, theta_d, phi_d):
    from ..measured.merl import directions_from_half_diff

    l, v = directions_from_half_diff(theta_h, theta_d, phi_d)
    return l, v, _evaluate(brdf, l, v)


def theta_h_slice(brdf, theta_d, phi_d=_HALF_PI, count=90):
    """f against theta_h in [0, pi/2] (``count`` cell centres) at fixed theta_d and
    phi_d (Burley 2012, fig. 3's slices; phi_d = pi/2 by default, the explorer's).
    Returns a dict: ``theta_h``, ``l``, ``v``, ``f`` (count, 3), ``value`` (luminance
    of f).  f is 0 where l or v is below the horizon."""
    theta_h = _centres(count)
    l, v, f = _half_diff(brdf, theta_h, theta_d, phi_d)
    return {"theta_h": theta_h, "l": l, "v": v, "f": f, "value": luminance(f)}


def theta_d_slice(brdf, theta_h, phi_d=_HALF_PI, count=90):
    """f against theta_d in [0, pi/2] (``count`` cell centres) at fixed theta_h and
    phi_d: the Fresnel and retro-reflection behaviour (Burley 2012, sec. 2.1).
    Returns a dict: ``theta_d``, ``l``, ``v``, ``f`` (count, 3), ``value``."""
    theta_d = _centres(count)
    l, v, f = _half_diff(brdf, theta_h, theta_d, phi_d)
    return {"theta_d": theta_d, "l": l, "v": v, "f": f, "value": luminance(f)}


def half_diff_image(brdf, phi_d=_HALF_PI, size=64):
    """The (theta_h, theta_d) image slice at fixed phi_d (Burley 2012, fig. 2; the
    explorer's "image slice"): row j at theta_d = (j + 0.5) / size pi/2 (row 0 at
    theta_d near 0, drawn at the bottom), column i at theta_h = (i + 0.5) / size
    pi/2.  Returns a dict: ``theta_h`` (size,), ``theta_d`` (size,), ``l``, ``v``,
    ``f`` (size, size, 3), ``value`` (luminance of f), ``log_value``
    (log10 max(value, 1e-3)), ``valid`` (both directions above the horizon)."""
    theta_h = _centres(size)
    theta_d = _centres(size)
    l, v, f = _half_diff(brdf, theta_h[None, :], theta_d[:, None], phi_d)
    value = luminance(f)
    return {"theta_h": theta_h, "theta_d": theta_d, "l": l, "v": v, "f": f, "value": value,
            "log_value": np.log10(np.maximum(value, 1e-3)), "valid": (l[..., 2] > 0.0) & (v[..., 2] > 0.0)}


# ================================================================ albedo

_MEASURED_NODE_ROUGHNESS = 0.2  # where albedo_quadrature places its nodes for a measured BRDF


def _albedo(brdf, mu, roughness, nodes):
    from ..albedo.furnace import albedo_quadrature

    def fn(l, v, n, r):  # albedo_quadrature places its nodes by the roughness; the BRDF keeps its own
        return _evaluate(brdf, l, v, n)

    return albedo_quadrature(fn, mu, [roughness], *nodes)[:, 0]


def directional_albedo(brdf, count=32, compensation="filament"):
    """Directional albedo E(theta_v) = integral of f (n.l) dl over the hemisphere,
    RGB, at theta_v = (i + 0.5) / count pi/2, by pbrkit's deterministic
    quadrature over the half vector (:func:`pbrkit.albedo.furnace.albedo_quadrature`,
    32 x 16 nodes per segment placed by the GGX lobe of the material's roughness:
    within 8e-5 of a 6 x 6 times denser rule for every model and roughness, URP's
    kink 3e-4, Disney's clear coat (a GTR1 lobe narrower than the nodes' lobe)
    5e-3 at clearcoat 1; a Lambertian lobe within 2.1e-5 of its analytic albedo,
    tests/explore/test_explore_views.py).

    For a :class:`ModelBRDF` also the white furnace of its specular lobe (F = 1,
    :meth:`ModelBRDF.white`: what single scattering keeps, Kulla & Conty 2017) and
    the white furnace of GGX with height-correlated Smith compensated by
    ``compensation`` (``filament``: 1 + F0 (1 / DFG2 - 1); ``kulla-conty``: the
    added f_ms lobe; :func:`pbrkit.albedo.compensation.white_furnace_compensated`,
    with the runtime DFG table lookups), at the material's roughness; None for
    a measured BRDF.  Returns a dict: ``theta_v``, ``mu`` = cos theta_v, ``albedo``
    (count, 3), ``value`` (its luminance), ``white`` (count,) or None,
    ``compensated`` (count,) or None, ``furnace`` (count,) = 1."""
    theta_v = _centres(count)
    mu = np.cos(theta_v)
    if compensation is not None and compensation not in COMPENSATIONS:
        raise ValueError(f"unknown compensation {compensation!r}; choose one of {', '.join(COMPENSATIONS)}")
    if isinstance(brdf, ModelBRDF):
        r = float(brdf.spec.roughness)
        albedo = _albedo(brdf, mu, r, _ALBEDO_NODES)
        white = _white_albedo(brdf.white().spec, count)
        compensated = None if compensation is None else _compensated_albedo(compensation, r, count)
    else:
        albedo = _cached(brdf, ("albedo", count), lambda: _albedo(brdf, mu, _MEASURED_NODE_ROUGHNESS, (64, 32)))
        white = compensated = None
    return {"theta_v": theta_v, "mu": mu, "albedo": albedo, "value": luminance(albedo), "white": white,
            "compensated": compensated, "furnace": np.ones(count), "compensation": compensation}


_ALBEDO_NODES = (32, 16)  # albedo_quadrature's (theta, phi) nodes (accuracy: directional_albedo)


@functools.lru_cache(maxsize=64)
def _white_albedo(white_spec, count):
    """The white furnace (count,) of a model's F = 1 lobe (:meth:`ModelBRDF.white`'s spec);
    cached: it depends on the roughness and the lobe, not on the colours the sliders move."""
    mu = np.cos(_centres(count))
    out = _albedo(ModelBRDF(white_spec), mu, float(white_spec.roughness), _ALBEDO_NODES)[:, 0]
    out.setflags(write=False)
    return out


@functools.lru_cache(maxsize=64)
def _compensated_albedo(method, roughness, count):
    from ..albedo.compensation import white_furnace_compensated

    out = white_furnace_compensated(method, np.cos(_centres(count)), [roughness])[:, 0]
    out.setflags(write=False)
    return out


# Per-BRDF results for measured BRDFs, which do not change while the sliders move:
# id -> (brdf, {key: value}); the identity check guards against a reused id.
_CACHE = {}


def _cached(brdf, key, compute):
    entry = _CACHE.get(id(brdf))
    if entry is None or entry[0] is not brdf:
        if len(_CACHE) >= 4:
            _CACHE.pop(next(iter(_CACHE)))
        entry = (brdf, {})
        _CACHE[id(brdf)] = entry
    if key not in entry[1]:
        entry[1][key] = compute()
    return entry[1][key]


# ================================================================ spheres

#: The camera of :func:`lit_sphere_environment`: the built-in ``sphere`` scene's
#: (a unit sphere at the origin seen from +z at 4.5, 32 degrees).
SPHERE_CAMERA = {"position": (0.0, 0.0, 4.5), "look_at": (0.0, 0.0, 0.0), "fov": 32.0}
#: Texels per cube face of the environment quadrature of measured BRDFs (:func:`lit_sphere_environment`).
_MEASURED_FACE = 12
#: Half the width of :func:`lit_sphere_point`'s frame (the sphere's radius is 1).
_SPHERE_FRAME = 1.1
#: Size of the specular cube of the environment's bake.
BAKE_SIZE = 64


def lit_sphere_point(brdf, light_theta, light_phi=0.0, size=96, irradiance=math.pi):
    """A unit sphere seen orthographically along -z, lit by a directional light.

    The camera frame is the world's (+x right, +y up, the eye at +z, so v = +z);
    the light comes from l = (sin theta cos phi, sin theta sin phi, cos theta)
    (theta from the view axis) with ``irradiance`` E on a surface facing it
    (default pi: a white Lambertian surface facing the light has radiance 1).
    Pixel (i, j) has its centre at x = s (2 (j + 0.5) / size - 1), y = s (1 - 2 (i + 0.5)
    / size) with s = 1.1 (a margin around the sphere); inside the disk the normal
    is n = (x, y, sqrt(1 - x^2 - y^2)) and the radiance L = f(l, v, n) max(n.l, 0) E, with the tangent of the renderer
    (:func:`pbrkit.brdf.bxdf.tangent_frame`: along the parallels about +Y, n x Y
    normalised) for anisotropic lobes.  Returns a dict: ``radiance`` (size,
    size, 3; 0 outside), ``mask``, ``normal``, ``light`` (3,)."""
    c = _SPHERE_FRAME * (2.0 * (np.arange(size) + 0.5) / size - 1.0)
    x, y = np.meshgrid(c, -c)
    r2 = x * x + y * y
    mask = r2 < 1.0
    n = np.stack([x, y, np.sqrt(np.maximum(0.0, 1.0 - r2))], axis=-1)
    st = math.sin(light_theta)
    light = np.array([st * math.cos(light_phi), st * math.sin(light_phi), math.cos(light_theta)])
    rows = n[mask]
    t = None
    if isinstance(brdf, ModelBRDF) and brdf.anisotropic:
        t = np.cross(rows, [0.0, 1.0, 0.0])
        length = np.linalg.norm(t, axis=-1, keepdims=True)
        t = np.where(length > 1e-6, t / np.maximum(length, 1e-300), [1.0, 0.0, 0.0])
    f = _evaluate(brdf, light[None, :], _N[None, :], rows, t)
    radiance = np.zeros((size, size, 3))
    radiance[mask] = f * np.maximum(rows @ light, 0.0)[:, None] * irradiance
    return {"radiance": radiance, "mask": mask, "normal": n, "light": light}


@functools.lru_cache(maxsize=2)
def _environment(bake_size=BAKE_SIZE):
    """The bundled environment (:class:`pbrkit.rendering.environment.EnvironmentLight`) and
    its bake (specular cube ``bake_size``, computed once per process)."""
    from ..rendering.environment import EnvironmentLight
    from ..rendering.scene import EnvironmentSpec

    env = EnvironmentLight(EnvironmentSpec())
    return env, env.bake(size=bake_size)


def _sphere_scene(spec, size):
    from ..rendering.scene import Camera, Scene, Sphere

    camera = Camera(width=size, height=size, **SPHERE_CAMERA)
    return Scene(camera=camera, materials={spec.name: spec}, objects=(Sphere(material=spec.name),),
                 source="pbrkit explore")


def lit_sphere_environment(brdf, size=96, bake_size=BAKE_SIZE):
    """A unit sphere under the bundled environment, through the camera of
    :data:`SPHERE_CAMERA` (``size`` x ``size`` pixels; the backdrop is the
    environment as the renderer draws it).

    A :class:`ModelBRDF` is rendered by pbrkit's real-time path
    (:func:`pbrkit.rendering.realtime.render_realtime`: split-sum IBL with the
    prefiltered chain and the DFG table, SH diffuse) with the environment's bake
    computed once per process.  A measured BRDF has no split sum: its sphere is
    the quadrature sum over the texels of the bake's level 0 (the environment
    itself, resampled with exact area weights) reduced to 12 x 12 per face
    (:func:`pbrkit.ibl.cubemap.resample_cube`, solid-angle block means), of
    f(l, v, n) L(l) max(n.l, 0) dOmega (:func:`pbrkit.ibl.cubemap.cube_texel_solid_angles`),
    computed once per BRDF.  Returns a dict: ``radiance`` (size, size, 3), ``mask``
    (the sphere's pixels)."""
    env, bake = _environment(bake_size)
    if isinstance(brdf, ModelBRDF):
        from ..rendering.realtime import render_realtime

        result = render_realtime(_sphere_scene(brdf.spec, size), env=env, bake=bake)
        return {"radiance": np.asarray(result.image, dtype=np.float64), "mask": np.asarray(result.mask, dtype=bool)}
    return _cached(brdf, ("environment", size, bake_size), lambda: _measured_sphere(brdf, size, env, bake))


def _sphere_hits(size):
    """Per pixel of the camera of :data:`SPHERE_CAMERA`: the ray directions
    (size, size, 3), the mask of rays that hit the unit sphere, and at those
    hits the normal (= the hit point) and v = -d."""
    from ..rendering.scene import Camera

    camera = Camera(width=size, height=size, **SPHERE_CAMERA)
    d = camera.ray_directions()[:, :, 0, :]
    o = np.asarray(camera.position)
    b = d @ o  # |o + t d|^2 = 1: t^2 + 2 b t + (|o|^2 - 1) = 0
    disc = b * b - (o @ o - 1.0)
    mask = disc > 0.0
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    p = o + t[..., None] * d
    return d, mask, p[mask], -d[mask]


def _measured_sphere(brdf, size, env, bake, face=_MEASURED_FACE, chunk=256):
    from ..ibl.cubemap import (
        cube_texel_directions,
        cube_texel_solid_angles,
        resample_cube,
    )

    d, mask, n, v = _sphere_hits(size)
    level0 = np.asarray(bake.specular[0], dtype=np.float64)
    cube = resample_cube(level0, face)
    dirs = cube_texel_directions(face).reshape(-1, 3)
    weight = (cube * cube_texel_solid_angles(face)[..., None]).reshape(-1, 3) * env.intensity
    out = np.zeros((n.shape[0], 3))
    for s in range(0, n.shape[0], chunk):
        nn, vv = n[s:s + chunk], v[s:s + chunk]
        cos = nn @ dirs.T  # (pixels, texels)
        p, k = np.nonzero(cos > 0.0)  # only the texels above each pixel's horizon
        f = _evaluate(brdf, dirs[k], vv[p], nn[p])
        np.add.at(out, s + p, f * (cos[p, k][:, None] * weight[k]))
    radiance = env.background(d.reshape(-1, 3)).reshape(size, size, 3)
    radiance[mask] = out
    return {"radiance": radiance, "mask": mask}


def display_rgba(radiance, exposure=0.0, operator="aces"):
    """8-bit sRGB RGBA (H, W, 4) of linear radiance: :func:`pbrkit.core.color.tonemap`
    then :func:`pbrkit.core.color.linear_to_srgb`, alpha 255."""
    rgb = np.rint(255.0 * linear_to_srgb(tonemap(radiance, operator, exposure))).astype(np.uint8)
    alpha = np.full(rgb.shape[:-1] + (1,), 255, dtype=np.uint8)
    return np.concatenate([rgb, alpha], axis=-1)


# ================================================================ terms


@kernel
def _terms_kernel(codes, params, roughness, metallic, base, l, v, out):
    # Per direction pair: the model's specular lobe D V, its visibility V and its Fresnel (RGB), from the
    # model's composition (pbrkit.brdf.dispatch: the same code the models and the renderer run).
    b = make_bxdf(codes, 0, params, 0, roughness, metallic, base[0], base[1], base[2])
    for i in range(l.shape[0]):
        c = local_cosines(v[i, 0], v[i, 1], v[i, 2], l[i, 0], l[i, 1], l[i, 2])
        out[i, 0] = specular_lobe(b, c)
        out[i, 1] = specular_visibility(b, c)
        f = bxdf_fresnel(b, c.voh)
        out[i, 2] = f[0]
        out[i, 3] = f[1]
        out[i, 4] = f[2]


def _lobe_terms(brdf, l, v):
    """(D V, V, F (N, 3)) of the model's specular lobe at local direction pairs (N, 3)."""
    from ..brdf.models import model_codes, parameter_rows

    m = brdf.material
    codes = model_codes(brdf.spec.model, material=m, **brdf.term_names)
    params = parameter_rows(m)
    out = np.empty((l.shape[0], 5))
    _terms_kernel(codes, params, float(m.roughness), float(m.metallic), np.ascontiguousarray(m.base_color, float),
                  np.ascontiguousarray(l, dtype=np.float64), np.ascontiguousarray(v, dtype=np.float64), out)
    return out[:, 0], out[:, 1], out[:, 2:]


def terms(brdf, theta_v, count=90):
    """The terms of a model's specular lobe alone, from its composition
    (:func:`pbrkit.brdf.dispatch.specular_lobe` = D V,
    :func:`~pbrkit.brdf.dispatch.specular_visibility` = V = G / (4 n.l n.v),
    :func:`~pbrkit.brdf.dispatch.bxdf_fresnel`), so that every model's own remaps
    apply (UE4's k = (r + 1)^2 / 8, Filament's f90, Disney's tint, ...):

    - ``D`` against ``theta_h`` in [0, pi/2) at l = v = h (n.l = n.v = n.h):
      D = (D V) / V; for ``urp_mobile``, whose term has no separate V, D is its
      GGX (:func:`pbrkit.microfacet.ggx.d_ggx`, alpha = r^2) and V = term / D;
    - ``G`` = V 4 (n.l)(n.v), the masking-shadowing G2, against ``theta_l`` in the
      plane of incidence with the view at ``theta_v`` (as :func:`incidence_plane`);
    - ``F`` (RGB) against ``theta_d`` (v.h = cos theta_d).

    Returns a dict with those arrays (count,) (F (count, 3)), or None for a
    measured BRDF (it has no terms)."""
    if not isinstance(brdf, ModelBRDF):
        return None
    theta_h = _centres(count)
    h = _plane_direction(theta_h)
    dv, vis, _ = _lobe_terms(brdf, h, h)
    if brdf.spec.model == "urp_mobile":
        d = d_ggx(h[:, 2], alpha_from_roughness(float(brdf.spec.roughness)))
    else:
        d = np.where(vis > 0.0, dv / np.where(vis > 0.0, vis, 1.0), 0.0)
    theta_l = np.linspace(-_HALF_PI, _HALF_PI, count + 2)[1:-1]
    l = _plane_direction(theta_l)
    v = np.broadcast_to(_plane_direction(theta_v), l.shape)
    dv_g, vis_g, _ = _lobe_terms(brdf, l, v)
    if brdf.spec.model == "urp_mobile":
        from ..core.vec import half_vector

        d_g = d_ggx(half_vector(l, v)[:, 2], alpha_from_roughness(float(brdf.spec.roughness)))
        vis_g = np.where(d_g > 0.0, dv_g / np.where(d_g > 0.0, d_g, 1.0), 0.0)
    g = vis_g * 4.0 * l[:, 2] * v[:, 2]
    theta_d = _centres(count)
    from ..measured.merl import directions_from_half_diff

    lf, vf = directions_from_half_diff(0.0, theta_d, 0.0)
    _, _, fresnel = _lobe_terms(brdf, lf, vf)
    return {"theta_h": theta_h, "D": d, "theta_l": theta_l, "G": g, "theta_d": theta_d, "F": fresnel,
            "theta_v": float(theta_v)}


# ================================================================ comparison


def compare(brdf_a, brdf_b, theta_v, phi_d=_HALF_PI, light_theta=_QUARTER_PI, size=64, count=181):
    """Two BRDFs side by side and their difference: the incidence-plane curves
    (:func:`incidence_plane`) and ``f_cos_difference`` = b - a (RGB and
    ``value_difference``, luminance); the half/difference images
    (:func:`half_diff_image`) and ``log_ratio`` = log10 (b / a) of their
    luminance where both are positive (NaN elsewhere); the point-lit spheres
    (:func:`lit_sphere_point`) and ``sphere_difference`` = b - a (RGB)."""
    pa, pb = incidence_plane(brdf_a, theta_v, count), incidence_plane(brdf_b, theta_v, count)
    ia, ib = half_diff_image(brdf_a, phi_d, size), half_diff_image(brdf_b, phi_d, size)
    sa, sb = lit_sphere_point(brdf_a, light_theta, 0.0, size), lit_sphere_point(brdf_b, light_theta, 0.0, size)
    both = (ia["value"] > 0.0) & (ib["value"] > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_ratio = np.where(both, np.log10(ib["value"] / np.where(both, ia["value"], 1.0)), np.nan)
    return {"plane_a": pa, "plane_b": pb, "f_cos_difference": pb["f_cos"] - pa["f_cos"],
            "value_difference": pb["value"] - pa["value"], "image_a": ia, "image_b": ib, "log_ratio": log_ratio,
            "sphere_a": sa, "sphere_b": sb, "sphere_difference": sb["radiance"] - sa["radiance"]}
