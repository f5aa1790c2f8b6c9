"""The ``pbrkit explore`` command (added to the ``pbrkit`` app by :mod:`pbrkit.cli`).

This module imports only Typer and the command line's own modules (``pbrkit
--help`` stays light); Panel, Bokeh, Matplotlib and pbrkit's models are imported
in the command's body.  Serving the app needs the ``explore`` extra (Panel,
Bokeh): without it the command says which ``pip install`` to run; ``--static``
needs only the base install.  The choices are written here for the same reason;
tests/explore/test_explore_static.py checks them against the library's lists.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .console import _Stages, need_extra, user_errors
from .options import OUT_DIR, _check_exposure, _choice, _flag, _quiet_option

#: ``pbrkit --help``'s line for the command.
SHORT_HELP = "Interactive BRDF explorer in the browser (--static: its views as PNG/SVG)."
#: The example ``pbrkit explore --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit explore --model disney --roughness 0.3 --compare gltf"

# pbrkit.brdf.models.MODELS, DISTRIBUTIONS, MASKINGS, FRESNELS, DIFFUSES; pbrkit.brdf.fresnel.CONDUCTORS;
# pbrkit.measured.fit.FIT_MODELS, FIT_WEIGHTINGS; pbrkit.explore.views.COMPENSATIONS
EXPLORE_MODELS = ("cook_torrance", "filament", "ue4", "urp_mobile", "disney", "gltf")
EXPLORE_DISTRIBUTIONS = ("ggx", "beckmann", "blinn-phong")
EXPLORE_MASKINGS = ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4", "kelemen", "implicit")
EXPLORE_FRESNELS = ("schlick", "schlick-pow4", "ue4-sg", "exact-conductor", "exact-dielectric", "none")
EXPLORE_DIFFUSES = ("lambert", "burley", "none", "eon")
EXPLORE_CONDUCTORS = ("aluminium", "copper", "gold", "silver")
EXPLORE_FIT_MODELS = ("ggx", "disney")
EXPLORE_FIT_WEIGHTINGS = ("log", "cosine")
EXPLORE_COMPENSATIONS = ("filament", "kulla-conty")
#: The optional material parameters: option -> Material field (each in [0, 1]; anisotropy in [-1, 1];
#: ior 0 or >= 1, checked by the material).
EXPLORE_PARAMETERS = {"--reflectance": "reflectance", "--anisotropy": "anisotropy", "--subsurface": "subsurface",
                      "--specular-tint": "specular_tint", "--sheen": "sheen", "--sheen-tint": "sheen_tint",
                      "--clearcoat": "clearcoat", "--clearcoat-gloss": "clearcoat_gloss",
                      "--sheen-roughness": "sheen_roughness", "--clearcoat-roughness": "clearcoat_roughness",
                      "--specular": "specular", "--ior": "ior", "--transmission": "transmission",
                      "--iridescence": "iridescence", "--iridescence-ior": "iridescence_ior",
                      "--iridescence-thickness": "iridescence_thickness_maximum",
                      "--anisotropy-strength": "anisotropy_strength", "--anisotropy-rotation": "anisotropy_rotation"}
#: The optional colour parameters: option -> Material field (R,G,B; sheen_color in [0, 1],
#: specular_color >= 0).
EXPLORE_COLOURS = {"--sheen-color": "sheen_color", "--specular-color": "specular_color"}
#: The upper end of each parameter's range where it is not 1 (checked here; the material checks again).
_HIGH = {"ior": float("inf"), "specular_color": float("inf"), "iridescence_ior": float("inf"),
         "iridescence_thickness_maximum": float("inf"), "anisotropy_rotation": 3.141592653589793}
#: The lower end where it is not 0.
_LOW = {"anisotropy": -1.0, "anisotropy_rotation": -3.141592653589793}


def _unit(option, value, lo=0.0, hi=1.0):
    import math

    if value is None:
        return None
    if not (math.isfinite(value) and lo <= value <= hi):
        raise ValueError(f"{option}: must be a number in [{lo:g}, {hi:g}]; got {value!r}")
    return float(value)


def _base_color(text, option="--base-color", hi=1.0):
    parts = text.split(",")
    try:
        rgb = tuple(float(x) for x in parts)
    except ValueError:
        rgb = ()
    if len(rgb) != 3:
        span = "in [0, 1]" if hi == 1.0 else ">= 0"
        raise ValueError(f"{option}: three comma-separated numbers R,G,B (linear, {span}); got {text!r}")
    for x in rgb:
        _unit(option, x, 0.0, hi)
    return rgb


def _angle(option, value, hi):
    return _unit(option, value, 0.0, hi)


#: The flag of each material key that a model's check can name (the rest of
#: EXPLORE_PARAMETERS' keys are added below).
_KEY_FLAGS = {"distribution": "--distribution", "masking": "--masking", "fresnel": "--fresnel",
              "diffuse": "--diffuse", "conductor": "--conductor", "base_color": "--base-color",
              "metallic": "--metallic", "roughness": "--roughness",
              **{name: option for option, name in EXPLORE_PARAMETERS.items()},
              **{name: option for option, name in EXPLORE_COLOURS.items()}}
_SPEC_PREFIX = "material 'explore': "


def _flagged(exc, model, compare=False):
    """A ValueError of :func:`pbrkit.explore.views.model_brdf` (a scene material's
    check, ``material 'explore': ...``: :class:`pbrkit.rendering.material_spec.MaterialSpec`)
    as one naming the flag: the option of the first material key the message
    names (``--fresnel: fresnel 'exact-conductor' needs ...``), else ``--model M``;
    for the second BRDF, ``--compare M``."""
    import re

    text = str(exc)
    if text.startswith(_SPEC_PREFIX):
        text = text[len(_SPEC_PREFIX):]
    if compare:
        return ValueError(f"--compare {model}: {text}")
    found = [(m.start(), flag) for key, flag in _KEY_FLAGS.items()
             for m in [re.search(rf"(?<![\w-]){re.escape(key)}(?![\w-])", text)] if m]
    flag = min(found)[1] if found and not text.startswith("unknown model") else f"--model {model}"
    return ValueError(f"{flag}: {text}")


def _model_brdf(V, model, *args, compare=False, **kwargs):
    """:func:`pbrkit.explore.views.model_brdf`, its errors naming the flag (:func:`_flagged`)."""
    try:
        return V.model_brdf(model, *args, **kwargs)
    except ValueError as exc:
        raise _flagged(exc, model, compare) from None


def _check_finite(what, values):
    """Raise a one-line ValueError naming ``what`` and the key if a number of
    ``values`` (a dict of numbers or sequences of numbers) is NaN or infinite."""
    import numpy as np

    for key, value in values.items():
        try:
            a = np.asarray(value, dtype=np.float64).ravel()
        except (TypeError, ValueError):  # not numbers (a name)
            continue
        bad = a[~np.isfinite(a)]
        if bad.size:
            raise ValueError(f"{what}: {key} is not finite ({bad[0]}); the measured values are too large to fit")


@user_errors
def explore(
    model: str = _choice("gltf", "--model", EXPLORE_MODELS, "model",
                         "Shading model (pbrkit.brdf.models); the second BRDF is --compare or --merl."),
    base_color: str = typer.Option("0.8,0.8,0.8", "--base-color", metavar="R,G,B",
                                   help="Base colour, linear RGB in [0, 1]."),
    metallic: float = typer.Option(0.0, "--metallic", metavar="M", help="Metallic in [0, 1]."),
    roughness: float = typer.Option(0.5, "--roughness", metavar="R",
                                    help="Perceptual roughness in [0, 1] (alpha = R^2 in every model)."),
    reflectance: Optional[float] = typer.Option(
        None, "--reflectance", metavar="X",
        help="Dielectric specular, f0 = 0.16 X^2 (default 0.5: f0 = 0.04; not gltf, urp_mobile)."),
    anisotropy: Optional[float] = typer.Option(
        None, "--anisotropy", metavar="A",
        help="cook_torrance, filament: [-1, 1]; disney: [0, 1] (Burley's aspect). Default 0."),
    subsurface: Optional[float] = typer.Option(None, "--subsurface", metavar="X", help="disney only."),
    specular_tint: Optional[float] = typer.Option(None, "--specular-tint", metavar="X", help="disney only."),
    sheen: Optional[float] = typer.Option(None, "--sheen", metavar="X", help="disney only."),
    sheen_tint: Optional[float] = typer.Option(None, "--sheen-tint", metavar="X",
                                               help="disney only (default 0.5)."),
    clearcoat: Optional[float] = typer.Option(None, "--clearcoat", metavar="X",
                                              help="disney; gltf (KHR_materials_clearcoat)."),
    clearcoat_gloss: Optional[float] = typer.Option(None, "--clearcoat-gloss", metavar="X",
                                                    help="disney only (default 1)."),
    clearcoat_roughness: Optional[float] = typer.Option(None, "--clearcoat-roughness", metavar="X",
                                                        help="gltf only (KHR_materials_clearcoat; default 0)."),
    sheen_color: Optional[str] = typer.Option(None, "--sheen-color", metavar="R,G,B",
                                              help="gltf only (KHR_materials_sheen; default 0,0,0)."),
    sheen_roughness: Optional[float] = typer.Option(None, "--sheen-roughness", metavar="X",
                                                    help="gltf only (KHR_materials_sheen; default 0)."),
    specular: Optional[float] = typer.Option(None, "--specular", metavar="X",
                                             help="gltf only (KHR_materials_specular; default 1)."),
    specular_color: Optional[str] = typer.Option(None, "--specular-color", metavar="R,G,B",
                                                 help="gltf, cook_torrance (KHR_materials_specular; >= 0, "
                                                      "default 1,1,1)."),
    ior: Optional[float] = typer.Option(None, "--ior", metavar="X",
                                        help="gltf only (KHR_materials_ior: 0 or >= 1; default 1.5)."),
    transmission: Optional[float] = typer.Option(
        None, "--transmission", metavar="X",
        help="gltf only (KHR_materials_transmission: the diffuse it takes; default 0)."),
    iridescence: Optional[float] = typer.Option(None, "--iridescence", metavar="X",
                                                help="gltf only (KHR_materials_iridescence; default 0)."),
    iridescence_ior: Optional[float] = typer.Option(None, "--iridescence-ior", metavar="X",
                                                    help="gltf only (the film's IOR, >= 1; default 1.3)."),
    iridescence_thickness_maximum: Optional[float] = typer.Option(
        None, "--iridescence-thickness", metavar="NM",
        help="gltf only (the film's thickness in nm; default 400)."),
    anisotropy_strength: Optional[float] = typer.Option(
        None, "--anisotropy-strength", metavar="X",
        help="gltf only (KHR_materials_anisotropy; default 0)."),
    anisotropy_rotation: Optional[float] = typer.Option(
        None, "--anisotropy-rotation", metavar="RAD",
        help="gltf only (from the tangent, in [-pi, pi]; default 0)."),
    distribution: str = _choice("ggx", "--distribution", EXPLORE_DISTRIBUTIONS, "distribution",
                                "cook_torrance's D."),
    masking: str = _choice("height-correlated", "--masking", EXPLORE_MASKINGS, "masking",
                           "cook_torrance's masking-shadowing G."),
    fresnel: str = _choice("schlick", "--fresnel", EXPLORE_FRESNELS, "Fresnel term", "cook_torrance's F."),
    diffuse: str = _choice("lambert", "--diffuse", EXPLORE_DIFFUSES, "diffuse lobe",
                           "cook_torrance's and filament's diffuse lobe."),
    conductor: Optional[str] = _choice(None, "--conductor", EXPLORE_CONDUCTORS, "conductor",
                                       "A metal's complex IOR (sets metallic 1 and the base colour; needed by "
                                       "--fresnel exact-conductor)."),
    compare: Optional[str] = _choice(None, "--compare", EXPLORE_MODELS, "model",
                                     "Second BRDF: this model with the same material, beside the first in "
                                     "every view and compared."),
    merl: Optional[Path] = typer.Option(None, "--merl", metavar="FILE",
                                        help="A MERL binary BRDF (.binary), shown as the second BRDF."),
    fit: Optional[str] = _choice(None, "--fit", EXPLORE_FIT_MODELS, "fit model",
                                 "With --static and --merl: fit this model to the measured BRDF and show the "
                                 "fit beside it (the app has a fit button)."),
    fit_weighting: str = _choice("log", "--fit-weighting", EXPLORE_FIT_WEIGHTINGS, "weighting",
                                 "The fit's objective (pbrkit.measured.fit)."),
    no_fit_fresnel: bool = _flag(False, ("--no-fit-fresnel",), "Fit GGX without Fresnel (a constant RGB scale)."),
    theta_v: float = typer.Option(45.0, "--theta-v", metavar="DEG", help="View angle from the normal, [0, 89]."),
    light_theta: float = typer.Option(45.0, "--light-theta", metavar="DEG",
                                      help="Point light's angle from the view axis (spheres), [0, 90]."),
    light_phi: float = typer.Option(135.0, "--light-phi", metavar="DEG",
                                    help="Point light's azimuth (0 = right, 90 = up), [0, 360]."),
    theta_h: float = typer.Option(0.0, "--theta-h", metavar="DEG", help="theta_h of the theta_d slice, [0, 90]."),
    theta_d: float = typer.Option(30.0, "--theta-d", metavar="DEG", help="theta_d of the theta_h slice, [0, 90]."),
    phi_d: float = typer.Option(90.0, "--phi-d", metavar="DEG",
                                help="phi_d of the slices and the image slice, [0, 180]."),
    exposure: float = typer.Option(0.0, "--exposure", metavar="EV", callback=_check_exposure,
                                   help="Exposure of the sphere images in EV."),
    compensation: str = _choice("filament", "--compensation", EXPLORE_COMPENSATIONS, "compensation",
                                "Multiple-scattering compensation of the albedo view's compensated curve."),
    port: int = typer.Option(0, "--port", metavar="N", help="Port on 127.0.0.1 (0: a free one)."),
    no_browser: bool = _flag(False, ("--no-browser",), "Do not open a browser (print the URL only)."),
    static: bool = _flag(False, ("--static",), "Write every view as PNG and SVG into -o DIR instead of serving."),
    out: Optional[Path] = typer.Option(None, "-o", "--out", metavar="DIR", parser=OUT_DIR,
                                       help="With --static: the output folder (absent or empty unless --force)."),
    force: bool = _flag(False, ("--force",), "With --static: replace a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Explore a BRDF: polar and 3D lobes, theta_h / theta_d slices and the (theta_h,
    theta_d) image, directional albedo with the furnace line and compensation, lit
    spheres under a point light and the bundled environment, D, G and F alone, and a
    second BRDF (a model or a MERL measurement, or a fit to it) side by side with
    the difference.  Serves a local web app on 127.0.0.1 (Panel / Bokeh; the values
    are pbrkit's models, computed in Python), or with --static writes the views
    as PNG and SVG into -o DIR."""
    import math

    if not static:  # the served app needs Panel and Bokeh; --static does not
        need_extra("pbrkit explore", "explore")
    if static and out is None:
        raise ValueError("--static needs -o DIR")
    if out is not None and not static:
        raise ValueError("-o/--out is for --static (the app is served, not written)")
    if force and not static:
        raise ValueError("--force is for --static")
    if not 0 <= port <= 65535:
        raise ValueError(f"--port: must be in [0, 65535]; got {port}")
    if fit is not None and (merl is None or not static):
        raise ValueError("--fit needs --merl and --static (the app has a fit button)")
    if fit is None and no_fit_fresnel:
        raise ValueError("--no-fit-fresnel is for --fit ggx")
    if fit is None and fit_weighting != "log":
        raise ValueError("--fit-weighting is for --fit")
    if fit == "disney" and no_fit_fresnel:
        raise ValueError("--no-fit-fresnel: only --fit ggx takes it (disney's Schlick Fresnel is part of the "
                         "model)")
    if compare is not None and merl is not None:
        raise ValueError("give --compare or --merl, not both (one second BRDF)")
    _unit("--metallic", metallic)
    _unit("--roughness", roughness)
    rgb = _base_color(base_color)
    values = locals()
    given = {name: _unit(option, values[name], _LOW.get(name, 0.0), _HIGH.get(name, 1.0))
             for option, name in EXPLORE_PARAMETERS.items() if values[name] is not None}
    given.update({name: _base_color(values[name], option, _HIGH.get(name, 1.0))
                  for option, name in EXPLORE_COLOURS.items() if values[name] is not None})
    angles = {"theta_v": _angle("--theta-v", theta_v, 89.0),
              "light_theta": _angle("--light-theta", light_theta, 90.0),
              "light_phi": _angle("--light-phi", light_phi, 360.0),
              "theta_h": _angle("--theta-h", theta_h, 90.0), "theta_d": _angle("--theta-d", theta_d, 90.0),
              "phi_d": _angle("--phi-d", phi_d, 180.0)}
    if static:
        from ..core.atomic import check_output_directory

        check_output_directory(out, force)
    else:
        from ..explore.server import check_port

        check_port(port)  # before any work: a port in use is refused with its one line
    from ..explore import views as V

    for option, name in {**EXPLORE_PARAMETERS, **EXPLORE_COLOURS}.items():
        if name in given and name not in V.MODEL_PARAMETERS[model] + V.COLOUR_PARAMETERS[model]:
            # (--compare takes those it has)
            having = [k for k in V.MODEL_PARAMETERS if name in V.MODEL_PARAMETERS[k] + V.COLOUR_PARAMETERS[k]]
            raise ValueError(f"{option}: model {model!r} has no {name} (models with it: {', '.join(having)})")
    terms = {}
    if model == "cook_torrance":
        terms = {"distribution": distribution, "masking": masking, "fresnel": fresnel, "diffuse": diffuse}
    else:
        for option, value, default in (("--distribution", distribution, "ggx"),
                                       ("--masking", masking, "height-correlated"),
                                       ("--fresnel", fresnel, "schlick")):
            if value != default:
                raise ValueError(f"{option}: only model cook_torrance takes it (model {model!r} fixes its terms)")
        if diffuse != "lambert":
            if model != "filament":
                raise ValueError("--diffuse: only models cook_torrance and filament take it")
            terms = {"diffuse": diffuse}
    first = _model_brdf(V, model, rgb, metallic, roughness, conductor=conductor, **terms, **given)
    second = None
    measured = None
    if compare is not None:
        second_terms = {}
        if compare == "cook_torrance":
            second_terms = terms
        elif compare == "filament" and "diffuse" in terms:
            second_terms = {"diffuse": terms["diffuse"]}
        second = _model_brdf(V, compare, rgb, metallic, roughness, conductor=conductor, **second_terms,
                             compare=True, **V.applicable_parameters(compare, given))
    if merl is not None:
        from ..measured.merl import read_merl

        measured = read_merl(merl)
        second = measured
    radians = {k: math.radians(v) for k, v in angles.items()}
    if static:
        _write_static(out, first, second, measured, fit, fit_weighting, not no_fit_fresnel, radians, exposure,
                      compensation, force, quiet)
        return
    _serve(dict(model=model, base_color=rgb, metallic=metallic, roughness=roughness, conductor=conductor,
                second=compare or ("measured" if merl is not None else "none"), merl=merl, exposure=exposure,
                compensation=compensation, **radians, **terms, **given), port, no_browser, quiet)


