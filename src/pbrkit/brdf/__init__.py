"""BRDFs, built on the microfacet distributions of :mod:`pbrkit.microfacet`.

The terms: the D terms and remaps re-exported by name
(:mod:`~pbrkit.brdf.distributions`, a facade), masking-shadowing G and
visibility V (:mod:`~pbrkit.brdf.masking`: the Schlick-GGX, Kelemen and
Neubelt approximations, and the Smith terms of the units re-exported),
Fresnel F (:mod:`~pbrkit.brdf.fresnel`), diffuse factors
(:mod:`~pbrkit.brdf.diffuse`); the named choices among them as method tables
(:mod:`~pbrkit.brdf.terms`).

What models are made of: parameter declarations (:mod:`~pbrkit.brdf.parameters`),
the BxDF record and the shading frame (:mod:`~pbrkit.brdf.bxdf`), lobes with
their value, sampling routine, pdf and albedo side by side
(:mod:`~pbrkit.brdf.lobes`), and the layering operators that compose them
(:mod:`~pbrkit.brdf.operators`).

The models: one module each in :mod:`~pbrkit.brdf.shading`, listed by its
registry; the dispatch generated from it (:mod:`~pbrkit.brdf.dispatch`), the
material generated from their declarations (:mod:`~pbrkit.brdf.material`), and
the NumPy API (:mod:`~pbrkit.brdf.models`)."""
