#version 130
// Visibility pass, hemicube variant (Cohen & Greenberg 1985, the paper's reference [3]): one of
// five 90-degree perspective views from the shooter. A perspective projection keeps straight
// edges straight, so the rasteriser draws them exactly.

uniform mat4 FaceViewProjection;  // projection * face rotation * shooter view
uniform float ShooterId;          // the shooter is not drawn (see hemiproj.vert)

in vec3 Position;
in float PolygonId;

flat out vec4 ItemColor;  // the polygon's ID as a colour (see encode_id)

// ID + 1 spread over the red, green and blue bytes of the item buffer's RGBA8 (0: no polygon),
// so up to 2^24 - 1 polygons are told apart exactly. Per vertex, not per fragment: it is the same
// for the whole polygon.
vec4 encode_id(float id)
{
    int n = int(id + 0.5) + 1;
    return vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0) / 255.0;
}

void main()
{
    ItemColor = encode_id(PolygonId);
    gl_Position = (PolygonId == ShooterId) ? vec4(0.0, 0.0, 2.0, 1.0)
                                           : FaceViewProjection * vec4(Position, 1.0);
}
