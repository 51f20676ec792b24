#version 130
// Reconstruction pass, vertex stage: the paper's one quad over the whole atlas (or the llvmpipe
// engine's squares of it), given in clip space, as triangle corners (Size unused) or as points
// of side Size texels; the fragment stage reads each patch's geometry from the atlas textures
// patchdata.frag wrote.

in vec2 Corner;
in float Size;

void main()
{
    gl_Position = vec4(Corner, 0.0, 1.0);
    gl_PointSize = Size;
}
