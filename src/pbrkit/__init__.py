"""pbrkit: physically based shading for real-time rendering.

The subpackages follow the theory, from the formulas up to the application:

- :mod:`pbrkit.core`: compiled helpers (:mod:`~pbrkit.core.jit`), vectors,
  colour and tone mapping, quadrature rules, errors, atomic file output;
- :mod:`pbrkit.sampling`: low-discrepancy points, generic warps with their
  pdfs, counter-based random numbers;
- :mod:`pbrkit.microfacet`: one unit per microfacet distribution (GGX,
  Beckmann, Blinn-Phong, GTR): D, Smith Lambda and G1, sampling and pdfs, and
  the roughness remaps;
- :mod:`pbrkit.brdf`: the BRDF terms (F, diffuse, the masking approximations,
  and the distributions' D and G re-exported), the material, and the shading
  models, each composed once (:mod:`~pbrkit.brdf.bxdf`);
- :mod:`pbrkit.albedo`: directional albedo (the white furnace), the
  split-sum / DFG lookup tables, energy compensation, and the error of the
  real-time approximations;
- :mod:`pbrkit.ibl`: cube maps, equirectangular maps, spherical harmonics,
  GGX prefiltering, irradiance and the bake;
- :mod:`pbrkit.io`: image files, float packing, KTX2, DDS, table and bake
  files, environment loading;
- :mod:`pbrkit.engines`: Filament, the Khronos Sample Viewer, three.js and
  Babylon.js: each one's level curve, IBL shading, target writer and pinned
  version (``bake --target``, ``render --engine``);
- :mod:`pbrkit.rendering`: scenes, lights, geometry, real-time shading and the
  Monte Carlo ground truth;
- :mod:`pbrkit.app`: the command line, the demo and the reports.

The names of the README's API tour are importable from here: :func:`render` (a
scene rendered in one call, returned as arrays: :class:`Rendering`), :func:`bake`
(an environment baked for image-based lighting; :func:`write_bake` and
:func:`load_bake` its files), :func:`load_scene` and
:func:`scene_from_dict`, ``Material``, and the modules ``models``,
``distributions``, ``masking``, ``fresnel``, ``diffuse``, ``sampling``,
``microfacet`` and ``tables``.  They are imported on first use, as are the
subpackages, so that ``import pbrkit`` and ``pbrkit --help`` do not load NumPy
and Numba.
"""

__all__ = ["render", "Rendering", "bake", "write_bake", "load_bake", "load_scene", "scene_from_dict", "Material", "__version__", "models",
           "distributions", "masking", "fresnel", "diffuse", "sampling", "microfacet", "tables"]

#: The names of the API tour, imported on first use (PEP 562) so that ``import
#: pbrkit`` (and ``pbrkit --help``) does not pay for NumPy and Numba.
_LAZY = {
    "render": ("pbrkit.rendering.run", "render"),
    "Rendering": ("pbrkit.rendering.result", "Rendering"),
    "bake": ("pbrkit.ibl.bake", "bake"),
    "write_bake": ("pbrkit.io.bake_files", "write_bake"),
    "load_bake": ("pbrkit.io.bake_files", "load_bake"),
    "load_scene": ("pbrkit.rendering.scene", "load_scene"),
    "scene_from_dict": ("pbrkit.rendering.scene", "scene_from_dict"),
    "sampling": ("pbrkit.sampling", None),
    "microfacet": ("pbrkit.microfacet", None),
    "tables": ("pbrkit.albedo.tables", None),
    "diffuse": ("pbrkit.brdf.diffuse", None),
    "distributions": ("pbrkit.brdf.distributions", None),
    "fresnel": ("pbrkit.brdf.fresnel", None),
    "masking": ("pbrkit.brdf.masking", None),
    "models": ("pbrkit.brdf.models", None),
    "Material": ("pbrkit.brdf.material", "Material"),
}

_SUBPACKAGES = {"core", "sampling", "microfacet", "brdf", "albedo", "ibl", "io", "engines", "ltc", "rendering", "npr",
                "measured", "explore", "shaders", "app"}


def _package_version():
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pbrkit")
    except PackageNotFoundError:  # running from a source tree
        return "0.0.0+unknown"


def __getattr__(name):
    from importlib import import_module

    if name == "__version__":
        value = _package_version()
    elif name in _LAZY:
        module, attribute = _LAZY[name]
        value = import_module(module)
        if attribute is not None:
            value = getattr(value, attribute)
    elif name in _SUBPACKAGES:
        value = import_module(f"pbrkit.{name}")
    else:
        raise AttributeError(f"module 'pbrkit' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(__all__) | _SUBPACKAGES)
