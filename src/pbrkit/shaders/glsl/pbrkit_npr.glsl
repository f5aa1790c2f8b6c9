// pbrkit_npr.glsl: pbrkit's non-photorealistic shading terms (pbrkit.npr.toon,
// pbrkit.npr.hatching) in GLSL: toon bands, ramps, highlights, VRM MToon 1.0's
// shading, parametric rim and GI equalisation, and the tone blend of a tonal art map.
//
// GLSL ES 3.00 (WebGL2) and GLSL 3.30+ (desktop OpenGL): add your own version
// line before this file.  Independent of the other pbrkit files.  Every function
// is tested against the pbrkit function named in its "pbrkit:" line in WebGL2
// (tests/shaders/test_shaders.py).  No roughness remap is involved in any of them.
//
// Inputs an engine supplies:
// - toon thresholds: up to 8, ascending, in a float[8] (a "uniform float
//   u_thresholds[8]" passes as it is) with their count; count 0 means no bands,
//   the tone is clamp(x, 0, 1) (pbrkit.npr.toon.toon_tone).
// - ramp images (style "ramp"): the whole image as a texture with linear values
//   (upload an 8-bit ramp as SRGB8 / SRGB8_ALPHA8); pbrkit reads its middle row
//   (row H / 2, row 0 first), texel centres at (i + 0.5) / M, clamp to edge.
// - tonal art maps (pbrkit.npr.hatching.write_tam): tone k as tone{k}_mip{l}.png
//   (a mip chain, REPEAT, sRGB-decoded to linear paper reflectance) or RGB atlas a
//   holding tones 3a .. 3a + 2 (atlas{a}_mip{l}.png).  Sample tone k at uv with
//   textureLod(tam_k, uv, pbrkit_hatchLevel(footprint, L)) (LINEAR_MIPMAP_LINEAR),
//   then blend with pbrkit_hatchBlend: tones 0..3 in the first vec4, 4..7 in the
//   second (from atlases: vec4(a0.rgb, a1.r), vec4(a1.gb, a2.rg)).
#ifndef PBRKIT_NPR_GLSL
#define PBRKIT_NPR_GLSL
precision highp float;

// ------------------------------------------------------------ toon bands

// pbrkit_smoothStepBand: 0 below edge and 1 above it (x >= edge gives 1); with softness s > 0 the smoothstep
//   3u^2 - 2u^3 of u = saturate((x - edge) / s + 1/2), a transition of width s centred on the edge.
// source: Lake, Marshall, Harris and Blackstein 2000, "Stylized Rendering Techniques for Scalable Real-Time 3D
//   Animation", NPAR, sec. 3 (the hard step); GLSL smoothstep for the soft band
// roughness: none
// pbrkit: pbrkit.npr.toon.smooth_step_band
float pbrkit_smoothStepBand(float x, float edge, float softness) {
    if (softness <= 0.0) {
        return x >= edge ? 1.0 : 0.0;
    }
    float u = clamp((x - edge) / softness + 0.5, 0.0, 1.0);
    return u * u * (3.0 - 2.0 * u);
}

// pbrkit_toonTone: the tone in [0, 1] of a lighting value x (n.l, or the summed lighting over its largest
//   value): the mean of the steps at thresholds[0 .. count - 1] (count <= 8; K thresholds give K + 1 tones
//   0, 1/K, .., 1 with hard steps); count 0 gives clamp(x, 0, 1).
// source: Lake et al. 2000, sec. 3 (the diffuse term quantised through a 1-D texture)
// roughness: none
// pbrkit: pbrkit.npr.toon.toon_tone
float pbrkit_toonTone(float x, float thresholds[8], int count, float softness) {
    int k = min(count, 8);
    if (k <= 0) {
        return clamp(x, 0.0, 1.0);
    }
    float total = 0.0;
    for (int i = 0; i < 8; ++i) {
        if (i >= k) break;
        total += pbrkit_smoothStepBand(x, thresholds[i], softness);
    }
    return total / float(k);
}

