// pbrkit_khr_material.glsl: the extended glTF material of pbrkit (pbrkit.brdf.shading.gltf) in GLSL:
// KHR_materials_ior and KHR_materials_specular (the dielectric's F0 and F90, the diffuse's weight),
// KHR_materials_clearcoat (the coat lobe and its Fresnel layering, about the coat's own normal from a
// clearcoatNormalTexture where it has one), the whole BRDF with
// KHR_materials_sheen, and their real-time image-based lighting -- pbrkit's own
// (pbrkit.rendering.realtime) and the Khronos glTF Sample Viewer's (pbrkit.rendering.khronos_ibl),
// with KHR_materials_transmission / _volume's transmitted light (pbrkit.rendering.transmission_ibl),
// KHR_materials_dispersion's IORs and lookups per channel, and the viewer's KHR_materials_iridescence
// mix; and KHR_materials_anisotropy (its frame, the anisotropic GGX D and V, the specular lobe, the
// core material's BRDF and the Sample Viewer's bent-normal lookup direction).
//
// GLSL ES 3.00 (WebGL2) and GLSL 3.30+: add your own version line, then pbrkit_brdf.glsl and
// pbrkit_khr.glsl (whose F_Schlick, D_GGX, V_SmithGGX, sheen lobe and albedo scaling these call)
// before this file.  Every function transcribes the pbrkit function named in its "pbrkit:" line
// and is tested against it in WebGL2 (tests/shaders/test_shaders_khr_material.py).
//
// Roughness: the base and the coat take perceptual roughness r, alpha = max(r^2, 1e-3)
// (pbrkit_alphaFromRoughness); the sheen's roughness is the Charlie one (pbrkit_charlieAlpha); the
// anisotropic lobe has alpha_b = alpha across the anisotropy direction and alpha_t = mix(alpha, 1,
// strength^2) along it.
// E_sheen (sheenAlbedo below) is pbrkit_fetchSheenAlbedo or pbrkit_sampleSheenAlbedo at
// (n.v, sheenRoughness).

precision highp float;

// pbrkit_KHRMaterial: the glTF material's factors as pbrkit.brdf.material.Material names them
//   (defaults: sheenColor 0, clearcoat 0, specular 1, specularColor 1, ior 1.5: the core material).
struct pbrkit_KHRMaterial {
    vec3 baseColor;
    float metallic;
    float roughness;
    vec3 sheenColor;
    float sheenRoughness;
    float clearcoat;
    float clearcoatRoughness;
    float specular;
    vec3 specularColor;
    float ior;
};

// ------------------------------------------------------------ KHR_materials_ior and KHR_materials_specular

// pbrkit_dielectricF0: the dielectric's normal reflectance per channel,
//   min(((ior - 1) / (ior + 1))^2 specularColor, 1) specular (ior 0 gives f0(ior) = 1).
// source: KHR_materials_specular README, "Implementation" (dielectric_f0); KHR_materials_ior README; glTF 2.0 Appendix B.3.4
// roughness: none
// pbrkit: pbrkit.brdf.shading.gltf.setup, pbrkit.brdf.fresnel.f0_from_ior
vec3 pbrkit_dielectricF0(float ior, vec3 specularColor, float specular) {
    return min(pbrkit_f0FromIOR(ior) * specularColor, vec3(1.0)) * specular;
}

// pbrkit_f0MetallicKHR: the specular lobe's F0 = mix(dielectricF0, baseColor, metallic) per channel.
// source: glTF 2.0 specification, Appendix B (the metal mixed by metallic); KHR_materials_specular README
// roughness: none
// pbrkit: pbrkit.brdf.shading.gltf.setup, pbrkit.brdf.fresnel.f0_metallic
vec3 pbrkit_f0MetallicKHR(vec3 baseColor, float metallic, vec3 dielectricF0) {
    return dielectricF0 + (baseColor - dielectricF0) * metallic;
}

// pbrkit_f90MetallicKHR: the specular lobe's F90 = mix(specular, 1, metallic) (the dielectric's F90 is the
//   specular factor, the metal's 1).
// source: KHR_materials_specular README, "Implementation" (dielectric_f90 = specular); glTF 2.0 Appendix B
// roughness: none
// pbrkit: pbrkit.brdf.shading.gltf.setup
float pbrkit_f90MetallicKHR(float specular, float metallic) {
    return specular + (1.0 - specular) * metallic;
}

// pbrkit_specularMixWeight: the diffuse's weight under the dielectric's specular layer,
//   1 - max3(dielectric_fresnel) = 1 - F_Schlick(v.h; max3(dielectricF0), specular).
// source: KHR_materials_specular README, "Implementation" (1 - max_value(dielectric_fresnel)); Schlick 1994
// roughness: none
// pbrkit: pbrkit.brdf.shading.gltf._specular_mix_weight
float pbrkit_specularMixWeight(float VoH, vec3 dielectricF0, float specular) {
    return 1.0 - F_Schlick(VoH, max(max(dielectricF0.r, dielectricF0.g), dielectricF0.b), specular);
}

// ------------------------------------------------------------ KHR_materials_clearcoat

// pbrkit_clearcoatBRDF: the coat lobe D_GGX(n.h; alpha_c) V_SmithGGX(n.l, n.v; alpha_c), white, no Fresnel.
// source: KHR_materials_clearcoat README, "Clearcoat BRDF" (the specular_brdf of glTF 2.0 Appendix B.3.2 at the coat's roughness)
// roughness: alpha_c = max(clearcoatRoughness^2, 1e-3) (pbrkit_alphaFromRoughness)
// pbrkit: pbrkit.brdf.lobes.clearcoat.clearcoat_value
float pbrkit_clearcoatBRDF(float NoH, float NoL, float NoV, float clearcoatRoughness) {
    float alpha = pbrkit_alphaFromRoughness(clearcoatRoughness);
    return D_GGX(NoH, alpha) * V_SmithGGX(NoL, NoV, alpha);
}

