"""The names of every option with a fixed set of values, defined once: the library
validates against these tuples and the command line offers them, so ``pbrkit --help``
lists them without importing NumPy, Numba or the renderers (this module imports
nothing).  Where a library module keeps a table keyed by the names (the visibility
codes of :mod:`pbrkit.albedo.tables`, the texel formats of :mod:`pbrkit.ibl.bake`) its
keys are these names, in this order (tests/app/test_bad_inputs.py checks)."""

__all__ = ["MODES", "TONEMAPS", "DIFFUSE_MODES", "RENDER_ENGINES", "LTC_CLIPPINGS", "LUT_KINDS", "VISIBILITIES",
           "LTC_FIT_F0", "KTX2_FORMATS", "BAKE_FORMATS", "BAKE_METHODS", "BAKE_TARGETS", "SH_WINDOWS", "LAYOUTS",
           "COMPENSATIONS", "LOBES", "SHADER_TARGETS"]

#: ``pbrkit render --mode`` (:func:`pbrkit.render`).
MODES = ("realtime", "reference", "compare")
#: Tone mappers (:func:`pbrkit.core.color.tonemap`).
TONEMAPS = ("aces", "khronos-neutral", "agx", "reinhard", "none")
#: The real-time diffuse: the bake's 9 SH coefficients or its irradiance cube.
DIFFUSE_MODES = ("sh", "cube")
#: Whose image-based lighting the real-time image follows (:mod:`pbrkit.rendering.realtime`): pbrkit's
#: own, or an engine's (:data:`pbrkit.engines.ENGINES`, the others in this order).
RENDER_ENGINES = ("pbrkit", "filament", "khronos", "three", "babylon")
#: The LTC fit's horizon clipping (:mod:`pbrkit.ltc.fit`).
LTC_CLIPPINGS = ("sphere", "exact")
#: ``pbrkit ltc --fit-f0``'s default, the normal reflectances the drop-in table's fit
#: weighs (:data:`pbrkit.ltc.fit.FIT_F0` is this tuple; chosen by measurement,
#: ``bench/ltc.md``).
LTC_FIT_F0 = (1.0, 0.04)
#: ``pbrkit lut`` tables (:func:`pbrkit.albedo.lut.lookup_table`).
LUT_KINDS = ("splitsum", "dfg")
#: The tables' Smith visibility terms (:data:`pbrkit.albedo.tables.VISIBILITIES`).
VISIBILITIES = ("schlick-ggx", "separable", "height-correlated")
#: The texel formats of ``pbrkit lut``'s KTX2 files (:func:`pbrkit.io.lut_files.write_lut`).
KTX2_FORMATS = ("float16", "float32")
#: The bake's specular texel formats (:data:`pbrkit.ibl.bake.SPECULAR_FORMATS`).
BAKE_FORMATS = ("rgba16f", "b10g11r11")
#: ``pbrkit bake --target``: pbrkit's own files, or an engine's (:data:`pbrkit.engines.ENGINES`),
#: in the order they are written.
BAKE_TARGETS = ("generic", "filament", "khronos", "babylon", "three")
#: The bake's prefiltering methods (:func:`pbrkit.ibl.bake.bake`).
BAKE_METHODS = ("spectral", "fis")
#: Windows of the stored SH (:func:`pbrkit.ibl.sh.sh_window`).
SH_WINDOWS = ("hanning", "lanczos")
#: Layouts of a single environment file (:func:`pbrkit.io.environment.load_environment`).
LAYOUTS = ("equirect", "hcross", "vcross")
#: Multiple-scattering compensations of ``pbrkit furnace --compensation``.
COMPENSATIONS = ("kulla-conty", "filament")
#: The furnace's lobes (:func:`pbrkit.albedo.furnace.furnace_lobes`).
LOBES = tuple(f"{d}/{g}" for d in ("ggx", "beckmann", "blinn-phong")
              for g in ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4", "kelemen",
                        "implicit")) + ("ue4", "filament", "urp_mobile")
#: ``pbrkit shaders --target`` (:data:`pbrkit.shaders.TARGETS`).
SHADER_TARGETS = ("glsl",)
