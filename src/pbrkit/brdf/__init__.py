"""BRDFs, built on the microfacet distributions of :mod:`pbrkit.microfacet`: the
D terms and remaps re-exported by name (:mod:`~pbrkit.brdf.distributions`, a
facade), masking-shadowing G and visibility V (:mod:`~pbrkit.brdf.masking`:
the Schlick-GGX, Kelemen and Neubelt approximations, and the Smith terms of
the units re-exported), Fresnel F (:mod:`~pbrkit.brdf.fresnel`), diffuse lobes
(:mod:`~pbrkit.brdf.diffuse`), the metallic-roughness material
(:mod:`~pbrkit.brdf.material`), and the shading models composed from them once
(:mod:`~pbrkit.brdf.bxdf`, with each model's value, sampling routine and pdf
side by side) with their NumPy API (:mod:`~pbrkit.brdf.models`)."""
