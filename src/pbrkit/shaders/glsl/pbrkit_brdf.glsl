// pbrkit_brdf.glsl: the BRDF terms and models of pbrkit (pbrkit.brdf), in GLSL.
//
// GLSL ES 3.00 (WebGL2) and GLSL 3.30+ (desktop OpenGL): add your own version
// line ("#version 300 es" or "#version 330 core") before this file.  Every
// function is a transcription of the pbrkit function named in its "pbrkit:"
// line and is tested against it numerically in WebGL2 (tests/shaders/test_shaders.py).
//
// Conventions (pbrkit docs/CONVENTIONS.md): n the normal, v toward the eye,
// l toward the light, h = normalize(l + v), all unit vectors; NoV = n.v,
// NoL = n.l, NoH = n.h, VoH = v.h = l.h.  "roughness" is perceptual roughness
// r in [0, 1]; "alpha" is the distribution's width, alpha = r^2 (clamped at
// PBRKIT_ALPHA_MIN by pbrkit_alphaFromRoughness).  BRDF values are f, not f cos.

precision highp float;

#ifndef PBRKIT_PI
#define PBRKIT_PI 3.14159265358979
#endif
#ifndef PBRKIT_INV_PI
#define PBRKIT_INV_PI 0.318309886183791
#endif
// pbrkit.brdf.distributions.ALPHA_MIN: the smallest alpha the models use.
#define PBRKIT_ALPHA_MIN 1e-3
// pbrkit.brdf.masking.COS_MIN: cosines are clamped to at least this in the masking terms.
#define PBRKIT_COS_MIN 1e-8

// ------------------------------------------------------------ roughness

// pbrkit_alphaFromRoughness: alpha = max(r^2, 1e-3) for perceptual roughness r.
// source: Burley 2012, "Physically-Based Shading at Disney", sec. 5.4 (adopted by Karis 2013 and glTF 2.0)
// roughness: alpha = r^2, clamped below at 1e-3 (PBRKIT_ALPHA_MIN)
// pbrkit: pbrkit.brdf.distributions.alpha_from_roughness
float pbrkit_alphaFromRoughness(float roughness) {
    return max(roughness * roughness, PBRKIT_ALPHA_MIN);
}

// ------------------------------------------------------------ D: distributions

// D_GGX: GGX / Trowbridge-Reitz distribution
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), 0 for n.h <= 0
//   (the denominator written alpha^2 c^2 + (1 - c)(1 + c): no cancellation near the peak).
// source: Trowbridge & Reitz 1975; Walter et al. 2007, eq. 33
// roughness: takes alpha (alpha = r^2, pbrkit_alphaFromRoughness)
// pbrkit: pbrkit.brdf.distributions.d_ggx
float D_GGX(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float c = min(NoH, 1.0);
    float d = a2 * c * c + (1.0 - c) * (1.0 + c);
    return NoH > 0.0 ? a2 / (PBRKIT_PI * d * d) : 0.0;
}

// D_Beckmann: Beckmann distribution
//   D = exp(-tan^2 theta_h / alpha^2) / (pi alpha^2 cos^4 theta_h), 0 for n.h <= 0.
// source: Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25
// roughness: takes alpha (alpha = r^2, pbrkit_alphaFromRoughness)
// pbrkit: pbrkit.brdf.distributions.d_beckmann
float D_Beckmann(float NoH, float alpha) {
    float c = clamp(NoH, 1e-8, 1.0);
    float c2 = c * c;
    float a2 = alpha * alpha;
    float value = exp(-(1.0 - c) * (1.0 + c) / (a2 * c2)) / (PBRKIT_PI * a2 * c2 * c2);
    return NoH > 0.0 ? value : 0.0;
}

