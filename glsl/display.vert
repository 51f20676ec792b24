#version 130
// Display: the lit scene from the camera, each polygon textured with its lightmap, with its
// smooth edges (glsl/smooth.glsl) passed on.

uniform mat4 ViewProjection;

in vec3 Position;
in vec2 LightmapUV;
in vec2 SmoothEdgeRange;

out vec2 UV;
flat out vec2 Edges;

void main()
{
    UV = LightmapUV;
    Edges = SmoothEdgeRange;
    gl_Position = ViewProjection * vec4(Position, 1.0);
}