// pbrkit_clearcoatWeight: the coat's weight over the material, clearcoat F_Schlick(n_c.v; 0.04, 1) (the coat's
//   IOR 1.5; the view's cosine to the coat's normal n_c, not v.h).  NoV: |n_c.v| (F_Schlick clamps its cosine
//   to [0, 1], the README's abs(dot(V, normal)) takes the magnitude); n.v where the coat has no normal of its own.
// source: KHR_materials_clearcoat README, "Layering" (clearcoat * clearcoat_fresnel); Schlick 1994
// roughness: none
// pbrkit: pbrkit.brdf.operators.fresnel_coat
float pbrkit_clearcoatWeight(float clearcoat, float NoV) {
    return clearcoat * F_Schlick(NoV, 0.04, 1.0);
}

// pbrkit_fresnelCoat: mix(base, coat, t) = (1 - t) base + t coat with t = pbrkit_clearcoatWeight.
// source: KHR_materials_clearcoat README, "Layering" (fresnel_coat)
// roughness: none
// pbrkit: pbrkit.brdf.operators.fresnel_coat
vec3 pbrkit_fresnelCoat(vec3 base, vec3 coat, float t) {
    return base * (1.0 - t) + coat * t;
}

// pbrkit_clearcoatNormal: the coat's own normal n_c from a clearcoatNormalTexture texel (RGB, as sampled),
//   normalize(mat3(t, b, ng) ((2 texel - 1) (scale, scale, 1))); ng where that is 0.  (t, b, ng) the
//   orthonormal tangent frame of the unmapped normal ng (the interpolated geometry normal, not the base's
//   normal-mapped one): t the glTF TANGENT made orthogonal to ng and normalised, b = w (ng x t).  Without a
//   clearcoatNormalTexture the coat's normal is ng itself ("no normal mapping is applied to the clear coat
//   layer, even if normal mapping is applied to the base material").
// source: KHR_materials_clearcoat README, "Clearcoat" (clearcoatNormalTexture, its scale); glTF 2.0 specification, "Materials" (normalTextureInfo.scale); glTF-Sample-Viewer material_info.glsl (getClearcoatNormal)
// roughness: none
// pbrkit: pbrkit.rendering.textures.tangent_space_normal
vec3 pbrkit_clearcoatNormal(vec3 t, vec3 b, vec3 ng, vec3 texel, float scale) {
    vec3 mapped = mat3(t, b, ng) * ((texel * 2.0 - 1.0) * vec3(scale, scale, 1.0));
    float len = length(mapped);
    return len > 1e-12 ? mapped / len : ng;
}

// ------------------------------------------------------------ the material

// BRDF_glTFExtendedCoatNormal: BRDF_glTFExtended with the coat's own normal coatNormal = n_c (unit; from
//   pbrkit_clearcoatNormal, or the unmapped normal under a base normal map): the base and the sheen about the
//   shading normal n, the coat lobe pbrkit_clearcoatBRDF at n_c.h, n_c.l, n_c.v (0 unless n_c.l > 0 and
//   n_c.v > 0) and its weight clearcoat F_Schlick(|n_c.v|; 0.04, 1) over the base (pbrkit_clearcoatWeight);
//   0 unless n.l > 0 and n.v > 0.  coatNormal = n: BRDF_glTFExtended.
// source: KHR_materials_clearcoat README, "Clearcoat" (clearcoatNormal) and "Layering" (fresnel_coat(clearcoatNormal, ...)); glTF 2.0 specification, Appendix B
// roughness: alpha = max(r^2, 1e-3) for the base, max(clearcoatRoughness^2, 1e-3) for the coat, sheenRoughness^2 for the sheen
// pbrkit: pbrkit.brdf.models.evaluate, pbrkit.brdf.lobes.clearcoat.clearcoat_value, pbrkit.brdf.lobes.clearcoat.coat_cosines, pbrkit.brdf.lobes.clearcoat.coat_nov
vec3 BRDF_glTFExtendedCoatNormal(vec3 l, vec3 v, vec3 n, vec3 coatNormal, pbrkit_KHRMaterial m, float sheenAlbedo) {
    pbrkit_Cosines c = pbrkit_cosines(l, v, n);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    float alpha = pbrkit_alphaFromRoughness(m.roughness);
    vec3 dielectricF0 = pbrkit_dielectricF0(m.ior, m.specularColor, m.specular);
    vec3 f0 = pbrkit_f0MetallicKHR(m.baseColor, m.metallic, dielectricF0);
    float f90 = pbrkit_f90MetallicKHR(m.specular, m.metallic);
    vec3 specular = (D_GGX(c.NoH, alpha) * V_SmithGGX(c.NoL, c.NoV, alpha)) * F_Schlick(c.VoH, f0, f90);
    float diffuseWeight = Fd_Lambert(c.NoL) * pbrkit_specularMixWeight(c.VoH, dielectricF0, m.specular);
    vec3 material = m.baseColor * (1.0 - m.metallic) * diffuseWeight + specular;
    vec3 sheen = pbrkit_sheenBRDF(m.sheenColor, m.sheenRoughness, c.NoH, c.NoL, c.NoV);
    material = sheen + material * pbrkit_sheenAlbedoScaling(m.sheenColor, sheenAlbedo);
    pbrkit_Cosines cc = pbrkit_cosines(l, v, coatNormal);  // n_c.l, n_c.v, n_c.h (v.h as c's)
    bool coated = m.clearcoat > 0.0 && cc.NoL > 0.0 && cc.NoV > 0.0;
    float coat = coated ? pbrkit_clearcoatBRDF(cc.NoH, cc.NoL, cc.NoV, m.clearcoatRoughness) : 0.0;
    return pbrkit_fresnelCoat(material, vec3(coat), pbrkit_clearcoatWeight(m.clearcoat, abs(cc.NoV)));
}

