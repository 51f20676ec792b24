#version 130
// Bake (src/display/bake.rs): the display's fragment shader run over the atlas itself, each
// triangle drawn at its lightmap coordinates, so that a texture holds what the display shows
// (the smooth shading of curved surfaces) for viewers that only sample it (`--gltf`).

in vec2 LightmapUV;
in vec2 SmoothEdgeRange;

out vec2 UV;
flat out vec2 Edges;

void main()
{
    UV = LightmapUV;
    Edges = SmoothEdgeRange;
    gl_Position = vec4(LightmapUV * 2.0 - 1.0, 0.0, 1.0);
}
