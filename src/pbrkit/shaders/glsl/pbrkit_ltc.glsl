// pbrkit_ltc.glsl: polygonal area lights with Linearly Transformed Cosines, as pbrkit
// evaluates them (pbrkit ltc --clipping exact): the LTC's integral over the light
// clipped at the true horizon.  Local shading frame: normal +z, view in the xz-plane
// (pbrkit_ltcFrame); light corners counter-clockwise seen from the lit side.
#ifndef PBRKIT_LTC_GLSL
#define PBRKIT_LTC_GLSL
precision highp float;

// pbrkit_ltcEdgeIntegral: one edge's term of the clamped-cosine polygon integral.
// source: Heitz, Dupuy, Hill, Neubelt 2016, eq. 11 (IntegrateEdge); Arvo 1995
// roughness: none (the matrix is what the fit produced)
// pbrkit: pbrkit.ltc.polygon.edge_integral
float pbrkit_ltcEdgeIntegral(vec3 a, vec3 b) {
    vec3 c = cross(a, b);
    float s = length(c);
    return s > 0.0 ? atan(s, dot(a, b)) * c.z / s : 0.0;
}

// pbrkit_ltcHorizonCrossing: where the arc p -> c crosses z = 0 (p.z, c.z of opposite signs).
// source: Heitz et al. 2016, sec. 5.2 (clipping to the horizon); Sutherland and Hodgman 1974
// roughness: none
// pbrkit: pbrkit.ltc.polygon._horizon_crossing
vec3 pbrkit_ltcHorizonCrossing(vec3 p, vec3 c) {
    vec2 xy = abs(p.z) * c.xy + abs(c.z) * p.xy;
    float l = length(xy);
    return l > 0.0 ? vec3(xy / l, 0.0) : vec3(0.0);
}

// pbrkit_ltcFormFactorQuad: the LTC's integral over a quad (q0..q3 already in the
// frame and multiplied by M^-1, any length), clipped at z >= 0; signed (positive
// counter-clockwise seen from the shading point).
// source: Heitz et al. 2016, eq. 11 and sec. 5.2 (the clipping streamed through the edge sum)
// roughness: none
// pbrkit: pbrkit.ltc.polygon.transformed_polygon_form_factor
float pbrkit_ltcFormFactorQuad(vec3 q0, vec3 q1, vec3 q2, vec3 q3) {
    vec3 q[4];
    q[0] = normalize(q0); q[1] = normalize(q1); q[2] = normalize(q2); q[3] = normalize(q3);
    float total = 0.0;
    bool haveFirst = false;
    vec3 first = vec3(0.0);
    vec3 last = vec3(0.0);
    vec3 p = q[3];
    for (int k = 0; k < 4; k++) {
        vec3 c = q[k];
        bool pIn = p.z >= 0.0;
        bool cIn = c.z >= 0.0;
        for (int emit = 0; emit < 2; emit++) {
            vec3 e;
            if (emit == 0) {
                if (pIn == cIn) continue;
                e = pbrkit_ltcHorizonCrossing(p, c);
            } else {
                if (!cIn) continue;
                e = c;
            }
            if (haveFirst) {
                total += pbrkit_ltcEdgeIntegral(e, last);
            } else {
                first = e;
                haveFirst = true;
            }
            last = e;
        }
        p = c;
    }
    if (haveFirst) total += pbrkit_ltcEdgeIntegral(first, last);
    return total / 6.283185307179586;
}

// pbrkit_ltcRect: the reflected radiance of a unit-radiance rectangle (corners p0..p3
// in the local frame, relative to the shading point) under the LTC of ltc_1 texel t
// (M^-1 = [[t.x, 0, t.z], [0, 1, 0], [t.y, 0, t.w]]), one-sided, before the ltc_2 norm.
// source: Heitz et al. 2016, sec. 3-5; pbrkit ltc --clipping exact (exact horizon clipping)
// roughness: none (the texel is looked up at perceptual roughness, alpha = r^2: pbrkit_ltcUv)
// pbrkit: pbrkit.ltc.shader.ltc_exact_rect
float pbrkit_ltcRect(vec4 t, vec3 p0, vec3 p1, vec3 p2, vec3 p3) {
    if (dot(cross(p1 - p0, p3 - p0), -p0) < 0.0) return 0.0;  // behind the light
    mat3 minv = mat3(vec3(t.x, 0.0, t.y), vec3(0.0, 1.0, 0.0), vec3(t.z, 0.0, t.w));
    float sgn = t.x * t.w - t.z * t.y >= 0.0 ? 1.0 : -1.0;
    return max(0.0, sgn * pbrkit_ltcFormFactorQuad(minv * p0, minv * p1, minv * p2, minv * p3));
}

// pbrkit_ltcRectFresnel: pbrkit's Fresnel-aware LTC of a unit-radiance rectangle with
// Schlick's F: f0 norm LTC_1 + (1 - f0) fresnel LTC_Fc, the f lobe under the ltc_1
// texel t1 and the f Fc lobe (Fc = (1 - v.h)^5) under the fresnel_ltc_1 texel tfc,
// split = (norm, fresnel) of ltc_2 (pbrkit ltc --clipping exact --fresnel-aware).
// source: Heitz et al. 2016, sec. 3-5, with Schlick's F split into two lobes (pbrkit)
// roughness: none (the texels are looked up at perceptual roughness, alpha = r^2: pbrkit_ltcUv)
// pbrkit: pbrkit.ltc.shader.ltc_fresnel_rect
float pbrkit_ltcRectFresnel(vec4 t1, vec4 tfc, vec2 split, float f0, vec3 p0, vec3 p1, vec3 p2, vec3 p3) {
    return f0 * split.x * pbrkit_ltcRect(t1, p0, p1, p2, p3)
        + (1.0 - f0) * split.y * pbrkit_ltcRect(tfc, p0, p1, p2, p3);
}

// pbrkit_ltcUv: the texture coordinate of (n.v, perceptual roughness) in an N x N table
// of the published layout (u = r, v = sqrt(1 - n.v), at texel centres).
// source: Heitz et al. 2016 (ltc_code, LUT_SCALE / LUT_BIAS); three.js LTC_Uv
// roughness: perceptual r, alpha = r^2
// pbrkit: pbrkit.ltc.shader.ltc_exact_rect
vec2 pbrkit_ltcUv(float nov, float roughness, float n) {
    vec2 uv = vec2(clamp(roughness, 0.0, 1.0), sqrt(1.0 - clamp(nov, 0.0, 1.0)));
    return uv * (n - 1.0) / n + 0.5 / n;
}
#endif
