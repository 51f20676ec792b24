#version 130
// Visibility pass, vertex stage (paper 3.2.1, step 3): the paper's `hemiproj`. Each vertex is put
// in the shooter's eye space, projected onto the unit hemisphere around the shooter's normal, and
// the hemisphere is flattened onto its base disk (Nusselt's analogue). Depth is the eye-space
// distance along the normal, scaled linearly between the near and far planes (the paper's
// `ProjPos.z`); w = f - n lets the hardware divide it out while leaving x, y on the unit disk.

uniform mat4 ShooterView;   // world -> shooter eye space (looking down -z along the normal)
uniform vec2 NearFar;       // near and far planes, scene units
uniform float ShooterId;    // the shooter cannot hide anything from itself: it is not drawn

in vec3 Position;
in float PolygonId;

flat out vec4 ItemColor;  // the polygon's ID as a colour (encode_id: glsl/item_id.glsl)

vec4 hemiproj(vec3 world)
{
    vec4 mpos = ShooterView * vec4(world, 1.0);
    vec3 hemi_pt = normalize(mpos.xyz);
    float f_minus_n = NearFar.y - NearFar.x;
    vec4 ProjPos;
    ProjPos.xy = hemi_pt.xy * f_minus_n;
    ProjPos.z = -2.0 * mpos.z - NearFar.y - NearFar.x;
    ProjPos.w = f_minus_n;
    return ProjPos;
}

void main()
{
    ItemColor = encode_id(PolygonId);
    // A planar shooter lies in its own z = 0 plane; drawn, its triangles would be clipped at the
    // near plane into slivers that the linear rasteriser smears across the disk (with any
    // non-planarity). Put it beyond the far plane instead.
    gl_Position = (PolygonId == ShooterId) ? vec4(0.0, 0.0, 2.0, 1.0) : hemiproj(Position);
}
