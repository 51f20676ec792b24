#version 130
// Display: bilinear lookup in the (dilated) radiance atlas, smoothed across the shared edges of
// curved surfaces (glsl/smooth.glsl, inserted before this). Output is linear radiance.

uniform sampler2D Lightmap;

in vec2 UV;
flat in vec2 Edges;
out vec4 Color;

void main()
{
    Color = vec4(smoothRadiance(Lightmap, UV, Edges), 1.0);
}
