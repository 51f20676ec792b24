#version 130
// Display: the lit scene from the camera, each polygon textured with its lightmap.

uniform mat4 ViewProjection;

in vec3 Position;
in vec2 LightmapUV;

out vec2 UV;

void main()
{
    UV = LightmapUV;
    gl_Position = ViewProjection * vec4(Position, 1.0);
}
