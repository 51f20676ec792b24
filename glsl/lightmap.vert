#version 130
// Every polygon drawn orthographically onto its own lightmap texels in the atlas, so that each
// fragment is one patch (paper 3.2.2, step 3). Drawn twice, at set-up: with glsl/patchdata.frag
// it records each patch's position, normal and reflectance, which the reconstruction pass then
// reads (glsl/atlas.vert draws that pass); with glsl/emission.frag it writes the initial emission.

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
