#version 130
// Viewer: the display pass's lookup in the (dilated) radiance atlas, smoothed across curved
// surfaces' edges (glsl/smooth.glsl, inserted before this), tone-mapped for the window exactly
// as image.png is (exposure, clamp to 1, sRGB curve), with the overlays:
//   HeatMap  the unshot radiance of each patch instead, log scale, HeatDecades below HeatMax
//   Borders  the patch (texel) grid
//   the last shooter striped orange, the next one striped cyan (ID -1: none)

uniform sampler2D Lightmap;
uniform sampler2D Unshot;   // unshot radiance, alpha = polygon ID + 1 (0: no patch); NEAREST
uniform vec2 AtlasSize;
uniform float Exposure;
uniform int HeatMap;
uniform float HeatMax;      // log10 of the largest unshot radiance (RGB mean)
uniform float HeatDecades;
uniform int Borders;
uniform float LastShooter;
uniform float NextShooter;

in vec2 UV;
flat in float Id;
flat in vec2 Edges;
out vec4 Color;

vec3 srgb(vec3 c)
{
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

// Black through purple, red and orange to pale yellow.
vec3 heat(float t)
{
    vec3 c0 = vec3(0.02, 0.02, 0.08), c1 = vec3(0.36, 0.07, 0.50), c2 = vec3(0.85, 0.20, 0.25),
         c3 = vec3(1.00, 0.62, 0.05), c4 = vec3(1.00, 1.00, 0.80);
    t = clamp(t, 0.0, 1.0) * 4.0;
    if (t < 1.0) return mix(c0, c1, t);
    if (t < 2.0) return mix(c1, c2, t - 1.0);
    if (t < 3.0) return mix(c2, c3, t - 2.0);
    return mix(c3, c4, t - 3.0);
}

void main()
{
    vec3 c;
    if (HeatMap != 0) {
        vec4 u = texture(Unshot, UV);
        float l = (u.r + u.g + u.b) / 3.0;
        c = u.a > 0.0 ? heat(l > 0.0 ? 1.0 + (log(l) / log(10.0) - HeatMax) / HeatDecades : 0.0)
                      : vec3(0.25);
    } else {
        c = srgb(clamp(smoothRadiance(Lightmap, UV, Edges) * Exposure, 0.0, 1.0));
    }
    if (Borders != 0) {
        vec2 t = UV * AtlasSize;
        vec2 d = abs(fract(t + 0.5) - 0.5) / max(fwidth(t), vec2(1e-6));
        float line = 1.0 - clamp(min(d.x, d.y) - 0.5, 0.0, 1.0);
        c = mix(c, vec3(0.05), 0.55 * line);
    }
    float stripe = step(0.5, fract((gl_FragCoord.x + gl_FragCoord.y) / 14.0));
    if (abs(Id - LastShooter) < 0.5)
        c = mix(c, vec3(1.0, 0.55, 0.1), 0.3 + 0.35 * stripe);
    else if (abs(Id - NextShooter) < 0.5)
        c = mix(c, vec3(0.1, 0.85, 1.0), 0.2 + 0.3 * stripe);
    Color = vec4(c, 1.0);
}