// pbrkit_toonShade: the two-colour ramp mix(shadowColor, 1, tone), the colour multiplier of a tone (times the
//   base colour and the light) when the style has no ramp image.
// source: Lake et al. 2000, sec. 3 (two-tone shading: the illuminated and the shadowed colour)
// roughness: none
// pbrkit: pbrkit.npr.render._shade
vec3 pbrkit_toonShade(vec3 shadowColor, float tone) {
    return shadowColor + (1.0 - shadowColor) * tone;
}

// pbrkit_fetchRamp: a ramp image's colour at tone in [0, 1] (clamped), computed from texelFetch: linear
//   between the texel centres (i + 0.5) / M of its middle row (row H / 2), clamp to edge; full float
//   precision, any format (unfilterable RGBA32F included).
// source: Lake et al. 2000, sec. 3 (a 1-D texture indexed by the tone); OpenGL 4.6 sec. 8.14.2 and 8.15
//   (linear filtering, CLAMP_TO_EDGE)
// roughness: none
// pbrkit: pbrkit.npr.toon.ramp_lookup, pbrkit.core.filtering.texel_pair
vec3 pbrkit_fetchRamp(highp sampler2D ramp, float tone) {
    ivec2 size = textureSize(ramp, 0);
    int row = size.y / 2;
    float t = clamp(clamp(tone, 0.0, 1.0) * float(size.x) - 0.5, 0.0, float(size.x - 1));
    int i0 = min(int(floor(t)), max(size.x - 2, 0));
    int i1 = min(i0 + 1, size.x - 1);
    float a = t - float(i0);
    return texelFetch(ramp, ivec2(i0, row), 0).rgb * (1.0 - a) + texelFetch(ramp, ivec2(i1, row), 0).rgb * a;
}

// pbrkit_sampleRamp: the same lookup with the GPU's filter (LINEAR, CLAMP_TO_EDGE, level 0; a filterable
//   format): at (tone, the centre of row H / 2), so a ramp image uploaded whole reads its middle row.
// source: Lake et al. 2000, sec. 3 (a 1-D texture indexed by the tone); OpenGL 4.6 sec. 8.14.2 (texel centres)
// roughness: none
// pbrkit: pbrkit.npr.toon.ramp_lookup
vec3 pbrkit_sampleRamp(highp sampler2D ramp, float tone) {
    float h = float(textureSize(ramp, 0).y);
    return textureLod(ramp, vec2(clamp(tone, 0.0, 1.0), (floor(h * 0.5) + 0.5) / h), 0.0).rgb;
}

// pbrkit_highlightTone: a toon highlight: the distribution's value D(n.h) relative to its peak D(1) (0 when
//   dPeak <= 0), banded at threshold (0.5 draws the lobe's half-maximum) with pbrkit_smoothStepBand.
// source: Lake et al. 2000, sec. 3 (the thresholded specular term), here on the material's own D
// roughness: none (D and its peak were evaluated with the material's alpha, e.g. D_GGX(n.h, alpha), D_GGX(1, alpha))
// pbrkit: pbrkit.npr.toon.highlight_tone
float pbrkit_highlightTone(float d, float dPeak, float threshold, float softness) {
    float ratio = dPeak > 0.0 ? d / dPeak : 0.0;
    return pbrkit_smoothStepBand(ratio, threshold, softness);
}

// ------------------------------------------------------------ VRM MToon 1.0

// pbrkit_linearstep: saturate((x - a) / (b - a)) (a != b).
// source: VRM Consortium, "VRMC_materials_mtoon 1.0" specification, Lighting (its linearstep)
// roughness: none
// pbrkit: pbrkit.npr.toon.linearstep
float pbrkit_linearstep(float a, float b, float x) {
    return clamp((x - a) / (b - a), 0.0, 1.0);
}

