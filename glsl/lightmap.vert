#version 130
// Reconstruction pass, vertex stage (paper 3.2.2): every receiver polygon is drawn
// orthographically onto its own lightmap texels in the atlas, so that each fragment is one patch.
// The world position and normal go on to the fragment stage for the form factor.

in vec3 Position;
in vec3 Normal;
in vec2 LightmapUV;
in float PolygonId;
in vec3 Reflectance;
in vec3 Emission;

out vec3 RecvPos;
flat out vec3 RecvNormal;
flat out vec3 RecvColor;
flat out vec3 RecvEmission;
flat out float RecvId;

void main()
{
    RecvPos = Position;
    RecvNormal = Normal;
    RecvColor = Reflectance;
    RecvEmission = Emission;
    RecvId = PolygonId;
    gl_Position = vec4(LightmapUV * 2.0 - 1.0, 0.0, 1.0);
}
