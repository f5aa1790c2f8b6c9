// pbrkit_khr.glsl: the terms of the glTF extensions KHR_materials_sheen and
// KHR_materials_iridescence as pbrkit evaluates them (pbrkit.microfacet.charlie,
// pbrkit.brdf.lobes.sheen, pbrkit.brdf.fresnel.f_iridescence), in GLSL.
//
// GLSL ES 3.00 (WebGL2) and GLSL 3.30+ (desktop OpenGL): add your own version
// line before this file.  Needs pbrkit_brdf.glsl before it (F_Schlick,
// V_Neubelt, pbrkit_f0FromIOR, PBRKIT_PI).  Every function is tested against the
// pbrkit function named in its "pbrkit:" line in WebGL2 (tests/shaders/test_shaders_khr.py).
//
// Sheen roughness: every Charlie term takes alpha = sheenRoughness^2 (the
// specification's alpha_g), floored at 1e-12 (pbrkit_charlieAlpha), never the
// sheen roughness itself; the table lookups take the sheen roughness.
//
// The E_sheen table (pbrkit/data/sheen_albedo.npy, 33 x 33, indexed [i, j]):
// row i at sheenRoughness = i / 32, column j at n.v = j / 32 -- GRID POINTS, not
// texel centres as the DFG table of pbrkit_ibl.glsl has.  Upload it as is (row 0
// first, one channel in .r: R32F, or RG32F with anything in .g) with CLAMP_TO_EDGE
// and no mipmaps; pbrkit_fetchSheenAlbedo and pbrkit_sampleSheenAlbedo map
// (n.v, sheenRoughness) onto the grid points.  (A texture(table, vec2(NoV,
// sheenRoughness)) straight on it, as the glTF Sample Viewer reads its own E
// table, would read pbrkit's table half a texel off.)

precision highp float;

#ifndef PBRKIT_PI
#define PBRKIT_PI 3.14159265358979
#endif
// pbrkit.microfacet.charlie._ALPHA_MIN: the smallest Charlie alpha.
#define PBRKIT_CHARLIE_ALPHA_MIN 1e-12

// ------------------------------------------------------------ KHR_materials_sheen: Charlie D and V

// pbrkit_charlieAlpha: alpha = sheenRoughness^2, floored at 1e-12.
// source: KHR_materials_sheen, "Sheen distribution" (alpha_g = sheenRoughness * sheenRoughness)
// roughness: alpha = sheenRoughness^2, clamped below at 1e-12 (PBRKIT_CHARLIE_ALPHA_MIN)
// pbrkit: pbrkit.microfacet.charlie.charlie_alpha
float pbrkit_charlieAlpha(float sheenRoughness) {
    return max(sheenRoughness * sheenRoughness, PBRKIT_CHARLIE_ALPHA_MIN);
}

// D_Charlie: the Charlie sheen distribution D = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi), the sine
//   taken as (1 - (n.h)^2)^(1 / (2 alpha)) with n.h clamped to [0, 1]; 0 for n.h < 0.
// source: Estevez & Kulla 2017, "Production Friendly Microfacet Sheen BRDF", eq. 2; KHR_materials_sheen "Sheen distribution"
// roughness: takes alpha = sheenRoughness^2 (pbrkit_charlieAlpha), floored at 1e-12
// pbrkit: pbrkit.microfacet.charlie.d_charlie
float D_Charlie(float NoH, float alpha) {
    float a = max(alpha, PBRKIT_CHARLIE_ALPHA_MIN);
    float c = clamp(NoH, 0.0, 1.0);
    float sin2 = (1.0 - c) * (1.0 + c);
    return NoH >= 0.0 ? (2.0 + 1.0 / a) * pow(sin2, 0.5 / a) * (0.5 / PBRKIT_PI) : 0.0;
}