// pbrkit_mtoonShading: MToon's shading factor linearstep(-1 + toony, 1 - toony, n.l + shift) (toony < 1;
//   shadingToonyFactor, shadingShiftFactor (+ the shift texture)); colour = mix(shade, lit, shading) x light.
// source: VRM Consortium, "VRMC_materials_mtoon 1.0" specification, Lighting, Implementation
// roughness: none
// pbrkit: pbrkit.npr.toon.mtoon_shading
float pbrkit_mtoonShading(float NoL, float shift, float toony) {
    return pbrkit_linearstep(-1.0 + toony, 1.0 - toony, NoL + shift);
}

// pbrkit_parametricRim: MToon's parametric rim pow(saturate(1 - n.v + lift), max(power, 1e-5))
//   (parametricRimFresnelPowerFactor, parametricRimLiftFactor; 0 where the base is 0).
// source: VRM Consortium, "VRMC_materials_mtoon 1.0" specification, Rim Lighting, Parametric Rim Lighting
// roughness: none
// pbrkit: pbrkit.npr.toon.parametric_rim
float pbrkit_parametricRim(float NoV, float power, float lift) {
    float x = clamp(1.0 - NoV + lift, 0.0, 1.0);
    return x > 0.0 ? pow(x, max(power, 1e-5)) : 0.0;
}

// pbrkit_giEqualized: MToon's equalised global illumination lerp(gi(n), (gi(up) + gi(down)) / 2, factor)
//   (giEqualizationFactor); e.g. gi = pbrkit_irradianceSH(sh, n), up / down at (0, +-1, 0).
// source: VRM Consortium, "VRMC_materials_mtoon 1.0" specification, Global Illumination, Implementation
// roughness: none
// pbrkit: pbrkit.npr.toon.gi_equalized
vec3 pbrkit_giEqualized(vec3 gi, vec3 giUp, vec3 giDown, float factor) {
    return gi + ((giUp + giDown) * 0.5 - gi) * factor;
}

// ------------------------------------------------------------ hatching (tonal art maps)

// pbrkit_hatchBlend: hatched paper reflectance for a continuous tone in [0, 1] (clamped; 0 white, 1 the
//   darkest tone) from the T = tones (1..8) TAM tones already sampled at the pixel: tones 0..3 in tam0123,
//   4..7 in tam4567 (unused entries ignored).  The sequence paper white (1), tone 0, .., tone T - 1 is blended
//   between its images floor(s) and floor(s) + 1 by frac(s), s = tone T (the last pair at s = T).
// source: Praun, Hoppe, Webb and Finkelstein 2001, "Real-Time Hatching", SIGGRAPH, sec. 4 (blending adjacent
//   TAM tones in one pass)
// roughness: none
// pbrkit: pbrkit.npr.hatching.hatch
float pbrkit_hatchBlend(float tone, int tones, vec4 tam0123, vec4 tam4567) {
    int count = clamp(tones, 1, 8);
    float s = clamp(tone, 0.0, 1.0) * float(count);
    int e0 = min(int(floor(s)), count - 1);
    float f = s - float(e0);
    float seq[9];
    seq[0] = 1.0;
    seq[1] = tam0123.x; seq[2] = tam0123.y; seq[3] = tam0123.z; seq[4] = tam0123.w;
    seq[5] = tam4567.x; seq[6] = tam4567.y; seq[7] = tam4567.z; seq[8] = tam4567.w;
    return (1.0 - f) * seq[e0] + f * seq[e0 + 1];
}

// pbrkit_hatchLevel: the TAM's mip level lambda = log2(footprint) clamped to [0, L - 1] (footprint > 0: level-0
//   texels per pixel; L = levels), for textureLod on every tone with LINEAR_MIPMAP_LINEAR.
// source: OpenGL 4.6 sec. 8.14.1 and 8.14.3 (lambda = log2 of the scale factor, LINEAR_MIPMAP_LINEAR); Praun et
//   al. 2001, sec. 4 (mip-mapped TAMs)
// roughness: none
// pbrkit: pbrkit.npr.hatching.hatch
float pbrkit_hatchLevel(float footprint, float levels) {
    return clamp(log2(footprint), 0.0, levels - 1.0);
}

#endif