// BRDF_glTFExtended: the glTF material with KHR_materials_ior, _specular, _sheen and _clearcoat, f (not f cos):
//   material = (1 - metallic) base / pi pbrkit_specularMixWeight + D_GGX V_SmithGGX F_Schlick(v.h; F0, F90)
//   (F0 pbrkit_f0MetallicKHR of pbrkit_dielectricF0, F90 pbrkit_f90MetallicKHR), under the sheen
//   sheenColor D_Charlie V_Charlie + material (1 - max3(sheenColor) sheenAlbedo), under the coat
//   pbrkit_fresnelCoat(.., pbrkit_clearcoatBRDF, clearcoat F_Schlick(n.v; 0.04, 1)); 0 unless n.l > 0 and n.v > 0.
//   sheenAlbedo: E_sheen at (n.v, sheenRoughness) (any value without sheen).  The coat about the shading
//   normal n: BRDF_glTFExtendedCoatNormal(l, v, n, n, m, sheenAlbedo).
// source: glTF 2.0 specification, Appendix B; KHR_materials_specular, KHR_materials_ior, KHR_materials_sheen and KHR_materials_clearcoat READMEs
// roughness: alpha = max(r^2, 1e-3) for the base, max(clearcoatRoughness^2, 1e-3) for the coat, sheenRoughness^2 for the sheen
// pbrkit: pbrkit.brdf.models.gltf, pbrkit.brdf.shading.gltf.EXTENDED_COMPOSITION
vec3 BRDF_glTFExtended(vec3 l, vec3 v, vec3 n, pbrkit_KHRMaterial m, float sheenAlbedo) {
    return BRDF_glTFExtendedCoatNormal(l, v, n, n, m, sheenAlbedo);
}

// ------------------------------------------------------------ image-based lighting, pbrkit's

// pbrkit_specularAlbedoDFGF90: the split-sum specular albedo with Schlick's F90,
//   DFG1 F90 + F0 (DFG2 - DFG1) (F90 = 1: pbrkit_specularAlbedoDFG).
// source: Karis 2013, split sum; Filament sec. 5.3.4.3 (lerp(DFG1, DFG2, F0)) with F90 scaling the (1 - v.h)^5 part
// roughness: none (the table lookup took r)
// pbrkit: pbrkit.rendering.realtime.render_realtime
vec3 pbrkit_specularAlbedoDFGF90(vec2 dfg, vec3 f0, float f90) {
    return dfg.x * f90 + f0 * (dfg.y - dfg.x);
}

// pbrkit_specularDiffuseWeightIBL: the diffuse's IBL weight with KHR_materials_specular: 1 - F* of Lagarde's
//   roughness-aware Schlick, F_Schlick(n.v; f0, max(specular (1 - r), f0)) with f0 = max3(dielectricF0)
//   (multiplies diffuseColor E / pi; the core's F, f0 0.04 and specular 1, is Lagarde's 1 - F*(0.04, r)).
// source: Lagarde 2011, "Adopting a physically based shading model" (F*); KHR_materials_specular README
// roughness: perceptual roughness r
// pbrkit: pbrkit.brdf.shading.gltf.ibl_specular_diffuse_weight
float pbrkit_specularDiffuseWeightIBL(float NoV, float roughness, vec3 dielectricF0, float specular) {
    float f0 = max(max(dielectricF0.r, dielectricF0.g), dielectricF0.b);
    return 1.0 - F_Schlick(NoV, f0, max(specular * (1.0 - roughness), f0));
}

// pbrkit_clearcoatRoughnessIBL: the perceptual roughness of the coat's prefiltered and DFG lookups, sqrt(alpha_c) =
//   sqrt(max(clearcoatRoughness^2, 1e-3)); -1 without a coat (clearcoat <= 0: no lookup).
// source: glTF 2.0 specification, Appendix B.2.2 (alpha = r^2); KHR_materials_clearcoat README (the coat's roughness); Karis 2013, split sum
// roughness: clearcoatRoughness -> sqrt(max(clearcoatRoughness^2, 1e-3)) (the floored alpha's perceptual roughness)
// pbrkit: pbrkit.brdf.shading.gltf.ibl_coat_roughness
float pbrkit_clearcoatRoughnessIBL(float clearcoat, float clearcoatRoughness) {
    return clearcoat > 0.0 ? sqrt(pbrkit_alphaFromRoughness(clearcoatRoughness)) : -1.0;
}

// pbrkit_extensionsIBLBaseScale: the factor on the base's IBL (specular and diffuse): (1 - clearcoat
//   F_Schlick(n_c.v; 0.04, 1)) times, with a sheen (any sheenColor channel > 0), 1 - max3(sheenColor) sheenAlbedo.
//   coatNoV: n_c.v, the view's cosine to the coat's normal (n.v where the coat has none of its own; the
//   renderer floors it at 1e-4); sheenAlbedo: E_sheen at the shading normal's (n.v, sheenRoughness).
// source: KHR_materials_clearcoat README, "Layering" (fresnel_coat(clearcoatNormal, ...)); KHR_materials_sheen README, "Albedo-scaling technique"
// roughness: none (sheenAlbedo took the sheen roughness)
// pbrkit: pbrkit.brdf.shading.gltf.ibl_extensions_base_scale
float pbrkit_extensionsIBLBaseScale(float coatNoV, float clearcoat, vec3 sheenColor, float sheenAlbedo) {
    float scale = 1.0 - pbrkit_clearcoatWeight(clearcoat, coatNoV);
    bool sheen = any(greaterThan(sheenColor, vec3(0.0)));
    return sheen ? scale * pbrkit_sheenAlbedoScaling(sheenColor, sheenAlbedo) : scale;
}