// pbrkit_lambdaSheenFit: Estevez and Kulla's fitted curve L(x) = a / (1 + b x^c) + d x + e, each coefficient
//   interpolated between its alpha = 0 and alpha = 1 fit by t = (1 - alpha)^2 (x clamped at 0 in the power).
// source: Estevez & Kulla 2017, sec. 3 and Table 1; KHR_materials_sheen "Sheen visibility" (l(x, alpha_g))
// roughness: takes alpha = sheenRoughness^2 (pbrkit_charlieAlpha)
// pbrkit: pbrkit.microfacet.charlie._lambda_fit
float pbrkit_lambdaSheenFit(float x, float alpha) {
    float t = (1.0 - alpha) * (1.0 - alpha);
    float a = mix(21.5473, 25.3245, t);
    float b = mix(3.82987, 3.32435, t);
    float c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t);
    float e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(max(x, 0.0), c)) + d * x + e;
}

// Lambda_Charlie: the fitted Smith Lambda of the Charlie distribution: exp(L(|cos|)) for |cos| < 0.5,
//   exp(2 L(0.5) - L(1 - |cos|)) beyond (L of pbrkit_lambdaSheenFit).
// source: Estevez & Kulla 2017, sec. 3; KHR_materials_sheen "Sheen visibility" (lambda_sheen)
// roughness: takes alpha = sheenRoughness^2 (pbrkit_charlieAlpha)
// pbrkit: pbrkit.microfacet.charlie.lambda_charlie
float Lambda_Charlie(float cosTheta, float alpha) {
    float x = abs(cosTheta);
    return x < 0.5 ? exp(pbrkit_lambdaSheenFit(x, alpha))
                   : exp(2.0 * pbrkit_lambdaSheenFit(0.5, alpha) - pbrkit_lambdaSheenFit(max(1.0 - x, 0.0), alpha));
}

// G2_Charlie: the height-correlated masking-shadowing 1 / (1 + Lambda(n.v) + Lambda(n.l)) of the fitted Lambda
//   (no terminator softening, as the specification leaves it out).
// source: Estevez & Kulla 2017, sec. 3; KHR_materials_sheen "Sheen visibility"
// roughness: takes alpha = sheenRoughness^2 (pbrkit_charlieAlpha)
// pbrkit: pbrkit.microfacet.charlie.g2_charlie
float G2_Charlie(float NoL, float NoV, float alpha) {
    return 1.0 / (1.0 + Lambda_Charlie(NoV, alpha) + Lambda_Charlie(NoL, alpha));
}

// V_Charlie: the KHR_materials_sheen visibility V = G2_Charlie / (4 n.l n.v); 0 unless n.l > 0 and n.v > 0.
// source: KHR_materials_sheen "Sheen visibility" (sheen_visibility); Estevez & Kulla 2017, sec. 3
// roughness: takes alpha = sheenRoughness^2 (pbrkit_charlieAlpha)
// pbrkit: pbrkit.microfacet.charlie.v_charlie
float V_Charlie(float NoL, float NoV, float alpha) {
    return (NoL > 0.0 && NoV > 0.0) ? G2_Charlie(NoL, NoV, alpha) / (4.0 * NoL * NoV) : 0.0;
}

// V_Ashikhmin: the cheaper sheen visibility 1 / (4 (n.l + n.v - n.l n.v)) the specification allows on
//   constrained devices (not energy conserving under the albedo scaling, whose table assumes V_Charlie);
//   0 unless n.l > 0 and n.v > 0.  The same formula as V_Neubelt (pbrkit_brdf.glsl), which it calls.
// source: Ashikhmin & Premoze 2007, "Distribution-based BRDFs"; Neubelt & Pettineo 2013; KHR_materials_sheen "Sheen visibility"
// roughness: none
// pbrkit: pbrkit.microfacet.charlie.v_ashikhmin
float V_Ashikhmin(float NoL, float NoV) {
    return V_Neubelt(NoL, NoV);
}

// pbrkit_sheenBRDF: the sheen lobe f_sheen = sheenColor D_Charlie(n.h) V_Charlie(n.l, n.v) (no Fresnel), f not f cos.
// source: KHR_materials_sheen "Implementation Notes" (SheenBRDF = nu_S D_S); Estevez & Kulla 2017
// roughness: sheen roughness -> alpha = sheenRoughness^2 (pbrkit_charlieAlpha)
// pbrkit: pbrkit.brdf.lobes.sheen.sheen_value
vec3 pbrkit_sheenBRDF(vec3 sheenColor, float sheenRoughness, float NoH, float NoL, float NoV) {
    float alpha = pbrkit_charlieAlpha(sheenRoughness);
    return sheenColor * (D_Charlie(NoH, alpha) * V_Charlie(NoL, NoV, alpha));
}