// D_GTR1: generalised Trowbridge-Reitz with gamma = 1 (Berry 1923), the Disney clear-coat lobe
//   D = (alpha^2 - 1) / (pi ln(alpha^2) (alpha^2 cos^2 + sin^2)); alpha = 1 is its limit 1 / pi.
// source: Burley 2012, Appendix B.1 (gtr_normalization with gamma = 1)
// roughness: takes alpha; the Disney clear coat uses alpha = mix(0.1, 0.001, gloss), not r^2
// pbrkit: pbrkit.brdf.distributions.d_gtr1, pbrkit.brdf.distributions.gtr_normalization
float D_GTR1(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float x = a2 - 1.0;
    // (alpha^2 - 1) / ln(alpha^2), with its limit 1 + x / 2 - x^2 / 12 where ln(alpha^2) ~ 0
    float xOverL = abs(x) > 1e-3 ? x / log(a2) : 1.0 + x * (0.5 - x / 12.0);
    float c = min(NoH, 1.0);
    float base = a2 * c * c + (1.0 - c) * (1.0 + c);
    return NoH > 0.0 ? xOverL * PBRKIT_INV_PI / base : 0.0;
}

// D_BlinnPhong: normalised Blinn-Phong distribution
//   D = (e + 2) / (2 pi) (n.h)^e, 0 for n.h <= 0.
// source: Blinn 1977; normalised as in Walter et al. 2007, eq. 30 and Karis 2013 ("Specular BRDF Reference")
// roughness: takes the exponent e; from a Beckmann alpha: e = 2 / alpha^2 - 2 (pbrkit_phongExponentFromBeckmannAlpha)
// pbrkit: pbrkit.brdf.distributions.d_blinn_phong
float D_BlinnPhong(float NoH, float exponent) {
    float c = clamp(NoH, 0.0, 1.0);
    return NoH > 0.0 ? (exponent + 2.0) / (2.0 * PBRKIT_PI) * pow(c, exponent) : 0.0;
}

// pbrkit_phongExponentFromBeckmannAlpha: e = 2 / alpha^2 - 2.
// source: Walter et al. 2007, eq. 30; Karis 2013 blog post ("Specular BRDF Reference")
// roughness: alpha (Beckmann) -> Blinn-Phong exponent e = 2 / alpha^2 - 2
// pbrkit: pbrkit.brdf.distributions.phong_exponent_from_beckmann_alpha
float pbrkit_phongExponentFromBeckmannAlpha(float alpha) {
    return 2.0 / (alpha * alpha) - 2.0;
}

// ------------------------------------------------------------ G and V: masking-shadowing

// Lambda_GGX: Smith Lambda for GGX, (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2
//   (the cosine clamped to [1e-8, 1]), written x / (2 (sqrt(1 + x) + 1)), x = alpha^2 tan^2 theta:
//   no cancellation in float32 where x is small.
// source: Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", eq. 72
// roughness: takes alpha (alpha = r^2)
// pbrkit: pbrkit.brdf.masking.lambda_ggx
float Lambda_GGX(float NoX, float alpha) {
    float c = clamp(NoX, PBRKIT_COS_MIN, 1.0);
    float tan2 = (1.0 - c) * (1.0 + c) / (c * c);  // 1 - c^2 as (1 - c)(1 + c): exact near c = 1
    float x = alpha * alpha * tan2;
    return 0.5 * x / (sqrt(1.0 + x) + 1.0);
}

// G2_Separable: separable Smith masking-shadowing G2 = G1(l) G1(v), G1 = 1 / (1 + Lambda).
// source: Heitz 2014, eqs. 43 and 98
// roughness: none (takes the Lambdas)
// pbrkit: pbrkit.brdf.masking.g2_separable
float G2_Separable(float lambdaL, float lambdaV) {
    return 1.0 / ((1.0 + lambdaL) * (1.0 + lambdaV));
}

// G2_HeightCorrelated: height-correlated Smith masking-shadowing G2 = 1 / (1 + Lambda(l) + Lambda(v)).
// source: Heitz 2014, eq. 99
// roughness: none (takes the Lambdas)
// pbrkit: pbrkit.brdf.masking.g2_height_correlated
float G2_HeightCorrelated(float lambdaL, float lambdaV) {
    return 1.0 / (1.0 + lambdaL + lambdaV);
}

// pbrkit_visibility: V = G2 / (4 n.l n.v), 0 unless n.l > 0 and n.v > 0 (cosines clamped at 1e-8).
// source: Karis 2013, "Real Shading in Unreal Engine 4"; Filament documentation, sec. 4.4.2
// roughness: none
// pbrkit: pbrkit.brdf.masking.visibility
float pbrkit_visibility(float G2, float NoL, float NoV) {
    float denominator = 4.0 * max(NoL, PBRKIT_COS_MIN) * max(NoV, PBRKIT_COS_MIN);
    return (NoL > 0.0 && NoV > 0.0) ? G2 / denominator : 0.0;
}