// pbrkit_extensionsIBL: the sheen's and the coat's IBL radiance, added to the base's scaled by
//   pbrkit_extensionsIBLBaseScale: sheenColor sheenAlbedo (1 - t) sheenPrefiltered + t coatDFG2 coatPrefiltered,
//   t = clearcoat F_Schlick(n_c.v; 0.04, 1), coatDFG2 the DFG table's second channel (the white lobe's albedo) at
//   (n_c.v, pbrkit_clearcoatRoughnessIBL), the prefiltered radiances at the sheen's and the coat's roughness (the
//   coat's looked up along reflect(-v, n_c)).  coatNoV: n_c.v, the view's cosine to the coat's normal (n.v where
//   the coat has none of its own); sheenAlbedo: E_sheen at the shading normal's (n.v, sheenRoughness).
// source: glTF-Sample-Viewer ibl.glsl (getIBLRadianceCharlie, getIBLRadianceGGX); KHR_materials_clearcoat and KHR_materials_sheen READMEs; Karis 2013 split sum
// roughness: none (the lookups took the sheen's and the coat's roughness)
// pbrkit: pbrkit.brdf.shading.gltf.ibl_extensions_extras
vec3 pbrkit_extensionsIBL(float coatNoV, float clearcoat, float coatDFG2, vec3 coatPrefiltered, vec3 sheenColor,
                          float sheenAlbedo, vec3 sheenPrefiltered) {
    float t = pbrkit_clearcoatWeight(clearcoat, coatNoV);
    bool sheen = any(greaterThan(sheenColor, vec3(0.0)));
    float e = sheen ? sheenAlbedo * (1.0 - t) : 0.0;
    return sheenColor * e * sheenPrefiltered + (t * coatDFG2) * coatPrefiltered;
}

// pbrkit_glTFExtendedIBL: the material's split-sum IBL as pbrkit renders it (render_realtime, engine "pbrkit",
//   without energy compensation): (prefiltered pbrkit_specularAlbedoDFGF90(dfg, F0, F90) + (1 - metallic) base
//   pbrkit_specularDiffuseWeightIBL E / pi) pbrkit_extensionsIBLBaseScale + pbrkit_extensionsIBL; dfg at (n.v, r),
//   coatDFG at (n_c.v, pbrkit_clearcoatRoughnessIBL), irradiance E (not E / pi); coatNoV = n_c.v, the view's
//   cosine to the coat's normal (NoV where the coat has none of its own; the renderer floors both at 1e-4).
// source: Karis 2013, split sum; glTF 2.0 Appendix B; KHR_materials_specular, KHR_materials_clearcoat and KHR_materials_sheen READMEs
// roughness: none (the lookups took r, the coat's and the sheen's roughness)
// pbrkit: pbrkit.rendering.realtime.render_realtime, pbrkit.brdf.shading.gltf.ibl_extensions_extras
vec3 pbrkit_glTFExtendedIBL(float NoV, float coatNoV, pbrkit_KHRMaterial m, vec2 dfg, vec3 prefiltered,
                            vec3 irradiance, vec2 coatDFG, vec3 coatPrefiltered, float sheenAlbedo,
                            vec3 sheenPrefiltered) {
    vec3 dielectricF0 = pbrkit_dielectricF0(m.ior, m.specularColor, m.specular);
    vec3 f0 = pbrkit_f0MetallicKHR(m.baseColor, m.metallic, dielectricF0);
    vec3 specular = prefiltered * pbrkit_specularAlbedoDFGF90(dfg, f0, pbrkit_f90MetallicKHR(m.specular, m.metallic));
    float weight = pbrkit_specularDiffuseWeightIBL(NoV, m.roughness, dielectricF0, m.specular) * PBRKIT_INV_PI;
    vec3 diffuse = m.baseColor * (1.0 - m.metallic) * weight * irradiance;
    return (specular + diffuse) * pbrkit_extensionsIBLBaseScale(coatNoV, m.clearcoat, m.sheenColor, sheenAlbedo)
        + pbrkit_extensionsIBL(coatNoV, m.clearcoat, coatDFG.y, coatPrefiltered, m.sheenColor, sheenAlbedo,
                               sheenPrefiltered);
}

// ------------------------------------------------------------ image-based lighting, the Khronos Sample Viewer's

// pbrkit_sampleViewerFresnel: the Sample Viewer's getIBLGGXFresnel per channel, FssEss + FmsEms with FssEss = w (k_S A
//   + B), k_S = F_SchlickRoughness(n.v; F0, r), E_ms = 1 - (A + B), F_avg = w (F0 + (1 - F0) / 21), FmsEms = E_ms
//   FssEss F_avg / (1 - F_avg E_ms); (A, B) Karis' split-sum pair at (n.v, r) (A = DFG2 - DFG1, B = DFG1).
// source: glTF-Sample-Viewer ibl.glsl (getIBLGGXFresnel); Fdez-Agüera 2019, "A Multiple-Scattering Microfacet Model for Real-Time Image-based Lighting"
// roughness: perceptual roughness r
// pbrkit: pbrkit.rendering.khronos_ibl.sample_viewer_fresnel
vec3 pbrkit_sampleViewerFresnel(float NoV, float roughness, vec3 f0, float weight, vec2 ab) {
    vec3 fssEss = weight * (F_SchlickRoughness(NoV, f0, roughness) * ab.x + ab.y);
    float eMs = 1.0 - (ab.x + ab.y);
    vec3 fAvg = weight * (f0 + (1.0 - f0) / 21.0);
    return fssEss + eMs * fssEss * fAvg / (1.0 - fAvg * eMs);
}

// pbrkit_sampleViewerBase: the Sample Viewer's metallic-roughness IBL: the dielectric mix(base E / pi, radiance,
//   W(F0, weight)) and the metal radiance W(base, 1), mixed by metallic (W pbrkit_sampleViewerFresnel).
// source: glTF-Sample-Viewer pbr.frag (f_dielectric_brdf_ibl, f_metal_brdf_ibl); Fdez-Agüera 2019
// roughness: perceptual roughness r
// pbrkit: pbrkit.rendering.khronos_ibl.sample_viewer_base
vec3 pbrkit_sampleViewerBase(float NoV, float roughness, vec3 baseColor, float metallic, vec3 f0, float weight,
                             vec2 ab, vec3 radiance, vec3 irradiance) {
    vec3 w = pbrkit_sampleViewerFresnel(NoV, roughness, f0, weight, ab);
    vec3 dielectric = baseColor * irradiance * PBRKIT_INV_PI * (1.0 - w) + radiance * w;
    vec3 metal = radiance * pbrkit_sampleViewerFresnel(NoV, roughness, baseColor, 1.0, ab);
    return dielectric + (metal - dielectric) * metallic;
}

