#version 130
// The upload-order probe (src/golden/upload_order.rs): each upload fills the texture with its
// step's number; a draw records the number it samples (red) and whether it is its own step's
// (green).

uniform sampler2D Uploaded;
uniform float Step;

out vec4 Seen;

void main()
{
    float k = floor(texelFetch(Uploaded, ivec2(gl_FragCoord.xy) & 255, 0).r * 255.0 + 0.5);
    Seen = vec4(k, k == Step ? 1.0 : 0.0, 0.0, 1.0);
}
