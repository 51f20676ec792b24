#version 130
// Visibility pass, fragment stage: write the polygon's ID as a colour (the item buffer).
// ID + 1 is spread over the red, green and blue bytes so 0 means "no polygon" and up to 2^24 - 1
// polygons are told apart exactly in an RGBA8 texture.

flat in float ItemId;
out vec4 Color;

vec4 encode_id(float id)
{
    int n = int(id + 0.5) + 1;
    return vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0) / 255.0;
}

void main()
{
    Color = encode_id(ItemId);
}