// pbrkit_sampleViewerExtensionsIBL: the Sample Viewer's IBL of the material with its extensions:
//   pbrkit_sampleViewerBase with F0 = min(f0(ior) specularColor, 1) and weight = specular; with a sheen,
//   sheenColor charlieLUT sheenRadiance + color (1 - max3(sheenColor) sheenAlbedo); then mix(color, coatRadiance,
//   clearcoat F_Schlick(n_c.v; f0(ior), 1)) (the coat's F0 of the material's ior, its radiance without an albedo,
//   looked up about the coat's normal n_c).  coatNoV = n_c.v, the viewer's clampedDot(clearcoatNormal, v) (NoV
//   where the coat has no normal of its own).  charlieLUT: the Charlie LUT (pbrkit lut --cloth, .b) at (n.v,
//   sheenRoughness).
// source: glTF-Sample-Viewer pbr.frag, material_info.glsl and ibl.glsl; KHR_materials_specular, KHR_materials_sheen and KHR_materials_clearcoat READMEs
// roughness: perceptual roughness r (the lookups took the coat's and the sheen's roughness)
// pbrkit: pbrkit.rendering.khronos_ibl.sample_viewer_extensions_ibl
vec3 pbrkit_sampleViewerExtensionsIBL(float NoV, float coatNoV, pbrkit_KHRMaterial m, vec2 ab, vec3 radiance,
                                      vec3 irradiance, vec3 coatRadiance, vec3 sheenRadiance, float charlieLUT,
                                      float sheenAlbedo) {
    float f0Ior = pbrkit_f0FromIOR(m.ior);
    vec3 f0 = min(f0Ior * m.specularColor, vec3(1.0));
    vec3 color = pbrkit_sampleViewerBase(NoV, m.roughness, m.baseColor, m.metallic, f0, m.specular, ab, radiance,
                                         irradiance);
    if (any(greaterThan(m.sheenColor, vec3(0.0)))) {
        color = m.sheenColor * charlieLUT * sheenRadiance + color * pbrkit_sheenAlbedoScaling(m.sheenColor, sheenAlbedo);
    }
    float t = m.clearcoat * F_Schlick(coatNoV, f0Ior, 1.0);
    return color + (coatRadiance - color) * t;
}

// ------------------------------------------------------------ KHR_materials_transmission and _volume, real time

// pbrkit_iorRoughness: the perceptual roughness at which transmitted light is blurred, r clamp(2 ior - 2, 0, 1).
// source: glTF-Sample-Viewer ibl.glsl (applyIorToRoughness)
// roughness: perceptual roughness r
// pbrkit: pbrkit.rendering.transmission_ibl.ior_roughness
float pbrkit_iorRoughness(float roughness, float ior) {
    return roughness * clamp(ior * 2.0 - 2.0, 0.0, 1.0);
}

// pbrkit_transmissionDirection: the transmission ray: -v through a thin wall (thickness 0), refract(-v, n,
//   1 / ior) into a volume (-v where refract gives 0).
// source: glTF-Sample-Viewer ibl.glsl (getVolumeTransmissionRay); KHR_materials_volume README
// roughness: none
// pbrkit: pbrkit.rendering.transmission_ibl.transmission_direction
vec3 pbrkit_transmissionDirection(vec3 n, vec3 v, float ior, float thickness) {
    vec3 bent = refract(-v, n, 1.0 / ior);
    return (thickness > 0.0 && dot(bent, bent) > 0.0) ? bent : -v;
}

// pbrkit_volumeAttenuation: the transmittance attenuationColor^(distance / attenuationDistance) over a path of
//   that length in the volume; 1 for attenuationDistance 0 (glTF's +Infinity).
// source: KHR_materials_volume README, "Attenuation"; glTF-Sample-Viewer ibl.glsl (applyVolumeAttenuation)
// roughness: none
// pbrkit: pbrkit.brdf.transmission.absorption
vec3 pbrkit_volumeAttenuation(float distance, vec3 attenuationColor, float attenuationDistance) {
    if (attenuationDistance <= 0.0) {
        return vec3(1.0);
    }
    return pow(attenuationColor, vec3(distance / attenuationDistance));
}

// pbrkit_transmissionIBL: pbrkit's real-time transmission, added to the diffuse IBL: (1 - metallic) transmission
//   baseColor diffuseWeight transmitted, diffuseWeight the diffuse's Fresnel weight (pbrkit_specularDiffuseWeightIBL,
//   without 1 / pi) and transmitted the light along pbrkit_transmissionDirection (the prefiltered radiance at
//   pbrkit_iorRoughness; with KHR_materials_dispersion each channel along its own, pbrkit_dispersionLookup) times
//   pbrkit_volumeAttenuation over the thickness.
// source: KHR_materials_transmission README ("Transmission BTDF"); glTF-Sample-Viewer ibl.glsl (getIBLVolumeRefraction)
// roughness: none (the lookup took pbrkit_iorRoughness)
// pbrkit: pbrkit.brdf.shading.gltf.ibl_transmission, pbrkit.rendering.realtime._ibl_kernel
vec3 pbrkit_transmissionIBL(vec3 baseColor, float metallic, float transmission, float diffuseWeight,
                            vec3 transmitted) {
    return (1.0 - metallic) * transmission * baseColor * diffuseWeight * transmitted;
}