def _write_static(out, first, second, measured, fit, weighting, fit_fresnel, radians, exposure, compensation, force,
                  quiet):
    from ..explore import views as V
    from ..explore.static import VIEW_NAMES, write_static

    extra = {}
    names = [n for n in VIEW_NAMES if n != "compare" or second is not None]
    with _Stages("explore", quiet, len(names) + 1 + (fit is not None)) as stages:
        if fit is not None:
            from ..measured.fit import FIT_MAX_THETA, fit_measured

            stages.start(f"fit {fit}")
            try:
                result = fit_measured(measured, model=fit, fresnel=fit_fresnel, weighting=weighting,
                                      max_theta=FIT_MAX_THETA)
            except ValueError as exc:
                raise ValueError(f"--fit {fit}: {exc}") from None
            what = f"--fit {fit}: the fit to {measured.name!r}"
            _check_finite(what, result.parameters)
            _check_finite(what, {f"error {k}": v for k, v in result.error.items()})
            first = V.fitted_brdf(result)
            extra["fit"] = {"model": result.model, "fresnel": result.fresnel, "weighting": result.weighting,
                            "parameters": result.parameters, "error": result.error, "measured": result.name}
        files = write_static(out, first, second, force=force, progress=stages.start, extra=extra,
                             exposure=exposure, compensation=compensation, **radians)
    if not quiet:
        if fit is not None:
            e = extra["fit"]["error"]
            print(f"fit {fit} to {measured.name}: rms_log {e['rms_log']:.4g}, relative_l2 {e['relative_l2']:.4g} "
                  f"over {e['bins']} bins")
        print(f"wrote {out}: " + ", ".join(files))


def _serve(kwargs, port, no_browser, quiet):
    import sys

    from ..core.errors import Terminated

    with _Stages("explore", quiet, 3) as stages:
        stages.start("load")
        from ..explore import views as V
        from ..explore.app import Explorer, serve

        stages.start("bake the environment")
        V.lit_sphere_environment(V.model_brdf())
        stages.start("first views")
        Explorer(**kwargs)  # compiles what the sessions run, and checks the options once
    try:
        serve(port=port, open_browser=not no_browser,
              announce=lambda url: print(f"pbrkit explore: serving {url} (Ctrl-C stops)", flush=True), **kwargs)
    except Terminated:
        raise
    except KeyboardInterrupt:  # Ctrl-C is how a server stops: a clean exit, status 0
        pass
    if not quiet:
        print("pbrkit explore: stopped", file=sys.stderr)
