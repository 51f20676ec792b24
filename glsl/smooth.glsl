// Smooth shading of curved surfaces (src/display/smooth.rs, beyond the paper): the lightmap
// plus the corrections of the face's smooth edges, inserted into glsl/display.frag and
// glsl/viewer.frag after the #defines of SMOOTH_FULL and SMOOTH_FADE (texels: smooth.rs's
// FULL_TEXELS and FADE_TEXELS). SmoothEdges holds four RGBA texels per smooth edge, rows of any
// width:
//   A.xy B.xy      the edge's ends in this face's lightmap (atlas texels)
//   A'.xy B'.xy    the same points in the neighbour's lightmap
//   KA.rgb, lit    V - M at A (vertex radiance minus the two faces' mean), this face has patches
//   KB.rgb, lit'   V - M at B, the neighbour has patches
// Along the edge the target is M + mix(KA, KB, t): the same from both faces, V at the ends.

uniform sampler2D SmoothEdges;

vec4 smoothEdgeTexel(int i)
{
    int w = textureSize(SmoothEdges, 0).x;
    return texelFetch(SmoothEdges, ivec2(i % w, i / w), 0);
}

// Radiance at atlas coordinate uv of a face whose smooth edges are range.y records from
// range.x. Without edges, the lightmap's bilinear value bit for bit.
vec3 smoothRadiance(sampler2D lightmap, vec2 uv, vec2 range)
{
    vec3 c = texture(lightmap, uv).rgb;
    int count = int(range.y);
    if (count == 0)
        return c;
    vec2 size = vec2(textureSize(lightmap, 0));
    vec2 p = uv * size;
    vec3 sum = vec3(0.0);
    float weights = 0.0;
    float nearest = 1e30;
    for (int k = 0; k < count; k++) {
        int i = 4 * (int(range.x) + k);
        vec4 ends = smoothEdgeTexel(i);
        vec4 other = smoothEdgeTexel(i + 1);
        vec4 ka = smoothEdgeTexel(i + 2);
        vec4 kb = smoothEdgeTexel(i + 3);
        vec2 e = ends.zw - ends.xy;
        float t = clamp(dot(p - ends.xy, e) / max(dot(e, e), 1e-12), 0.0, 1.0);
        vec2 q = ends.xy + t * e;
        float d = length(p - q);
        vec3 own = texture(lightmap, q / size).rgb;
        vec3 them = texture(lightmap, mix(other.xy, other.zw, t) / size).rgb;
        float lit = ka.a + kb.a;
        vec3 mean = lit > 0.0 ? (own * ka.a + them * kb.a) / lit : vec3(0.0);
        vec3 correction = mean + mix(ka.rgb, kb.rgb, t) - own;
        // Inverse squared distance: on an edge, that edge's correction alone.
        float w = 1.0 / (d * d + 1e-12);
        sum += w * correction;
        weights += w;
        nearest = min(nearest, d);
    }
    // Whole within SMOOTH_FULL texels of a smooth edge, none beyond SMOOTH_FULL + SMOOTH_FADE.
    float fade = clamp((SMOOTH_FULL + SMOOTH_FADE - nearest) / SMOOTH_FADE, 0.0, 1.0);
    // A correction never makes radiance negative.
    return max(c + fade * sum / weights, min(c, vec3(0.0)));
}
