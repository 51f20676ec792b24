#version 130
// Display: bilinear lookup in the (dilated) radiance atlas. Output is linear radiance.

uniform sampler2D Lightmap;

in vec2 UV;
out vec4 Color;

void main()
{
    Color = vec4(texture(Lightmap, UV).rgb, 1.0);
}
