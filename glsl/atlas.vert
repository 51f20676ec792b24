#version 130
// Reconstruction pass, vertex stage: rectangles of the atlas (the lightmaps of the receivers,
// neighbours merged), given in clip space; the fragment stage reads each patch's geometry from the
// atlas textures patchdata.frag wrote.

in vec2 Corner;

void main()
{
    gl_Position = vec4(Corner, 0.0, 1.0);
}
