#version 130
// Reconstruction pass, vertex stage: squares of the atlas covering the lightmaps of the
// receivers, given in clip space, as points of side Size texels (or as triangle corners, Size
// unused); the fragment stage reads each patch's geometry from the atlas textures
// patchdata.frag wrote.

in vec2 Corner;
in float Size;

void main()
{
    gl_Position = vec4(Corner, 0.0, 1.0);
    gl_PointSize = Size;
}
