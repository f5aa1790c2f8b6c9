// pbrkit_ibl.glsl: sampling a pbrkit bake (pbrkit bake -o DIR) in GLSL, with the
// conventions of its manifest.json ("conventions") built in.
//
// GLSL ES 3.00 (WebGL2) and GLSL 3.30+ (desktop OpenGL): add your own version
// line before this file.  Independent of pbrkit_brdf.glsl.  Every function is
// tested against the pbrkit function named in its "pbrkit:" line in WebGL2.
//
// What the bake holds (docs/CONVENTIONS.md):
// - specular.ktx2 / .dds: a cube map, faces +X -X +Y -Y +Z -Z in OpenGL's
//   orientation (upload as is, no mirroring); level m of M holds GGX-prefiltered
//   radiance for perceptual roughness r_m = m / (M - 1), so a shader samples
//   lod = r (M - 1) with trilinear filtering (pbrkit_sampleSpecular).
// - brdf_lut.*: an N x N (DFG1, DFG2) table, column i at n.v = (i + 0.5) / N,
//   row j at r = (j + 0.5) / N, row 0 first (texel centres): texture
//   coordinates are (n.v, r) as they are (pbrkit_sampleDFG); the specular
//   albedo is DFG1 + F0 (DFG2 - DFG1) (pbrkit_specularAlbedoDFG).
// - manifest.json "sh": 9 radiance coefficients (rows) of real, orthonormal SH
//   in the order (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) (2,1) (2,2), no
//   Condon-Shortley phase; irradiance E = sum A_l L_lm Y_lm(n) with
//   A = (pi, 2 pi / 3, pi / 4) (pbrkit_irradianceSH).  E, like irradiance.ktx2,
//   is irradiance, not E / pi: Lambertian radiance is diffuseColor / pi * E.

precision highp float;

#ifndef PBRKIT_PI
#define PBRKIT_PI 3.14159265358979
#endif
#ifndef PBRKIT_INV_PI
#define PBRKIT_INV_PI 0.318309886183791
#endif

// ------------------------------------------------------------ prefiltered specular

// pbrkit_lodFromRoughness: the fractional mip level lod = r (M - 1) of perceptual roughness r (clamped to [0, 1])
//   in a pbrkit bake of M = levels specular levels (manifest outputs.specular.levels).
// source: Karis 2013 split sum; the linear mapping of the Khronos glTF IBL sampler and glTF-Sample-Viewer (lod = roughness (mipCount - 1))
// roughness: perceptual roughness r; level m holds r_m = m / (M - 1)
// pbrkit: pbrkit.ibl.prefilter.level_of_roughness
float pbrkit_lodFromRoughness(float roughness, float levels) {
    return clamp(roughness, 0.0, 1.0) * (levels - 1.0);
}

// pbrkit_roughnessFromLod: the perceptual roughness r = m / (M - 1) of (fractional) level m of M levels.
// source: Khronos glTF IBL sampler and glTF-Sample-Viewer (their linear mapping, lod = roughness (mipCount - 1))
// roughness: returns perceptual roughness r
// pbrkit: pbrkit.ibl.prefilter.roughness_of_level
float pbrkit_roughnessFromLod(float lod, float levels) {
    return lod / (levels - 1.0);
}

// pbrkit_sampleSpecular: prefiltered radiance of a pbrkit specular cube (all M levels uploaded, trilinear
//   filtering: LINEAR_MIPMAP_LINEAR) in direction dir for perceptual roughness r: textureLod at r (M - 1).
// source: Karis 2013, "Real Shading in Unreal Engine 4", split-sum approximation (prefiltered environment, n = v = r)
// roughness: perceptual roughness r -> lod = r (M - 1)
// pbrkit: pbrkit.ibl.prefilter.level_of_roughness, pbrkit.ibl.cubemap.sample_cube
vec3 pbrkit_sampleSpecular(highp samplerCube specular, vec3 dir, float roughness, float levels) {
    return textureLod(specular, dir, pbrkit_lodFromRoughness(roughness, levels)).rgb;
}

// ------------------------------------------------------------ DFG / split-sum table

// pbrkit_sampleDFG: the table's two channels at (n.v, r) with the GPU's bilinear filter (LINEAR, CLAMP_TO_EDGE,
//   no mipmaps; a filterable format such as RG16F, or RG32F with OES_texture_float_linear): texel centres at
//   (i + 0.5) / N are OpenGL's, so the coordinates are (n.v, r) as they are.
// source: Karis 2013 (environment BRDF lookup); OpenGL 4.6 sec. 8.14.2 (texel selection)
// roughness: perceptual roughness r (the table's rows)
// pbrkit: pbrkit.albedo.tables.sample_table
vec2 pbrkit_sampleDFG(highp sampler2D lut, float NoV, float roughness) {
    return texture(lut, clamp(vec2(NoV, roughness), 0.0, 1.0)).rg;
}