// pbrkit_sampleViewerTransmission: the Sample Viewer's f_diffuse with transmission, mix(fDiffuse, (1 - (F0 A + B))
//   transmitted baseColor, transmission) (f90 1).
// source: glTF-Sample-Viewer pbr.frag and ibl.glsl (getIBLVolumeRefraction)
// roughness: none
// pbrkit: pbrkit.rendering.khronos_ibl.sample_viewer_transmission
vec3 pbrkit_sampleViewerTransmission(vec3 fDiffuse, float transmission, vec3 f0, vec2 ab, vec3 transmitted,
                                     vec3 baseColor) {
    return mix(fDiffuse, (1.0 - (f0 * ab.x + ab.y)) * transmitted * baseColor, transmission);
}

// ------------------------------------------------------------ KHR_materials_dispersion, real time

// pbrkit_dispersionIors: each colour channel's IOR of a KHR_materials_dispersion volume, Cauchy's n(lambda) through
//   n_d = ior at 587.6 nm with Abbe number V_d = 20 / dispersion, max(n_d + (n_d - 1) dispersion / 20 (523655 /
//   lambda^2 - 1.5168), 1), at the Fraunhofer lines the Abbe number is defined by (R at C 656.3 nm, G at d 587.6,
//   B at F 486.1: pbrkit.brdf.transmission.FRAUNHOFER_NM); ior in every channel for dispersion 0 (not clamped:
//   KHR_materials_ior's 0 stays 0; green is ior - 1.6e-4 (ior - 1) dispersion / 20, the README's constants).
//   pbrkit's IORs, in the ground truth and in real time (engine "pbrkit").
// source: KHR_materials_dispersion README, "Overview" (Cauchy's equation through the Abbe number, n(lambda) = max(n_d + (n_d - 1) / V_d (523655 / lambda^2 - 1.5168), 1))
// roughness: none
// pbrkit: pbrkit.brdf.transmission.dispersion_iors
vec3 pbrkit_dispersionIors(float ior, float dispersion) {
    const vec3 lambda = vec3(656.3, 587.6, 486.1);
    vec3 cauchy = 523655.0 / (lambda * lambda) - 1.5168;
    return dispersion > 0.0 ? max(ior + (ior - 1.0) * (dispersion / 20.0) * cauchy, vec3(1.0)) : vec3(ior);
}

// pbrkit_sampleViewerDispersionIors: KHR_materials_dispersion's real-time IORs, as the Sample Viewer takes them:
//   green at ior, red and blue half the F - C spread below and above, ior -+ (ior - 1) 0.025 dispersion.
// source: KHR_materials_dispersion README, "Implementation"; glTF-Sample-Viewer ibl.glsl (getIBLVolumeRefraction, halfSpread)
// roughness: none
// pbrkit: pbrkit.brdf.transmission.sample_viewer_dispersion_iors
vec3 pbrkit_sampleViewerDispersionIors(float ior, float dispersion) {
    float halfSpread = (ior - 1.0) * 0.025 * dispersion;
    return vec3(ior - halfSpread, ior, ior + halfSpread);
}

// pbrkit_dispersionLookup: channel c's lookup of the transmitted light with KHR_materials_dispersion (channel c
//   of what it reads is transmitted[c]): (pbrkit_transmissionDirection, pbrkit_iorRoughness) at that channel's IOR
//   max(iors[c], 1) (KHR_materials_ior's 0 refracts as 1), the direction in .xyz and the lookup's perceptual
//   roughness in .w; iors pbrkit_dispersionIors (engine "pbrkit") or pbrkit_sampleViewerDispersionIors.  A
//   thin wall (thickness 0) looks up along -v, only the roughness per channel.  The Sample Viewer instead reads
//   its framebuffer at the projection of position + direction thickness, at that roughness.
// source: KHR_materials_dispersion README, "Implementation" (a refraction per channel); glTF-Sample-Viewer ibl.glsl (getIBLVolumeRefraction, getTransmissionSample)
// roughness: perceptual roughness r -> r clamp(2 iors[c] - 2, 0, 1) (pbrkit_iorRoughness)
// pbrkit: pbrkit.rendering.transmission_ibl.transmission_lookups
vec4 pbrkit_dispersionLookup(vec3 n, vec3 v, float roughness, vec3 iors, float thickness, int channel) {
    float ior = max(iors[channel], 1.0);
    return vec4(pbrkit_transmissionDirection(n, v, ior, thickness), pbrkit_iorRoughness(roughness, ior));
}

// ------------------------------------------------------------ KHR_materials_iridescence, the Sample Viewer's IBL

// pbrkit_sampleViewerFilm: pbr.frag's MATERIAL_IRIDESCENCE branch: the metal mix(W(base, 1) radiance, radiance
//   filmMetal, k) and the dielectric mix(mix(fDiffuse, radiance, W(F0, weight)), rgb_mix(fDiffuse, radiance,
//   filmDielectric), k), mixed by metallic; filmDielectric and filmMetal the film's Fresnel (F_Iridescence) at n.v
//   over F0 and over the base colour; rgb_mix(a, b, t) = (1 - max3(t)) a + t b.
// source: glTF-Sample-Viewer pbr.frag and iridescence.glsl; KHR_materials_iridescence README
// roughness: perceptual roughness r
// pbrkit: pbrkit.rendering.khronos_ibl.sample_viewer_film
vec3 pbrkit_sampleViewerFilm(float NoV, float roughness, vec3 fDiffuse, vec3 baseColor, float metallic, vec3 f0,
                             float weight, vec2 ab, vec3 radiance, float k, vec3 filmDielectric, vec3 filmMetal) {
    vec3 w = pbrkit_sampleViewerFresnel(NoV, roughness, f0, weight, ab);
    vec3 dielectric = fDiffuse * (1.0 - w) + radiance * w;
    vec3 metal = radiance * pbrkit_sampleViewerFresnel(NoV, roughness, baseColor, 1.0, ab);
    float dMax = max(filmDielectric.r, max(filmDielectric.g, filmDielectric.b));
    dielectric = mix(dielectric, (1.0 - dMax) * fDiffuse + filmDielectric * radiance, k);
    metal = mix(metal, radiance * filmMetal, k);
    return mix(dielectric, metal, metallic);
}