// ------------------------------------------------------------ KHR_materials_sheen: albedo scaling

// pbrkit_fetchSheenAlbedo: E_sheen(n.v, sheenRoughness) from the E_sheen table (see the file's header) by
//   texelFetch, bilinear between GRID POINTS (n.v = j / (N - 1), sheenRoughness = i / (M - 1)), both arguments
//   clamped to [0, 1]: full float precision, and works with unfilterable R32F / RG32F textures.  Reads .r.
// source: Estevez & Kulla 2017 (the albedo E of the sheen lobe); KHR_materials_sheen "Albedo-scaling technique" (x = VdotN, y = sheenRoughness)
// roughness: sheen roughness (the table's rows), not alpha
// pbrkit: pbrkit.brdf.lobes.sheen.sheen_albedo_lookup, pbrkit.brdf.lobes.sheen.sheen_albedo_table
float pbrkit_fetchSheenAlbedo(highp sampler2D table, float NoV, float sheenRoughness) {
    ivec2 size = textureSize(table, 0);
    vec2 t = clamp(vec2(NoV, sheenRoughness), 0.0, 1.0) * vec2(size - 1);
    ivec2 i0 = min(ivec2(t), max(size - 2, 0));
    ivec2 i1 = min(i0 + 1, size - 1);
    vec2 a = t - vec2(i0);
    float t00 = texelFetch(table, ivec2(i0.x, i0.y), 0).r;
    float t10 = texelFetch(table, ivec2(i1.x, i0.y), 0).r;
    float t01 = texelFetch(table, ivec2(i0.x, i1.y), 0).r;
    float t11 = texelFetch(table, ivec2(i1.x, i1.y), 0).r;
    return (t00 * (1.0 - a.x) + t10 * a.x) * (1.0 - a.y) + (t01 * (1.0 - a.x) + t11 * a.x) * a.y;
}

// pbrkit_sampleSheenAlbedo: the same lookup with the GPU's bilinear filter (LINEAR, CLAMP_TO_EDGE, no mipmaps; a
//   filterable format such as R16F, or R32F with OES_texture_float_linear): grid point k of N lies at the texel
//   centre (k + 0.5) / N, so the coordinates are (x (N - 1) + 0.5) / N of x = (n.v, sheenRoughness) in [0, 1].
// source: KHR_materials_sheen "Albedo-scaling technique"; OpenGL 4.6 sec. 8.14.2 (texel selection)
// roughness: sheen roughness (the table's rows), not alpha
// pbrkit: pbrkit.brdf.lobes.sheen.sheen_albedo_lookup
float pbrkit_sampleSheenAlbedo(highp sampler2D table, float NoV, float sheenRoughness) {
    vec2 size = vec2(textureSize(table, 0));
    vec2 uv = (clamp(vec2(NoV, sheenRoughness), 0.0, 1.0) * (size - 1.0) + 0.5) / size;
    return texture(table, uv).r;
}

// pbrkit_sheenAlbedoScaling: the base's scale under the sheen, 1 - max3(sheenColor) E_sheen(n.v), E from
//   pbrkit_fetchSheenAlbedo or pbrkit_sampleSheenAlbedo at (n.v, sheenRoughness) (the simplified n.v-only form;
//   negative where E > 1, as the specification's fitted visibility gives near grazing at small sheen roughness).
// source: KHR_materials_sheen "Albedo-scaling technique" (sheen_albedo_scaling); Estevez & Kulla 2017
// roughness: none (the lookup took the sheen roughness)
// pbrkit: pbrkit.brdf.lobes.sheen.sheen_albedo_scaling
float pbrkit_sheenAlbedoScaling(vec3 sheenColor, float sheenAlbedo) {
    return 1.0 - max(max(sheenColor.r, sheenColor.g), sheenColor.b) * sheenAlbedo;
}

