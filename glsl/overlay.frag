#version 130
// Viewer insets, one texture drawn flat:
//   Kind 0  the item buffer, polygon IDs in false colour: (ID + 1) * 0xF9C94F mod 2^24 as R, G, B
//           bytes (black: nothing seen), the same colours as src/display/passes.rs writes
//   Kind 1  a radiance atlas, tone-mapped as image.png; texels that are no patch dark blue-grey
//   Kind 2  the unshot atlas as the heat map of glsl/viewer.frag

uniform sampler2D Image;
uniform int Kind;
uniform float Exposure;
uniform float HeatMax;
uniform float HeatDecades;

in vec2 UV;
out vec4 Color;

vec3 srgb(vec3 c)
{
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

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

const vec3 NoPatch = vec3(28.0, 30.0, 44.0) / 255.0;

void main()
{
    vec4 t = texture(Image, UV);
    if (Kind == 0) {
        uvec3 b = uvec3(t.rgb * 255.0 + 0.5);
        uint n = b.r | (b.g << 8) | (b.b << 16);
        uint f = (n * 0xF9C94Fu) & 0xFFFFFFu;
        Color = vec4(float(f & 255u), float((f >> 8) & 255u), float(f >> 16), 255.0) / 255.0;
    } else if (Kind == 1) {
        Color = vec4(t.a > 0.0 ? srgb(clamp(t.rgb * Exposure, 0.0, 1.0)) : NoPatch, 1.0);
    } else {
        float l = (t.r + t.g + t.b) / 3.0;
        vec3 c = l > 0.0 ? heat(1.0 + (log(l) / log(10.0) - HeatMax) / HeatDecades) : heat(0.0);
        Color = vec4(t.a > 0.0 ? c : NoPatch, 1.0);
    }
}