// pbrkit_fetchDFG: the same lookup computed in the shader from texelFetch (bilinear between texel centres, clamp to
//   edge): full float precision, and works with unfilterable RG32F textures.
// source: OpenGL 4.6 sec. 8.14.2 and 8.15 (linear filtering, CLAMP_TO_EDGE)
// roughness: perceptual roughness r (the table's rows)
// pbrkit: pbrkit.albedo.tables.table_bilinear, pbrkit.core.filtering.texel_pair
vec2 pbrkit_fetchDFG(highp sampler2D lut, float NoV, float roughness) {
    ivec2 size = textureSize(lut, 0);
    vec2 t = clamp(vec2(NoV, roughness) * vec2(size) - 0.5, vec2(0.0), vec2(size - 1));
    ivec2 i0 = min(ivec2(floor(t)), max(size - 2, 0));
    ivec2 i1 = min(i0 + 1, size - 1);
    vec2 a = t - vec2(i0);
    vec2 t00 = texelFetch(lut, ivec2(i0.x, i0.y), 0).rg;
    vec2 t10 = texelFetch(lut, ivec2(i1.x, i0.y), 0).rg;
    vec2 t01 = texelFetch(lut, ivec2(i0.x, i1.y), 0).rg;
    vec2 t11 = texelFetch(lut, ivec2(i1.x, i1.y), 0).rg;
    return (t00 * (1.0 - a.x) + t10 * a.x) * (1.0 - a.y) + (t01 * (1.0 - a.x) + t11 * a.x) * a.y;
}

// pbrkit_specularAlbedoDFG: specular directional albedo from a `dfg` table (the bake's brdf_lut):
//   lerp(DFG1, DFG2, F0) = DFG1 + F0 (DFG2 - DFG1).
// source: Filament documentation, sec. 5.3.4.3 (after Karis 2013)
// roughness: none (the table lookup took r)
// pbrkit: pbrkit.albedo.lut.lookup_table, pbrkit.albedo.lut.dfg_table
vec3 pbrkit_specularAlbedoDFG(vec2 dfg, vec3 f0) {
    return dfg.x + f0 * (dfg.y - dfg.x);
}

// pbrkit_specularAlbedoSplitSum: specular directional albedo from a `splitsum` table (pbrkit lut --kind splitsum):
//   F0 A + B.
// source: Karis 2013, "Real Shading in Unreal Engine 4", environment BRDF
// roughness: none (the table lookup took r)
// pbrkit: pbrkit.albedo.lut.lookup_table, pbrkit.albedo.lut.splitsum_table
vec3 pbrkit_specularAlbedoSplitSum(vec2 ab, vec3 f0) {
    return f0 * ab.x + ab.y;
}

// EnvBRDFApprox: Karis' analytic fit of the environment BRDF (A, B) for mobile, used as F0 A + B.
// source: Karis 2014, "Physically Based Shading on Mobile" (after Lazarov 2013)
// roughness: perceptual roughness r
// pbrkit: pbrkit.albedo.tables.env_brdf_approx
vec2 EnvBRDFApprox(float NoV, float roughness) {
    vec4 q = roughness * vec4(-1.0, -0.0275, -0.572, 0.022) + vec4(1.0, 0.0425, 1.04, -0.04);
    float a004 = min(q.x * q.x, exp2(-9.28 * NoV)) * q.x + q.y;
    return vec2(-1.04, 1.04) * a004 + q.zw;
}

// pbrkit_specularIBL: the split-sum specular radiance prefiltered * (DFG1 + F0 (DFG2 - DFG1)), prefiltered from
//   pbrkit_sampleSpecular at the reflection direction and dfg from pbrkit_sampleDFG / pbrkit_fetchDFG at (n.v, r).
// source: Karis 2013, "Real Shading in Unreal Engine 4", split-sum approximation; Filament sec. 5.3.4
// roughness: none (the lookups took r)
// pbrkit: pbrkit.rendering.realtime.render_realtime
vec3 pbrkit_specularIBL(vec3 prefiltered, vec2 dfg, vec3 f0) {
    return prefiltered * pbrkit_specularAlbedoDFG(dfg, f0);
}

// ------------------------------------------------------------ spherical harmonics

// pbrkit_irradianceSH: irradiance E(n) = sum_lm A_l L_lm Y_lm(n) from the bake's 9 radiance coefficients
//   (manifest "sh": rows in the order (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) (2,1) (2,2); RGB), orthonormal
//   real SH on world (x, y, z) without Condon-Shortley phase, A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4; a constant
//   radiance 1 gives pi.  n: unit normal.
// source: Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps", eqs. 3 and 7-9
// roughness: none (Lambertian cosine lobe)
// pbrkit: pbrkit.ibl.sh.irradiance_from_sh
vec3 pbrkit_irradianceSH(vec3 sh[9], vec3 n) {
    float x = n.x;
    float y = n.y;
    float z = n.z;
    // A_l Y_lm(n): A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 times the constants of CONVENTIONS.md
    vec3 e = sh[0] * (PBRKIT_PI * 0.282094791773878)
           + (sh[1] * y + sh[2] * z + sh[3] * x) * (2.0 * PBRKIT_PI / 3.0 * 0.488602511902920)
           + (sh[4] * (x * y) + sh[5] * (y * z) + sh[7] * (x * z)) * (0.25 * PBRKIT_PI * 1.092548430592079)
           + sh[6] * (0.25 * PBRKIT_PI * 0.315391565252520 * (3.0 * z * z - 1.0))
           + sh[8] * (0.25 * PBRKIT_PI * 0.546274215296040 * (x * x - y * y));
    return e;
}

// pbrkit_diffuseIBL: Lambertian radiance diffuseColor / pi * E(n) with E from pbrkit_irradianceSH (or the bake's
//   irradiance cube, which also stores E, not E / pi).
// source: Ramamoorthi & Hanrahan 2001; pbrkit docs/CONVENTIONS.md ("Irradiance")
// roughness: none
// pbrkit: pbrkit.ibl.sh.irradiance_from_sh
vec3 pbrkit_diffuseIBL(vec3 diffuseColor, vec3 irradiance) {
    return diffuseColor * PBRKIT_INV_PI * irradiance;
}