// ------------------------------------------------------------ KHR_materials_anisotropy

// pbrkit_anisotropicFrame: the anisotropy's frame mat3(anisotropicT, anisotropicB, n) at unit normal n, from
//   a glTF TANGENT (xyz, w the handedness): T = tangent.xyz made orthogonal to n and normalised, B = w (n x T)
//   (w = -1 where tangent.w < 0, else 1), anisotropicT = normalize(direction.x T + direction.y B),
//   anisotropicB = n x anisotropicT.  direction = (cos, sin) of anisotropyRotation (counter-clockwise from T
//   towards B), the README's u_AnisotropyRotation: computed once per material on the CPU (the GPU's sin and
//   cos need only be within 2^-11; SwiftShader's are off by up to 2e-4 on [-4, 4]), or a texture's
//   direction turned by it.  tangent.xyz must not be zero or parallel to n (pbrkit then takes a frame of its
//   own, tangent_frame's).
// source: KHR_materials_anisotropy README, "Implementation" (anisotropicT = normalize(TBN (cos, sin, 0)), anisotropicB = normalize(cross(n, anisotropicT))); glTF 2.0 specification, "Meshes" (bitangent = cross(normal, tangent.xyz) tangent.w)
// roughness: none
// pbrkit: pbrkit.brdf.bxdf.shading_frame, pbrkit.brdf.bxdf.turned_frame
mat3 pbrkit_anisotropicFrame(vec3 n, vec4 tangent, vec2 direction) {
    vec3 t = normalize(tangent.xyz - dot(tangent.xyz, n) * n);
    vec3 b = (tangent.w < 0.0 ? -1.0 : 1.0) * cross(n, t);
    t = normalize(direction.x * t + direction.y * b);
    return mat3(t, cross(n, t), n);
}

// pbrkit_anisotropicAlphaT: the GGX alpha along anisotropicT, alpha_t = mix(alpha, 1, strength^2); across it
//   (along anisotropicB) alpha_b = alpha.
// source: KHR_materials_anisotropy README, "Implementation" (at = mix(alphaRoughness, 1.0, anisotropy * anisotropy), ab = alphaRoughness); glTF 2.0 specification, Appendix B.2.2 (alpha = r^2)
// roughness: alpha (= max(r^2, 1e-3), pbrkit_alphaFromRoughness) -> alpha_t = alpha + (1 - alpha) strength^2, strength in [0, 1]
// pbrkit: pbrkit.brdf.shading.gltf.setup
float pbrkit_anisotropicAlphaT(float alpha, float strength) {
    return alpha + (1.0 - alpha) * (strength * strength);
}

// pbrkit_dGGXAnisotropic: anisotropic GGX D = 1 / (pi a_t a_b ((t.h / a_t)^2 + (b.h / a_b)^2 + (n.h)^2)^2), written
//   as the README's a2 w2^2 / pi, a2 = a_t a_b, f = (a_b t.h, a_t b.h, a2 n.h), w2 = a2 / (f.f) (no division by
//   an alpha); 0 for n.h <= 0 (the README has no such guard).
// source: Burley 2012, Appendix B.2, eq. 13; Heitz 2014, eq. 85; KHR_materials_anisotropy README, "Implementation" (D_GGX_anisotropic)
// roughness: takes alpha_t (pbrkit_anisotropicAlphaT) and alpha_b (= alpha = max(r^2, 1e-3))
// pbrkit: pbrkit.brdf.distributions.d_ggx_anisotropic
float pbrkit_dGGXAnisotropic(float NoH, float ToH, float BoH, float alphaT, float alphaB) {
    float a2 = alphaT * alphaB;
    vec3 f = vec3(alphaB * ToH, alphaT * BoH, a2 * NoH);
    float w2 = a2 / dot(f, f);
    return NoH > 0.0 ? a2 * w2 * w2 * PBRKIT_INV_PI : 0.0;
}

// pbrkit_vGGXAnisotropic: the height-correlated Smith visibility of anisotropic GGX, G2 / (4 n.l n.v) with
//   G2 = 1 / (1 + Lambda(l) + Lambda(v)), in the division-free form
//   V = 0.5 / (n.l |(a_t t.v, a_b b.v, n.v)| + n.v |(a_t t.l, a_b b.l, n.l)|) (cosines clamped to [0, 1]);
//   0 unless n.l > 0 and n.v > 0.  Not clamped: the README's V_GGX_anisotropic clamps V to [0, 1], which cuts
//   the lobe wherever G2 > 4 n.l n.v (a smooth lobe where n.l n.v < 1/4); pbrkit does not clamp it.
// source: Heitz 2014, eq. 99 with eqs. 80 and 86; KHR_materials_anisotropy README, "Implementation" (V_GGX_anisotropic, without its clamp)
// roughness: takes alpha_t (pbrkit_anisotropicAlphaT) and alpha_b (= alpha = max(r^2, 1e-3))
// pbrkit: pbrkit.brdf.masking.lambda_ggx_anisotropic, pbrkit.brdf.masking.g2_height_correlated, pbrkit.brdf.masking.visibility
float pbrkit_vGGXAnisotropic(float NoL, float ToL, float BoL, float NoV, float ToV, float BoV, float alphaT,
                             float alphaB) {
    float cl = clamp(NoL, 0.0, 1.0);
    float cv = clamp(NoV, 0.0, 1.0);
    float lv = cl * length(vec3(alphaT * ToV, alphaB * BoV, cv));
    float ll = cv * length(vec3(alphaT * ToL, alphaB * BoL, cl));
    return (NoL > 0.0 && NoV > 0.0) ? 0.5 / max(lv + ll, 1e-30) : 0.0;
}