// ------------------------------------------------------------ KHR_materials_sheen: image-based lighting

// pbrkit_sampleSheen: Charlie-prefiltered radiance of a cube map whose level m of M holds sheen roughness
//   m / (M - 1) (as the Khronos IBL sampler's Charlie output), at the reflection of v about n, lod =
//   sheenRoughness (M - 1) (clamped to [0, M - 1]), trilinear filtering (LINEAR_MIPMAP_LINEAR).  pbrkit bakes
//   no Charlie cube; the mapping is the one pbrkit_sampleSpecular uses for its GGX levels.
// source: glTF-Sample-Viewer ibl.glsl (getIBLRadianceCharlie: lod = sheenRoughness (mipCount - 1) at reflect(-v, n)); Karis 2013 split sum
// roughness: sheen roughness r -> lod = r (M - 1), not alpha
// pbrkit: pbrkit.ibl.prefilter.level_of_roughness, pbrkit.ibl.cubemap.sample_cube
vec3 pbrkit_sampleSheen(highp samplerCube charlie, vec3 n, vec3 v, float sheenRoughness, float levels) {
    vec3 dir = normalize(reflect(-v, n));
    return textureLod(charlie, dir, clamp(sheenRoughness, 0.0, 1.0) * (levels - 1.0)).rgb;
}

// pbrkit_sheenIBL: the split-sum sheen radiance prefiltered * sheenColor * E, prefiltered from pbrkit_sampleSheen
//   and E the white sheen lobe's albedo at (n.v, sheenRoughness): pbrkit_fetchSheenAlbedo (D_Charlie V_Charlie,
//   the albedo the scaling uses), or the cloth channel (.b) of `pbrkit lut --cloth` (D_Charlie V_Neubelt, what
//   the Sample Viewer's Charlie LUT holds) read as pbrkit_sampleDFG reads the table (texel centres).
// source: Estevez & Kulla 2017 (the lobe); glTF-Sample-Viewer ibl.glsl (getIBLRadianceCharlie); Karis 2013 split sum
// roughness: none (the lookups took the sheen roughness)
// pbrkit: pbrkit.brdf.lobes.sheen.sheen_albedo_lookup
vec3 pbrkit_sheenIBL(vec3 prefiltered, float sheenAlbedo, vec3 sheenColor) {
    return prefiltered * sheenColor * sheenAlbedo;
}

// ------------------------------------------------------------ KHR_materials_iridescence

// pbrkit_iorFromF0: the IOR n = (1 + sqrt f0) / (1 - sqrt f0) of a normal reflectance f0 per channel (the inverse
//   of pbrkit_f0FromIOR), the denominator clamped at 1e-6.
// source: Fresnel equations at normal incidence; KHR_materials_iridescence (Fresnel0ToIor)
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.ior_from_f0
vec3 pbrkit_iorFromF0(vec3 f0) {
    vec3 root = sqrt(f0);
    return (1.0 + root) / max(1.0 - root, 1e-6);
}

// pbrkit_thinFilmSensitivity: the Rec.709 response to the spectral fringe cos(2 pi OPD / lambda + shift): the
//   Fourier transform of the CIE XYZ matching functions at the optical path difference opd (nm) by Belcour and
//   Barla's Gaussian fit (X with a second lobe), each of X, Y, Z with its own phase shift, normalised by
//   1.0685e-7, then XYZ -> linear Rec.709 (D65).  At opd = 0, shift 0: (1.205, 0.948, 0.910).
// source: Belcour & Barla 2017, sec. 4 "Analytical Spectral Integration"; KHR_materials_iridescence (evalSensitivity, XYZ_TO_REC709)
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.thin_film_sensitivity
vec3 pbrkit_thinFilmSensitivity(float opd, vec3 shift) {
    float phase = 2.0 * PBRKIT_PI * opd * 1.0e-9;
    float p2 = phase * phase;
    // value sqrt(2 pi var) cos(pos phase + shift) exp(-var phase^2) of each lobe (value, pos, var)
    vec3 value = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    vec3 pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    vec3 var = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    vec3 xyz = value * sqrt(2.0 * PBRKIT_PI * var) * cos(pos * phase + shift) * exp(-var * p2);
    xyz.x += 9.7470e-14 * sqrt(2.0 * PBRKIT_PI * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x) * exp(-4.5282e+09 * p2);
    xyz /= 1.0685e-7;
    // XYZ -> linear Rec.709, rows R, G, B (pbrkit.brdf.fresnel.XYZ_TO_REC709)
    return vec3(dot(vec3(3.2404542, -1.5371385, -0.4985314), xyz),
                dot(vec3(-0.9692660, 1.8760108, 0.0415560), xyz),
                dot(vec3(0.0556434, -0.2040259, 1.0572252), xyz));
}

