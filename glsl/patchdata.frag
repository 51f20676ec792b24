#version 130
// Patch geometry, rasterised once before the first shot (beside the initialisation): for every
// patch (atlas texel) its world position and polygon ID, its normal and its reflectance. Each
// reconstruction pass then draws rectangles of the atlas and reads these instead of rasterising
// every receiver polygon again: the same fragments at the same texel centres, with the same
// interpolated positions, but without thousands of small triangles to set up per pass.

in vec3 RecvPos;
flat in vec3 RecvNormal;
flat in vec3 RecvColor;
flat in float RecvId;

out vec4 PatchPosition;     // xyz: world position of the texel centre; w: polygon ID + 1
out vec4 PatchNormal;       // xyz: polygon normal
out vec4 PatchReflectance;  // rgb: Kd

void main()
{
    PatchPosition = vec4(RecvPos, RecvId + 1.0);
    PatchNormal = vec4(RecvNormal, 0.0);
    PatchReflectance = vec4(RecvColor, 0.0);
}
