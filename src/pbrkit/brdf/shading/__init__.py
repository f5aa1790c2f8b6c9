"""The shading models, one module each (:mod:`.gltf`, :mod:`.ue4`,
:mod:`.filament`, :mod:`.urp_mobile`, :mod:`.disney`, :mod:`.cook_torrance`):
each declares its parameters, how the BxDF is set up from them, its
composition of lobes (:mod:`pbrkit.brdf.lobes`, :mod:`pbrkit.brdf.operators`)
and its real-time treatment, as a :class:`.model.Model`.  :mod:`.registry`
lists them, one line each; generated from it: the dispatch the kernels call
(:mod:`pbrkit.brdf.dispatch`), :class:`pbrkit.Material`, the packed parameter
row, the scene-file keys and their checks (:mod:`pbrkit.rendering.material_spec`),
the explorer's controls and the documentation's parameter table
(:func:`pbrkit.brdf.parameters.markdown_table`).  The NumPy API is
:mod:`pbrkit.brdf.models`.
"""