// V_SmithGGXCorrelated: height-correlated Smith-GGX visibility in the division-free form
//   V = 0.5 / (n.l sqrt((n.v)^2 (1 - a^2) + a^2) + n.v sqrt((n.l)^2 (1 - a^2) + a^2)).
// source: Heitz 2014, eq. 99 with eq. 72; Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", listing 2; Filament sec. 4.4.2
// roughness: takes alpha (alpha = r^2)
// pbrkit: pbrkit.brdf.masking.v_smith_ggx_height_correlated
float V_SmithGGXCorrelated(float NoL, float NoV, float alpha) {
    float a2 = alpha * alpha;
    float cl = clamp(NoL, 0.0, 1.0);
    float cv = clamp(NoV, 0.0, 1.0);
    float lv = cl * sqrt(cv * cv * (1.0 - a2) + a2);
    float ll = cv * sqrt(cl * cl * (1.0 - a2) + a2);
    return (NoL > 0.0 && NoV > 0.0) ? 0.5 / max(lv + ll, 1e-30) : 0.0;
}

// V_SmithGGX: separable Smith-GGX visibility, G1(l) G1(v) / (4 n.l n.v) with the exact GGX Lambda
//   (the glTF 2.0 BRDF's V, Appendix B.3.2).
// source: Heitz 2014, eqs. 72 and 98; glTF 2.0 specification, Appendix B.3.2
// roughness: takes alpha (alpha = r^2)
// pbrkit: pbrkit.brdf.masking.visibility, pbrkit.brdf.masking.g2_separable, pbrkit.brdf.masking.lambda_ggx
float V_SmithGGX(float NoL, float NoV, float alpha) {
    return pbrkit_visibility(G2_Separable(Lambda_GGX(NoL, alpha), Lambda_GGX(NoV, alpha)), NoL, NoV);
}

// G1_SchlickGGX: Schlick-GGX G1 = n.v / (n.v (1 - k) + k), 0 for n.v <= 0.
// source: Schlick 1994; Karis 2013, "Real Shading in Unreal Engine 4", eq. 4
// roughness: takes k: UE4 direct light k = (r + 1)^2 / 8 (pbrkit_kUE4Direct), IBL k = alpha / 2 (pbrkit_kUE4IBL)
// pbrkit: pbrkit.brdf.masking.g1_schlick_ggx
float G1_SchlickGGX(float NoX, float k) {
    float c = max(NoX, 0.0);
    return NoX > 0.0 ? c / max(c * (1.0 - k) + k, 1e-30) : 0.0;
}

// V_SchlickGGX: UE4's visibility, separable Schlick-GGX G2 = G1(l) G1(v) divided by 4 n.l n.v.
// source: Karis 2013, "Real Shading in Unreal Engine 4", eq. 4
// roughness: takes k: direct light k = (r + 1)^2 / 8 (pbrkit_kUE4Direct), IBL k = alpha / 2 (pbrkit_kUE4IBL)
// pbrkit: pbrkit.brdf.masking.visibility, pbrkit.brdf.masking.g2_schlick_ggx
float V_SchlickGGX(float NoL, float NoV, float k) {
    return pbrkit_visibility(G1_SchlickGGX(NoL, k) * G1_SchlickGGX(NoV, k), NoL, NoV);
}

// pbrkit_kUE4Direct: UE4 direct-light k = (r + 1)^2 / 8 = alpha_g / 2 with Disney's alpha_g = (0.5 + r / 2)^2.
// source: Karis 2013, "Real Shading in Unreal Engine 4", eq. 4; Burley 2012, sec. 5.6
// roughness: k = (r + 1)^2 / 8 from perceptual roughness r
// pbrkit: pbrkit.brdf.masking.k_ue4_direct
float pbrkit_kUE4Direct(float roughness) {
    float ag = (0.5 + 0.5 * roughness) * (0.5 + 0.5 * roughness);
    return 0.5 * ag;
}

// pbrkit_kUE4IBL: UE4 image-based-lighting k = alpha / 2 with alpha = r^2.
// source: Karis 2013, "Real Shading in Unreal Engine 4", "Specular G"
// roughness: k = r^2 / 2 from perceptual roughness r (unclamped alpha)
// pbrkit: pbrkit.brdf.masking.k_ue4_ibl
float pbrkit_kUE4IBL(float roughness) {
    return 0.5 * roughness * roughness;
}