// F_Iridescence: the thin-film Fresnel (RGB) of a film of IOR filmIor and thickness nm between the outside medium
//   (outsideIor, 1 for air) and a base of normal reflectance f0 (its IOR from f0 + 1e-4, extinction 0):
//   interfaces by Schlick (R12 = F_Schlick(((n_film - n_out) / (n_film + n_out))^2, cos theta_1), T121 = 1 - R12,
//   R23 = F_Schlick(((n_base - n_film) / (n_base + n_film))^2, cos theta_2), Snell's cos theta_2), phases 0 or pi,
//   the first two Airy fringes in Fourier space I = C0 + sum_{m=1,2} C_m 2 S(m OPD, m phi), OPD = 2 n_film d
//   cos theta_2, clamped at 0; 1 under total internal reflection into the film; Schlick's F(f0) at thickness <= 0.
//   cosTheta: v.h (n.v for IBL).
// source: Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence"; KHR_materials_iridescence "Iridescence Fresnel"
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f_iridescence
vec3 F_Iridescence(float cosTheta, float filmIor, float thickness, vec3 f0, float outsideIor) {
    float c1 = clamp(cosTheta, 0.0, 1.0);
    float r0 = (filmIor - outsideIor) / (filmIor + outsideIor);
    float r12 = F_Schlick(c1, r0 * r0, 1.0);
    float t121 = 1.0 - r12;
    float ratio = outsideIor / filmIor;
    float sin2 = ratio * ratio * (1.0 - c1 * c1);
    float cos2 = sqrt(max(1.0 - sin2, 0.0));
    float phi21 = PBRKIT_PI - (filmIor < outsideIor ? PBRKIT_PI : 0.0);
    float opd = 2.0 * filmIor * thickness * cos2;
    vec3 baseIor = pbrkit_iorFromF0(f0 + 0.0001);
    vec3 r1 = (baseIor - filmIor) / (baseIor + filmIor);
    vec3 r23 = F_Schlick(cos2, r1 * r1, 1.0);
    vec3 phi = phi21 + mix(vec3(0.0), vec3(PBRKIT_PI), lessThan(baseIor, vec3(filmIor)));
    vec3 r123 = clamp(r12 * r23, 1e-5, 0.9999);
    vec3 root = sqrt(r123);
    vec3 rs = t121 * t121 * r23 / (1.0 - r123);
    vec3 cm1 = (rs - t121) * root;
    vec3 cm2 = cm1 * root;
    vec3 film = max(r12 + rs + 2.0 * (cm1 * pbrkit_thinFilmSensitivity(opd, phi)
                                      + cm2 * pbrkit_thinFilmSensitivity(2.0 * opd, 2.0 * phi)), 0.0);
    film = sin2 >= 1.0 ? vec3(1.0) : film;
    return thickness > 0.0 ? film : F_Schlick(c1, f0, 1.0);
}

// F_IridescenceDielectric: F_Iridescence over a dielectric base of IOR baseIor: f0 = ((baseIor - 1) / (baseIor + 1))^2.
// source: KHR_materials_iridescence "Dielectric Base Material" (iridescent_dielectric_layer); Belcour & Barla 2017
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f_iridescence_dielectric
vec3 F_IridescenceDielectric(float cosTheta, float filmIor, float thickness, float baseIor, float outsideIor) {
    return F_Iridescence(cosTheta, filmIor, thickness, vec3(pbrkit_f0FromIOR(baseIor)), outsideIor);
}
