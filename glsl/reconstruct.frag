#version 130
// Reconstruction pass, fragment stage (paper 3.2.2, codes 1 and 2). For this patch (fragment):
// is it the polygon the shooter sees in this direction (item buffer ID test)? If so, the point
// form factor F = max(cos_i cos_j, 0) / (pi r^2) and the received radiance
// dL = rho * F * ShootEnergy, where ShootEnergy is the shooter's unshot radiance times its area.
// The paper adds the result to the lightmaps (GL_ADD + glCopyTexSubImage2D); here the addition
// is done in this shader and the host copies the sums over the old textures.

in vec3 RecvPos;
flat in vec3 RecvNormal;
flat in vec3 RecvColor;
flat in float RecvId;

uniform sampler2D HemiItemBuffer;  // visibility pass result (RGBA8 IDs)
uniform sampler2D Radiosity;       // accumulated radiance per patch (alpha: ID + 1)
uniform sampler2D Unshot;          // unshot radiance per patch (alpha: ID + 1)
uniform mat4 ShooterView;
uniform vec3 ShootPos;
uniform vec3 ShootNormal;
uniform vec3 ShootEnergy;          // unshot radiance x area of the shooter, RGB
uniform float ShooterId;
uniform vec4 ShooterTexels;        // [x0, y0, x1, y1) atlas texels whose unshot energy is shot

out vec4 NewRadiosity;
out vec4 NewUnshot;

vec4 encode_id(float id)
{
    int n = int(id + 0.5) + 1;
    return vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0) / 255.0;
}

// Code 1: project the fragment onto the shooter's hemisphere and compare IDs.
bool Visible()
{
    vec3 proj = normalize((ShooterView * vec4(RecvPos, 1.0)).xyz);
    if (proj.z >= 0.0)
        return false;
    vec2 uv = proj.xy * 0.5 + 0.5;
    vec4 xtex = texture(HemiItemBuffer, uv);
    return all(equal(floor(xtex.rgb * 255.0 + 0.5), floor(encode_id(RecvId).rgb * 255.0 + 0.5)));
}

// Code 2: form factor and received energy.
vec3 FormFactorEnergy()
{
    vec3 r = ShootPos - RecvPos;
    float distance = dot(r, r);
    r = normalize(r);
    float cosi = dot(RecvNormal, r);
    float cosj = -dot(ShootNormal, r);
    const float pi = 3.1415926535897932;
    float Fij = max(cosi * cosj, 0.0) / (pi * distance);
    Fij *= Visible() ? 1.0 : 0.0;
    return ShootEnergy * RecvColor * Fij;
}

void main()
{
    ivec2 texel = ivec2(gl_FragCoord.xy);
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