// V_Kelemen: Kelemen visibility V = 1 / (4 (v.h)^2).
// source: Kelemen & Szirmay-Kalos 2001, "A Microfacet Based Coupled Specular-Matte BRDF Model with Importance Sampling"
// roughness: none
// pbrkit: pbrkit.brdf.masking.v_kelemen
float V_Kelemen(float VoH) {
    float h = max(VoH, PBRKIT_COS_MIN);
    return 0.25 / (h * h);
}

// V_Neubelt: cloth visibility V = 1 / (4 (n.l + n.v - n.l n.v)).
// source: Neubelt & Pettineo 2013, "Crafting a Next-Gen Material Pipeline for The Order: 1886"; Filament sec. 4.12.2
// roughness: none
// pbrkit: pbrkit.brdf.masking.v_neubelt
float V_Neubelt(float NoL, float NoV) {
    float cl = max(NoL, 0.0);
    float cv = max(NoV, 0.0);
    return (NoL > 0.0 && NoV > 0.0) ? 0.25 / max(cl + cv - cl * cv, PBRKIT_COS_MIN) : 0.0;
}

// ------------------------------------------------------------ F: Fresnel

// F_Schlick: Schlick's approximation F = f0 + (f90 - f0)(1 - cos)^5 (cos clamped to [0, 1]); scalar and RGB.
// source: Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering", eq. 15; f90: Filament sec. 4.4.3, Lagarde & de Rousiers 2014
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f_schlick
float F_Schlick(float cosTheta, float f0, float f90) {
    float m = 1.0 - clamp(cosTheta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (f90 - f0) * (m2 * m2 * m);
}
vec3 F_Schlick(float cosTheta, vec3 f0, float f90) {
    float m = 1.0 - clamp(cosTheta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (f90 - f0) * (m2 * m2 * m);
}

// F_SphericalGaussian: UE4's spherical-Gaussian Schlick F = f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c); scalar and RGB.
// source: Karis 2013, "Real Shading in Unreal Engine 4", eq. 5 (after Lagarde 2012)
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f_schlick_ue4_sg
float F_SphericalGaussian(float cosTheta, float f0) {
    float c = clamp(cosTheta, 0.0, 1.0);
    return f0 + (1.0 - f0) * exp2((-5.55473 * c - 6.98316) * c);
}
vec3 F_SphericalGaussian(float cosTheta, vec3 f0) {
    float c = clamp(cosTheta, 0.0, 1.0);
    return f0 + (1.0 - f0) * exp2((-5.55473 * c - 6.98316) * c);
}

// F_SchlickRoughness: Lagarde's roughness-aware Fresnel F* = f0 + (max(1 - r, f0) - f0)(1 - cos)^5,
//   the diffuse IBL weight k_d = (1 - F*)(1 - metallic).
// source: Lagarde 2011, "Adopting a physically based shading model"
// roughness: perceptual roughness r
// pbrkit: pbrkit.brdf.fresnel.f_schlick_roughness
vec3 F_SchlickRoughness(float cosTheta, vec3 f0, float roughness) {
    float m = 1.0 - clamp(cosTheta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (max(vec3(1.0 - roughness), f0) - f0) * (m2 * m2 * m);
}

// F_Dielectric: exact unpolarised Fresnel reflectance of a dielectric interface of relative IOR eta
//   (Fresnel's equations; 1 under total internal reflection, ((eta - 1) / (eta + 1))^2 at normal incidence).
// source: Born & Wolf, "Principles of Optics", sec. 14.2; pbrt-v4 sec. 9.3 (FrDielectric)
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f_dielectric, pbrkit.brdf.fresnel.f_conductor
float F_Dielectric(float cosTheta, float eta) {
    float ci = clamp(cosTheta, 0.0, 1.0);
    float sin2t = (1.0 - ci * ci) / (eta * eta);
    if (sin2t >= 1.0) return 1.0;
    float ct = sqrt(1.0 - sin2t);
    float rPar = (eta * ci - ct) / (eta * ci + ct);
    float rPerp = (ci - eta * ct) / (ci + eta * ct);
    return 0.5 * (rPar * rPar + rPerp * rPerp);
}

// pbrkit_f0FromIOR: normal-incidence reflectance ((n - 1) / (n + 1))^2.
// source: Fresnel's equations at cos = 1 (Born & Wolf, sec. 14.2)
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f0_from_ior
float pbrkit_f0FromIOR(float ior) {
    float r = (ior - 1.0) / (ior + 1.0);
    return r * r;
}

// pbrkit_f0FromReflectance: Filament's dielectric f0 = 0.16 reflectance^2 (0.5 gives 0.04).
// source: Filament documentation, sec. 4.8.3.2
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f0_from_reflectance
float pbrkit_f0FromReflectance(float reflectance) {
    return 0.16 * reflectance * reflectance;
}

// pbrkit_f0Metallic: metallic workflow f0 = mix(dielectricF0, baseColor, metallic).
// source: Karis 2013, "Real Shading in Unreal Engine 4"; glTF 2.0 specification, Appendix B
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f0_metallic
vec3 pbrkit_f0Metallic(vec3 baseColor, float metallic, float dielectricF0) {
    return dielectricF0 + (baseColor - dielectricF0) * metallic;
}

// pbrkit_f90Filament: Filament's specular occlusion of f90, saturate(50 * 0.33 * (f0.r + f0.g + f0.b)).
// source: Filament shading code (shading_model_standard); Schüler 2009
// roughness: none
// pbrkit: pbrkit.brdf.fresnel.f90_filament
float pbrkit_f90Filament(vec3 f0) {
    return clamp(50.0 * 0.33 * (f0.r + f0.g + f0.b), 0.0, 1.0);
}

// ------------------------------------------------------------ diffuse

// Fd_Lambert: Lambert's diffuse factor, 1 / pi for n.l > 0, else 0 (multiplies the diffuse colour).
// source: Lambert 1760
// roughness: none
// pbrkit: pbrkit.brdf.diffuse.lambert
float Fd_Lambert(float NoL) {
    return NoL > 0.0 ? PBRKIT_INV_PI : 0.0;
}

// Fd_Burley: Disney / Burley diffuse factor (multiplies the diffuse colour)
//   (1 / pi)(1 + (F_D90 - 1)(1 - n.l)^5)(1 + (F_D90 - 1)(1 - n.v)^5), F_D90 = 0.5 + 2 r (l.h)^2.
// source: Burley 2012, "Physically-Based Shading at Disney", sec. 5.3, eq. 3
// roughness: perceptual roughness r (not alpha)
// pbrkit: pbrkit.brdf.diffuse.burley
float Fd_Burley(float NoL, float NoV, float LoH, float roughness) {
    float fd90 = 0.5 + 2.0 * roughness * LoH * LoH;
    return PBRKIT_INV_PI * F_Schlick(NoL, 1.0, fd90) * F_Schlick(NoV, 1.0, fd90);
}

// ------------------------------------------------------------ models

// pbrkit_Cosines: n.l, n.v, n.h and max(v.h, 0) of unit l, v, n with h = normalize(l + v)
// (h = n where l = -v), as pbrkit.brdf.bxdf.isotropic_cosines.
struct pbrkit_Cosines {
    float NoL;
    float NoV;
    float NoH;
    float VoH;
};

// pbrkit_cosines: the cosines the models use, h = normalize(l + v) (n where |l + v| <= 1e-12), v.h clamped at 0.
// source: Walter et al. 2007, eq. 13 (the reflection half vector); Pharr, Jakob & Humphreys 2023 (pbrt-v4), ch. 9
// roughness: none
// pbrkit: pbrkit.brdf.bxdf.isotropic_cosines
pbrkit_Cosines pbrkit_cosines(vec3 l, vec3 v, vec3 n) {
    vec3 h = l + v;
    float len = length(h);
    h = len > 1e-12 ? h / len : n;
    return pbrkit_Cosines(dot(n, l), dot(n, v), dot(n, h), max(dot(v, h), 0.0));
}

// BRDF_UE4: UE4's shading model, f = base (1 - metallic) / pi + D_GGX V_SchlickGGX F_SphericalGaussian
//   with f0 = mix(0.16 reflectance^2, base, metallic); 0 unless n.l > 0 and n.v > 0.
// source: Karis 2013, "Real Shading in Unreal Engine 4" (eqs. 3-5)
// roughness: alpha = max(r^2, 1e-3) for D; direct-light k = (r + 1)^2 / 8 for G
// pbrkit: pbrkit.brdf.models.ue4, pbrkit.brdf.shading.ue4.ue4_specular
vec3 BRDF_UE4(vec3 l, vec3 v, vec3 n, vec3 baseColor, float metallic, float roughness, float reflectance) {
    pbrkit_Cosines c = pbrkit_cosines(l, v, n);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    float alpha = pbrkit_alphaFromRoughness(roughness);
    float specular = D_GGX(c.NoH, alpha) * V_SchlickGGX(c.NoL, c.NoV, pbrkit_kUE4Direct(roughness));
    vec3 f0 = pbrkit_f0Metallic(baseColor, metallic, pbrkit_f0FromReflectance(reflectance));
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    return diffuseColor * Fd_Lambert(c.NoL) + specular * F_SphericalGaussian(c.VoH, f0);
}

// BRDF_Filament: Filament's standard (isotropic) model, f = base (1 - metallic) Fd + D_GGX V_SmithGGXCorrelated F_Schlick
//   with f0 = mix(0.16 reflectance^2, base, metallic), f90 = pbrkit_f90Filament(f0), Fd Lambert or
//   (burleyDiffuse) Burley; 0 unless n.l > 0 and n.v > 0.
// source: Filament documentation, sec. 4 ("Material system": 4.4, 4.8.3.2)
// roughness: alpha = max(r^2, 1e-3) for D and V; Burley's diffuse takes r
// pbrkit: pbrkit.brdf.models.filament, pbrkit.brdf.shading.filament.filament_specular
vec3 BRDF_Filament(vec3 l, vec3 v, vec3 n, vec3 baseColor, float metallic, float roughness, float reflectance,
                   bool burleyDiffuse) {
    pbrkit_Cosines c = pbrkit_cosines(l, v, n);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    float alpha = pbrkit_alphaFromRoughness(roughness);
    float specular = D_GGX(c.NoH, alpha) * V_SmithGGXCorrelated(c.NoL, c.NoV, alpha);
    vec3 f0 = pbrkit_f0Metallic(baseColor, metallic, pbrkit_f0FromReflectance(reflectance));
    float f90 = pbrkit_f90Filament(f0);
    float fd = burleyDiffuse ? Fd_Burley(c.NoL, c.NoV, c.VoH, roughness) : Fd_Lambert(c.NoL);
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    return diffuseColor * fd + specular * F_Schlick(c.VoH, f0, f90);
}

// BRDF_glTF: the glTF 2.0 metallic-roughness BRDF of its Appendix B,
//   mix(fresnel_mix(ior 1.5, diffuse_brdf(base), specular_brdf(alpha)), conductor_fresnel(base, specular_brdf(alpha)), metallic)
//   = (1 - metallic)(1 - F_0.04(v.h)) base / pi + D_GGX V_SmithGGX F_Schlick(f0 = mix(0.04, base, metallic));
//   0 unless n.l > 0 and n.v > 0.
// source: glTF 2.0 specification, Appendix B (B.2.2, B.3.2, B.3.4, B.3.5)
// roughness: alpha = max(r^2, 1e-3)
// pbrkit: pbrkit.brdf.models.gltf, pbrkit.brdf.shading.gltf.gltf_fresnel_mix_weight
vec3 BRDF_glTF(vec3 l, vec3 v, vec3 n, vec3 baseColor, float metallic, float roughness) {
    pbrkit_Cosines c = pbrkit_cosines(l, v, n);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    float alpha = pbrkit_alphaFromRoughness(roughness);
    float specular = D_GGX(c.NoH, alpha) * V_SmithGGX(c.NoL, c.NoV, alpha);
    vec3 f0 = pbrkit_f0Metallic(baseColor, metallic, 0.04);
    float diffuseWeight = Fd_Lambert(c.NoL) * (1.0 - F_Schlick(c.VoH, 0.04, 1.0));
    vec3 diffuseColor = baseColor * (1.0 - metallic);
    return diffuseColor * diffuseWeight + specular * F_Schlick(c.VoH, f0, 1.0);
}
