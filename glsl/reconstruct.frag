#version 130
// Reconstruction pass, fragment stage (paper 3.2.2, codes 1 and 2). For this patch (fragment):
// is it the polygon the shooter sees in this direction (item buffer ID test)? If so, the form
// factor and the received radiance. The paper adds the result to the lightmaps (GL_ADD +
// glCopyTexSubImage2D); here the addition is done in this shader and the host copies the sums
// over the old textures.

uniform sampler2D PatchPosition;   // per patch: world position, polygon ID + 1 (0: no patch)
uniform sampler2D PatchNormal;
uniform sampler2D PatchReflectance;

// This fragment's patch, read from the atlas textures (see patchdata.frag) at the start of main.
vec3 RecvPos = vec3(0.0);
vec3 RecvNormal = vec3(0.0, 0.0, 1.0);
vec3 RecvColor = vec3(0.0);
float RecvId = -1.0;

uniform sampler2D HemiItemBuffer;  // visibility pass result (RGBA8 IDs)
uniform sampler2D Radiosity;       // accumulated radiance per patch (alpha: ID + 1)
uniform sampler2D Unshot;          // unshot radiance per patch (alpha: ID + 1)
uniform mat4 ShooterView;
uniform vec3 ShootPos;
uniform vec3 ShootNormal;
uniform vec3 ShootEnergy;          // unshot radiance x area of the shooter, RGB
uniform float ShooterId;
uniform vec4 ShooterTexels;        // [x0, y0, x1, y1) atlas texels whose unshot energy is shot

uniform int FormFactorKind;        // 0: point (paper), 1: polygon (exact, finite)
uniform vec3 ShootCorners[12];     // the shooter's outline, counter-clockwise from its front
uniform int ShootCornerCount;
uniform float ShootArea;           // area of that outline

uniform int HemiCube;              // 0: hemispherical projection (paper), 1: hemicube
uniform mat3 FaceRotation[5];      // hemicube faces: shooter eye space -> face eye space
uniform int Robust;                // 0: nearest pixel's ID (paper); 1: ID or depth with slack
uniform sampler2D HemiDistance;    // distance from the shooter to what each pixel shows

out vec4 NewRadiosity;
out vec4 NewUnshot;

const float pi = 3.1415926535897932;
// Robust visibility: how many pixels' worth of the receiver's slope the depth of what its pixel
// shows may fall short of its own (about a pixel from its direction to the pixel's centre, and
// room for the slope estimate).
const float DepthSlack = 1.5;
// Surfaces seen more edge-on than this count as this: their slope's slack stays a few pixels,
// or light would reach under a block through its grazing edge.
const float MinCosine = 0.25;

vec4 encode_id(float id)
{
    int n = int(id + 0.5) + 1;
    return vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0) / 255.0;
}

bool same_id(vec2 uv, vec3 want)
{
    return all(equal(floor(texture(HemiItemBuffer, uv).rgb * 255.0 + 0.5), want));
}

// Where the direction d (shooter eye space) lands in the item buffer, in [0,1]^2.
vec2 item_coordinates(vec3 d)
{
    if (HemiCube == 0) {
        // The paper: project onto the hemisphere, flatten onto its base disk.
        return normalize(d).xy * 0.5 + 0.5;
    }
    // Hemicube: the face of the largest component; faces are stacked left to right.
    int face;
    vec3 a = abs(d);
    if (-d.z >= a.x && -d.z >= a.y)
        face = 0;
    else if (a.x >= a.y)
        face = d.x > 0.0 ? 1 : 2;
    else
        face = d.y > 0.0 ? 3 : 4;
    vec3 f = FaceRotation[face] * d;
    // Inside this face's own pixels: at u = 1 the nearest pixel would be the next face's first.
    float half_pixel = 0.5 / float(textureSize(HemiItemBuffer, 0).y);
    vec2 uv = clamp((f.xy / -f.z) * 0.5 + 0.5, half_pixel, 1.0 - half_pixel);
    return vec2((float(face) + uv.x) / 5.0, uv.y);
}