// pbrkit_anisotropicSpecular: the glTF specular lobe with KHR_materials_anisotropy, f (not f cos):
//   pbrkit_dGGXAnisotropic pbrkit_vGGXAnisotropic F_Schlick(v.h; f0, f90) in the frame (anisotropicT, anisotropicB,
//   n) of pbrkit_anisotropicFrame, alpha_b = max(r^2, 1e-3), alpha_t = pbrkit_anisotropicAlphaT; 0 unless n.l > 0
//   and n.v > 0.  The core material: f0 = pbrkit_f0Metallic(baseColor, metallic, 0.04), f90 = 1; with
//   KHR_materials_ior / _specular: pbrkit_f0MetallicKHR, pbrkit_f90MetallicKHR.  Anisotropic for any strength
//   (pbrkit's model, and BRDF_glTFAnisotropic, take the core's separable V at strength 0).
// source: KHR_materials_anisotropy README, "Implementation" (BRDF_specularAnisotropicGGX); glTF 2.0 specification, Appendix B.3.2; Schlick 1994
// roughness: perceptual roughness r -> alpha_b = max(r^2, 1e-3) (pbrkit_alphaFromRoughness), alpha_t = alpha_b + (1 - alpha_b) strength^2
// pbrkit: pbrkit.brdf.shading.gltf._v_khr, pbrkit.brdf.distributions.d_ggx_anisotropic, pbrkit.brdf.shading.gltf.khr_fresnel
vec3 pbrkit_anisotropicSpecular(vec3 l, vec3 v, mat3 frame, vec3 f0, float f90, float roughness, float strength) {
    pbrkit_Cosines c = pbrkit_cosines(l, v, frame[2]);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    vec3 h = normalize(l + v);  // |l + v| >= n.l + n.v > 0 here: pbrkit_cosines' h
    float alphaB = pbrkit_alphaFromRoughness(roughness);
    float alphaT = pbrkit_anisotropicAlphaT(alphaB, strength);
    float d = pbrkit_dGGXAnisotropic(c.NoH, dot(frame[0], h), dot(frame[1], h), alphaT, alphaB);
    float vis = pbrkit_vGGXAnisotropic(c.NoL, dot(frame[0], l), dot(frame[1], l), c.NoV, dot(frame[0], v),
                                       dot(frame[1], v), alphaT, alphaB);
    return (d * vis) * F_Schlick(c.VoH, f0, f90);
}

// BRDF_glTFAnisotropic: the glTF 2.0 metallic-roughness BRDF with KHR_materials_anisotropy, f (not f cos):
//   (1 - metallic) base / pi (1 - F_Schlick(v.h; 0.04, 1)) (pbrkit_specularMixWeight of the core's 0.04) +
//   pbrkit_anisotropicSpecular with f0 = mix(0.04, base, metallic), f90 = 1, in the frame pbrkit_anisotropicFrame
//   of the glTF TANGENT and direction = (cos, sin) of anisotropyRotation; strength anisotropyStrength in [0, 1]
//   (0: BRDF_glTF, the core's separable V, as pbrkit's model); 0 unless n.l > 0 and n.v > 0.
// source: KHR_materials_anisotropy README, "Anisotropy" and "Implementation"; glTF 2.0 specification, Appendix B
// roughness: perceptual roughness r -> alpha_b = max(r^2, 1e-3), alpha_t = alpha_b + (1 - alpha_b) strength^2
// pbrkit: pbrkit.brdf.models.gltf, pbrkit.brdf.models.evaluate, pbrkit.brdf.shading.gltf.setup
vec3 BRDF_glTFAnisotropic(vec3 l, vec3 v, vec3 n, vec4 tangent, vec3 baseColor, float metallic, float roughness,
                          float strength, vec2 direction) {
    if (strength <= 0.0) return BRDF_glTF(l, v, n, baseColor, metallic, roughness);
    pbrkit_Cosines c = pbrkit_cosines(l, v, n);
    if (c.NoL <= 0.0 || c.NoV <= 0.0) return vec3(0.0);
    mat3 frame = pbrkit_anisotropicFrame(n, tangent, direction);
    vec3 f0 = pbrkit_f0Metallic(baseColor, metallic, 0.04);
    vec3 specular = pbrkit_anisotropicSpecular(l, v, frame, f0, 1.0, roughness, strength);
    float diffuseWeight = Fd_Lambert(c.NoL) * pbrkit_specularMixWeight(c.VoH, vec3(0.04), 1.0);
    return baseColor * (1.0 - metallic) * diffuseWeight + specular;
}

// pbrkit_anisotropicReflection: the direction the Sample Viewer looks the prefiltered environment up in for
//   KHR_materials_anisotropy (at lod of r, as the isotropic lookup): the anisotropic normal a = (b x v) x b (b
//   anisotropicB, across the direction of increased roughness) bent back towards n by k = (1 - strength (1 - r))^4,
//   n' = normalize(mix(a, n, k)) (n where that is 0), R = reflect(-v, n').  The README's further
//   normalize(mix(R, n', r^2)) is not applied (the Sample Viewer does not).
// source: glTF-Sample-Viewer ibl.glsl (getIBLRadianceAnisotropy); KHR_materials_anisotropy README, "Image-based lighting" (bent normal); McAuley 2015 (Filament's bent normal)
// roughness: perceptual roughness r (k = (1 - strength (1 - r))^4: no bend at r = 1 or strength 0)
// pbrkit: pbrkit.rendering.ibl_lookups.khr_anisotropic_reflection
vec3 pbrkit_anisotropicReflection(vec3 n, vec3 v, vec3 b, float strength, float roughness) {
    vec3 a = cross(cross(b, v), b);
    float k = 1.0 - strength * (1.0 - roughness);
    k *= k;
    k *= k;
    vec3 m = a + (n - a) * k;
    float len = length(m);
    m = len > 0.0 ? m / len : n;
    return reflect(-v, m);
}
