#version 130
// Viewer: the display pass's vertex stage (glsl/display.vert) with the polygon ID passed on,
// for the shooter highlight.

uniform mat4 ViewProjection;

in vec3 Position;
in vec2 LightmapUV;
in float PolygonId;
in vec2 SmoothEdgeRange;

out vec2 UV;
flat out float Id;
flat out vec2 Edges;

void main()
{
    UV = LightmapUV;
    Id = PolygonId;
    Edges = SmoothEdgeRange;
    gl_Position = ViewProjection * vec4(Position, 1.0);
}
