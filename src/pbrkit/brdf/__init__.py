"""BRDFs: the microfacet distributions D (:mod:`~pbrkit.brdf.distributions`),
masking-shadowing G and visibility V (:mod:`~pbrkit.brdf.masking`), Fresnel F
(:mod:`~pbrkit.brdf.fresnel`), diffuse lobes (:mod:`~pbrkit.brdf.diffuse`),
the metallic-roughness material (:mod:`~pbrkit.brdf.material`), and the
shading models composed from them once (:mod:`~pbrkit.brdf.bxdf`, with each
model's value, sampling routine and pdf side by side) with their NumPy API
(:mod:`~pbrkit.brdf.models`)."""