// Code 1: is this fragment what the shooter sees in its direction?
bool Visible()
{
    vec3 d = (ShooterView * vec4(RecvPos, 1.0)).xyz;
    if (d.z >= 0.0)
        return false;
    vec2 uv = item_coordinates(d);
    vec3 want = floor(encode_id(RecvId).rgb * 255.0 + 0.5);
    if (same_id(uv, want))
        return true;
    if (Robust == 0)
        return false;
    // Robust: the pixel shows something else, but is it in front of this patch (a shadow) or
    // beside it (a joint, or a receiver too small to own a pixel)? Beside it: what the pixel
    // shows is no nearer than the receiver's own surface could be within about a pixel, a depth
    // range that grows as the receiver is seen edge-on (slope-scaled, as a shadow-map bias). No
    // neighbourhood of pixels is searched for the receiver's ID: that lets light through every
    // shadow edge.
    float r = length(d);
    float shown = texture(HemiDistance, uv).r;
    vec3 n = mat3(ShooterView) * RecvNormal;
    float grazing = max(abs(dot(d, n)) / r, MinCosine);
    float pixel = 2.0 / float(textureSize(HemiItemBuffer, 0).y);
    if (HemiCube == 0)
        pixel /= max(-d.z / r, 0.1);  // the disk's pixels widen toward the horizon
    return shown >= r * (1.0 - DepthSlack * pixel / grazing);
}

// The exact factor from this fragment (a differential area) to the shooter's outline, clipped
// to the fragment's side of its tangent plane (Lambert's contour integral).
float PolygonFormFactor()
{
    if (dot(ShootNormal, RecvPos - ShootCorners[0]) <= 0.0)
        return 0.0;
    vec3 clipped[13];
    int m = 0;
    for (int k = 0; k < ShootCornerCount; ++k) {
        vec3 a = ShootCorners[k] - RecvPos;
        vec3 b = ShootCorners[k + 1 < ShootCornerCount ? k + 1 : 0] - RecvPos;
        float da = dot(a, RecvNormal);
        float db = dot(b, RecvNormal);
        if (da > 0.0)
            clipped[m++] = a;
        if ((da > 0.0) != (db > 0.0))
            clipped[m++] = a + (b - a) * (da / (da - db));
    }
    if (m < 3)
        return 0.0;
    float sum = 0.0;
    for (int k = 0; k < m; ++k) {
        vec3 a = normalize(clipped[k]);
        vec3 b = normalize(clipped[k + 1 < m ? k + 1 : 0]);
        vec3 c = cross(a, b);
        float len = length(c);
        if (len > 1e-12)
            sum += acos(clamp(dot(a, b), -1.0, 1.0)) * dot(c / len, RecvNormal);
    }
    return min(abs(sum) / (2.0 * pi), 1.0);
}

// Code 2: form factor and received energy. The visibility lookup (code 1) comes last, only
// where the form factor is not zero: most receivers of a shot face away or lie behind it.
vec3 FormFactorEnergy()
{
    float F;
    if (FormFactorKind == 1) {
        F = PolygonFormFactor() / ShootArea;
    } else {
        vec3 r = ShootPos - RecvPos;
        float distance = dot(r, r);
        r = normalize(r);
        float cosi = dot(RecvNormal, r);
        float cosj = -dot(ShootNormal, r);
        F = max(cosi * cosj, 0.0) / (pi * distance);
    }
    if (F <= 0.0 || !Visible())
        return vec3(0.0);
    return ShootEnergy * RecvColor * F;
}

void main()
{
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(PatchPosition, texel, 0);
    if (position.w == 0.0)
        discard;  // not a patch: the attachments keep their cleared zero
    RecvPos = position.xyz;
    RecvId = position.w - 1.0;
    RecvNormal = texelFetch(PatchNormal, texel, 0).xyz;
    RecvColor = texelFetch(PatchReflectance, texel, 0).rgb;
    vec4 radiosity = texelFetch(Radiosity, texel, 0);
    vec4 unshot = texelFetch(Unshot, texel, 0);
    // A planar shooter sends nothing to itself.
    bool shooter = RecvId == ShooterId;
    vec3 delta = shooter ? vec3(0.0) : FormFactorEnergy();
    // The shooter has shot its unshot energy: clear it (paper: "清零").
    bool shot = shooter && all(greaterThanEqual(gl_FragCoord.xy, ShooterTexels.xy))
        && all(lessThan(gl_FragCoord.xy, ShooterTexels.zw));
    vec3 remaining = shot ? vec3(0.0) : unshot.rgb;
    NewRadiosity = vec4(radiosity.rgb + delta, RecvId + 1.0);
    NewUnshot = vec4(remaining + delta, RecvId + 1.0);
}
