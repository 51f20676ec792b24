// Inserted after `#version` into both visibility vertex shaders (`Source::insert`): the item
// buffer's ID encoding, decoded by reconstruct.frag and `VisibilityPass::read_ids`.
// ID + 1 spread over the red, green and blue bytes of the item buffer's RGBA8 (0: no polygon),
// so up to 2^24 - 1 polygons are told apart exactly. Per vertex, not per fragment: it is the same
// for the whole polygon.
vec4 encode_id(float id)
{
    int n = int(id + 0.5) + 1;
    return vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0) / 255.0;
}