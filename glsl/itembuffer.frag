#version 130
// Visibility pass, fragment stage: write the polygon's ID as a colour (the item buffer). The
// vertex stage encodes it (encode_id), once per vertex instead of once per fragment.

flat in vec4 ItemColor;
out vec4 Color;

void main()
{
    Color = ItemColor;
}
