#version 130
// Visibility pass, hemicube variant (Cohen & Greenberg 1985, the paper's reference [3]): one of
// five 90-degree perspective views from the shooter. A perspective projection keeps straight
// edges straight, so the rasteriser draws them exactly.

uniform mat4 FaceViewProjection;  // projection * face rotation * shooter view
uniform float ShooterId;          // the shooter is not drawn (see hemiproj.vert)

in vec3 Position;
in float PolygonId;

flat out vec4 ItemColor;  // the polygon's ID as a colour (encode_id: glsl/item_id.glsl)

void main()
{
    ItemColor = encode_id(PolygonId);
    gl_Position = (PolygonId == ShooterId) ? vec4(0.0, 0.0, 2.0, 1.0)
                                           : FaceViewProjection * vec4(Position, 1.0);
}
