#version 130
// Reconstruction pass, fragment stage (paper 3.2.2, codes 1 and 2). For this patch (fragment):
// is it the polygon the shooter sees in this direction (item buffer ID test)? If so, the form
// factor and the received radiance ΔL. The paper's GL_ADD texture environment, in GLSL 1.30:
// the patch's current radiance and unshot radiance are read from the lightmap textures and
// old + ΔL is written to the two renderbuffer attachments; the host then copies them back into
// the textures with glCopyTexSubImage2D, ready for the next shot. The shooter's own texels get
// unshot radiance zero ("the shooter's lightmap energy is cleared"), or, when overshooting
// (beyond the paper), ShooterRemainder.
//
// SHOOTERS (defined by the host; 1 in the paper): how many shooters this pass serves
// (`SolveOptions::shooters_per_pass`, beyond the paper). Every shooter uniform is an array with
// one element per shooter, each shooter has its own item buffer, and a patch adds up what every
// shooter sends it.
#ifndef SHOOTERS
#define SHOOTERS 1
#endif

uniform sampler2D PatchPosition;   // per patch: world position, polygon ID + 1 (0: no patch)
uniform sampler2D PatchNormal;
uniform sampler2D PatchReflectance;
uniform sampler2D LightmapRadiosity; // the lightmaps as the last glCopyTexSubImage2D left them
uniform sampler2D LightmapUnshot;
uniform ivec4 ShooterTexels[SHOOTERS];   // [x0, y0, x1, y1): the texels that shoot now
uniform vec3 ShooterRemainder[SHOOTERS]; // their patches' unshot radiance after the shot: 0, or
                                         // minus the overshoot

// This fragment's patch, read from the atlas textures (see patchdata.frag) at the start of main.
vec3 RecvPos = vec3(0.0);
vec3 RecvNormal = vec3(0.0, 0.0, 1.0);
vec3 RecvColor = vec3(0.0);
float RecvId = -1.0;
bool RecvPatch = false;            // false: a texel that is no patch

uniform sampler2D HemiItemBuffer[SHOOTERS]; // visibility pass results (RGBA8 IDs)
uniform int HemiRes[SHOOTERS];     // each shot's resolution: its item buffer's lower-left
                                   // (5 x) HemiRes x HemiRes pixels
uniform mat4 ShooterView[SHOOTERS];
uniform vec3 ShootPos[SHOOTERS];
uniform vec3 ShootNormal[SHOOTERS];
uniform vec3 ShootEnergy[SHOOTERS]; // unshot radiance x area of the shooter, RGB
uniform float ShooterId[SHOOTERS];

uniform int FormFactorKind;        // 0: point (paper), 1: polygon (exact, finite)
uniform vec3 ShootCorners[12 * SHOOTERS]; // each shooter's outline, counter-clockwise from its
                                          // front: 12 slots per shooter
uniform int ShootCornerCount[SHOOTERS];
uniform float ShootArea[SHOOTERS]; // area of that outline

// Beyond the paper (face clusters, src/solver/cluster_parts.rs): a face cluster's members as its
// shot's near field. Receivers nearer shooter k's point than ShootReach[k] get the members' own
// outlines and normals instead of its one flat outline: ShootParts rows ShootPartRows[k].x and
// on, ShootPartRows[k].y of them (0 for every other shooter). A row: texel 0 the member's share
// of the shooter's energy over its outline's area (RGB) and its corner count, texel 1 its
// normal, then its corners.
// FACE_CLUSTERS (defined by the host): 1 in the variants drawn for passes with a face cluster's
// shooter (`reconstruction::Variants`); other passes compile none of this, which costs llvmpipe
// even where it runs no part.
#ifndef FACE_CLUSTERS
#define FACE_CLUSTERS 0
#endif
uniform sampler2D ShootParts;
uniform ivec2 ShootPartRows[SHOOTERS];
uniform float ShootReach[SHOOTERS];

uniform int HemiCube;              // 0: hemispherical projection (paper), 1: hemicube
uniform int Robust;                // 0: nearest pixel's ID (paper); 1: ID, or the shown plane
uniform sampler2D PolygonPlanes;   // per polygon ID (row-major, width PlanesWidth): n, n.x
uniform int PlanesWidth;           // a power of two (llvmpipe divides integers lane by lane)
uniform int PlanesShift;           // log2(PlanesWidth)
uniform float PlaneSlack;          // world units: how far beyond a plane counts as behind it

out vec4 NewRadiosity;
out vec4 NewUnshot;

const float pi = 3.1415926535897932;

// FORM_FACTOR_KIND, HEMI_CUBE, ROBUST: the solve's choices above, compiled in as constants
// when the host defines them (`Tuning::compile_choices`; llvmpipe runs both sides of a branch
// even on a uniform), read from the uniforms otherwise.
#ifndef FORM_FACTOR_KIND
#define FORM_FACTOR_KIND FormFactorKind
#endif
#ifndef HEMI_CUBE
#define HEMI_CUBE HemiCube
#endif
#ifndef ROBUST
#define ROBUST Robust
#endif

// The item-buffer texel the direction d (shooter k's eye space, d.z < 0) lands in.
ivec2 item_texel(vec3 d, int k)
{
    ivec2 size = ivec2(HemiRes[k]);
    if (HEMI_CUBE == 0) {
        // The paper: project onto the hemisphere, flatten onto its base disk.
        vec2 uv = normalize(d).xy * 0.5 + 0.5;
        return clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
    }
    // Hemicube: the face of the largest component; faces are stacked left to right. Each face's
    // (x, y, depth) is d's components permuted and signed as `face_rotations` (src/solver/visibility/mod.rs)
    // rotates them: front (d.x, d.y, -d.z), +x (d.z, d.y, d.x), -x (-d.z, d.y, -d.x),
    // +y (d.x, d.z, d.y), -y (-d.x, d.z, -d.y). Selects, not a dynamically indexed matrix array:
    // llvmpipe gathers such an array lane by lane.
    vec3 a = abs(d);
    bool front = -d.z >= a.x && -d.z >= a.y;
    bool side_x = !front && a.x >= a.y;
    bool side_y = !front && !side_x;
    float face = front ? 0.0 : side_x ? (d.x > 0.0 ? 1.0 : 2.0) : (d.y > 0.0 ? 3.0 : 4.0);
    float sx = side_x ? sign(d.x) : 1.0;
    float sy = side_y ? sign(d.y) : 1.0;
    vec3 f = front ? vec3(d.x, d.y, -d.z)
                   : side_x ? vec3(sx * d.z, d.y, sx * d.x) : vec3(sy * d.x, d.z, sy * d.y);
    int r = HemiRes[k];
    // Inside this face's own pixels: at u = 1 the nearest pixel would be the next face's first.
    ivec2 t = clamp(ivec2(((f.xy / f.z) * 0.5 + 0.5) * float(r)), ivec2(0), ivec2(r - 1));
    return ivec2(int(face) * r + t.x, t.y);
}

// Code 1: is this fragment what shooter k sees in its direction (in its item buffer `items`)?
bool Visible(int k, sampler2D items)
{
    vec3 d = (ShooterView[k] * vec4(RecvPos, 1.0)).xyz;
    if (d.z >= 0.0)
        return false;
    ivec3 shown = ivec3(texelFetch(items, item_texel(d, k), 0).rgb * 255.0 + 0.5);
    int n = shown.r + 256 * shown.g + 65536 * shown.b;  // ID + 1; 0: nothing
    if (n == int(RecvId + 0.5) + 1)
        return true;
    if (ROBUST == 0)
        return false;
    // Robust: the pixel shows another polygon X (or nothing). X hides this patch only if the
    // segment from the shooter to the patch crosses X's plane, i.e. the two lie on opposite
    // sides of it. Exact wherever X covers this patch's direction, whatever the angle: a
    // neighbour at a joint, a coplanar neighbour, or what lies behind a patch too small to own a
    // pixel do not hide it; a glass pane or a door a few millimetres in front of a wall does
    // (a depth comparison with slack cannot tell those apart at a pixel's resolution).
    if (n == 0)
        return true;
    vec4 plane = texelFetch(PolygonPlanes, ivec2((n - 1) & (PlanesWidth - 1), (n - 1) >> PlanesShift), 0);
    float hs = dot(plane.xyz, ShootPos[k]) - plane.w;
    float hr = dot(plane.xyz, RecvPos) - plane.w;
    return !(abs(hs) > PlaneSlack && abs(hr) > PlaneSlack && (hs > 0.0) != (hr > 0.0));
}

// One edge's term of Lambert's contour integral, from corner a to corner b (relative to the
// receiver): the angle the edge subtends times the cosine of its plane with the receiver's
// normal. Scale-free, so a and b need no normalising; zero for a degenerate edge.
float EdgeTerm(vec3 a, vec3 b)
{
    vec3 c = cross(a, b);
    float len = length(c);
    return atan(len, dot(a, b)) * dot(c, RecvNormal) / max(len, 1e-30);
}

// SHOOTER_ABOVE (defined by the host for a second program): every polygon drawn has the whole
// shooter above its tangent plane, so nothing needs clipping. llvmpipe runs both sides of every
// branch, even one on a uniform, so the host compiles this file twice and draws the blocks that
// need no clipping with the cheaper variant. Where nothing is clipped both compute the same sum,
// up to float rounding (tests/tuning.rs:
// skipping_needless_clipping_changes_nothing_but_float_noise).
// One edge of a contour clipped to the receiver's side of its tangent plane (see
// PolygonFormFactor): a and b relative to the receiver, da and db their heights above the plane.
// Adds the edge's part above the plane to sum, and records where the contour leaves the side
// (exit_point) and comes back (entry_point).
void ClippedEdge(vec3 a, float da, vec3 b, float db, inout float sum, inout vec3 exit_point,
                 inout vec3 entry_point)
{
    bool above_a = da > 0.0;
    bool crossing = above_a != (db > 0.0);
    vec3 p = a + (b - a) * (crossing ? da / (da - db) : 0.0);
    exit_point = (crossing && above_a) ? p : exit_point;
    entry_point = (crossing && !above_a) ? p : entry_point;
    float term = EdgeTerm((crossing && !above_a) ? p : a, (crossing && above_a) ? p : b);
    sum += (above_a || db > 0.0) ? term : 0.0;
}

#ifndef SHOOTER_ABOVE
#define SHOOTER_ABOVE 0
#endif

// The exact factor from this fragment (a differential area) to the shooter's outline, clipped
// to the fragment's side of its tangent plane (Lambert's contour integral). The convex outline
// leaves that side at most once and comes back at most once: the clipped outline is its edges
// above the plane, cut where they cross it, closed by one edge along the plane from the exit to
// the entry point. Written without branches or a local array: llvmpipe runs a block of
// fragments in lockstep, through both sides of every branch they disagree on, and spills a
// dynamically indexed local array to memory; this way each edge costs one EdgeTerm.
// CORNERS (defined by the host for quadrilateral shooters, the rooms' usual case): the corner
// count is known when compiling, so the loops unroll and every corner is a uniform read once;
// with a count known only at run time llvmpipe fetches ShootCorners[i] lane by lane.
// Within PlaneSlack of a plane counts as on it: a receiver on the shooter's plane, or a shooter
// in the receiver's tangent plane, gets 0 (seen edge-on: exact), where the contour integral of
// float-noise heights reads up to 1 (the back-to-back faces of a double-sided quad, crossed
// quads; src/solver/form_factor.rs, `polygon`).
#ifndef CORNERS
#define CORNERS 0
#endif
#if CORNERS
#define CORNER_COUNT CORNERS
#else
#define CORNER_COUNT ShootCornerCount[k]
#endif
float PolygonFormFactor(int k)
{
    int c0 = 12 * k;   // shooter k's first corner
    if (dot(ShootNormal[k], RecvPos - ShootCorners[c0]) <= PlaneSlack)
        return 0.0;
    vec3 a = ShootCorners[c0 + CORNER_COUNT - 1] - RecvPos;
    float sum = 0.0;
#if SHOOTER_ABOVE
    for (int i = 0; i < CORNER_COUNT; ++i) {
        vec3 b = ShootCorners[c0 + i] - RecvPos;
        sum += EdgeTerm(a, b);
        a = b;
    }
#else
    float da = dot(a, RecvNormal);
    float highest = da;
    vec3 exit_point = vec3(0.0);   // both stay zero when nothing is clipped: a null closing edge
    vec3 entry_point = vec3(0.0);
    for (int i = 0; i < CORNER_COUNT; ++i) {
        vec3 b = ShootCorners[c0 + i] - RecvPos;
        float db = dot(b, RecvNormal);
        highest = max(highest, db);
        ClippedEdge(a, da, b, db, sum, exit_point, entry_point);
        a = b;
        da = db;
    }
    sum += EdgeTerm(exit_point, entry_point);
    sum = highest > PlaneSlack ? sum : 0.0;
#endif
    return min(abs(sum) / (2.0 * pi), 1.0);
}

// Beyond the paper: Σ over the first `rows` of shooter k's parts (its members) of weight × the
// factor to the part's outline, clipped as PolygonFormFactor's. The caller gives 0 rows beyond
// ShootReach[k], so a block of far fragments runs no iteration (llvmpipe runs both sides of a
// branch, but a loop only while a lane is in it).
vec3 PartsFactor(int k, int rows)
{
    vec3 sum = vec3(0.0);
    for (int m = 0; m < rows; ++m) {
        int row = ShootPartRows[k].x + m;
        vec4 head = texelFetch(ShootParts, ivec2(0, row), 0);
        vec3 normal = texelFetch(ShootParts, ivec2(1, row), 0).xyz;
        int count = int(head.w);
        vec3 a = texelFetch(ShootParts, ivec2(1 + count, row), 0).xyz - RecvPos;
        bool facing = dot(normal, -a) > PlaneSlack;
        float da = dot(a, RecvNormal);
        float highest = da;
        float part = 0.0;
        vec3 exit_point = vec3(0.0);
        vec3 entry_point = vec3(0.0);
        for (int i = 0; i < count; ++i) {
            vec3 b = texelFetch(ShootParts, ivec2(2 + i, row), 0).xyz - RecvPos;
            float db = dot(b, RecvNormal);
            highest = max(highest, db);
            ClippedEdge(a, da, b, db, part, exit_point, entry_point);
            a = b;
            da = db;
        }
        part += EdgeTerm(exit_point, entry_point);
        bool seen = facing && highest > PlaneSlack;
        sum += head.rgb * (seen ? min(abs(part) / (2.0 * pi), 1.0) : 0.0);
    }
    return sum;
}

// Code 2: form factor and received energy from shooter k (for a visible receiver).
vec3 FormFactorEnergy(int k)
{
    float F;
    if (FORM_FACTOR_KIND == 1) {
        F = PolygonFormFactor(k) / ShootArea[k];
#if FACE_CLUSTERS
        // Near a face cluster, its members' own outlines (ShootReach is 0 for other shooters).
        bool near = distance(RecvPos, ShootPos[k]) < ShootReach[k];
        vec3 parts = PartsFactor(k, near ? ShootPartRows[k].y : 0);
        return ShootEnergy[k] * RecvColor * (near ? parts : vec3(max(F, 0.0)));
#endif
    } else {
        vec3 r = ShootPos[k] - RecvPos;
        float distance = dot(r, r);
        r = normalize(r);
        // Each cosine clamped on its own (the paper clamps the product, which lets a receiver
        // behind the shooter and facing away from it through: two negative cosines).
        float cosi = max(dot(RecvNormal, r), 0.0);
        float cosj = max(-dot(ShootNormal[k], r), 0.0);
        F = cosi * cosj / (pi * distance);
    }
    return ShootEnergy[k] * RecvColor * max(F, 0.0);
}

// MARK (defined by the host for a program of its own; see `Tuning::marking_pass`): the marking
// pass, drawn over the same squares just before the pass proper. It runs the cheap tests only
// and writes depth where a texel can receive (a patch, not the shooter's, seen from the shooter)
// or shoots now; the pass proper (compiled with MARKED) then tests depth EQUAL and computes ΔL
// only there. llvmpipe runs every branch of a shader for every fragment, but skips the shader
// for a group of fragments that all fail an early depth test: the only way it has of not
// computing form factors for the texels the shooter cannot see. Texels the pass proper does not
// write keep what the renderbuffers hold: the last copy's values, which the textures hold too.
#ifndef MARK
#define MARK 0
#endif
#ifndef MARKED
#define MARKED 0
#endif

// Does this patch receive from shooter k? Not a texel without a patch, not the shooter's own
// polygon (a plane sends nothing to itself), and visible from the shooter.
bool Receives(int k, sampler2D items)
{
    return RecvPatch && RecvId != ShooterId[k] && Visible(k, items);
}

// ΔL from shooter k.
vec3 Received(int k, sampler2D items)
{
#if MARKED && SHOOTERS == 1
    // The marking pass found this texel visible (or shooting): no second visibility test.
    bool seen = RecvPatch && RecvId != ShooterId[k];
#else
    // With several shooters the marking pass found that one of them sees it, not which one.
    bool seen = Receives(k, items);
#endif
    return seen ? FormFactorEnergy(k) : vec3(0.0);
}

// Does this texel shoot now, as one of shooter k's? Then its patch keeps that shooter's remainder.
bool Shooting = false;
vec3 Remainder = vec3(0.0);
void ShootsFrom(ivec2 texel, int k)
{
    bool s = all(greaterThanEqual(texel, ShooterTexels[k].xy)) && all(lessThan(texel, ShooterTexels[k].zw));
    Shooting = Shooting || s;
    Remainder = s ? ShooterRemainder[k] : Remainder;
}

// The shooters one by one, each with constant array indices (GLSL 1.30 indexes sampler arrays
// with constants only, and llvmpipe fetches other arrays indexed at run time lane by lane). The
// host writes their bodies for SHOOTERS shooters and appends them to this file
// (`reconstruction::programs::per_shooter_functions`); for SHOOTERS = 2 they read:
//
//   void ShootsFromEach(ivec2 texel) { ShootsFrom(texel, 0); ShootsFrom(texel, 1); }
//   bool ReceivesFromAny()
//   {
//       return Receives(0, HemiItemBuffer[0]) || Receives(1, HemiItemBuffer[1]);
//   }
//   vec3 ReceivedFromEach()
//   {
//       vec3 delta = vec3(0.0);
//       delta += Received(0, HemiItemBuffer[0]);
//       delta += Received(1, HemiItemBuffer[1]);
//       return delta;
//   }
void ShootsFromEach(ivec2 texel); // sets Shooting and Remainder (ShootsFrom, each shooter)
bool ReceivesFromAny();           // whether any shooter of the pass reaches this patch
vec3 ReceivedFromEach();          // ΔL: the sum of what each shooter sends this patch

void main()
{
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(PatchPosition, texel, 0);
    RecvPos = position.xyz;
    RecvId = position.w - 1.0;
    RecvPatch = position.w != 0.0;
    ShootsFromEach(texel);
#if MARK
    if (!(Shooting || ReceivesFromAny()))
        discard;
#else
    RecvNormal = texelFetch(PatchNormal, texel, 0).xyz;
    RecvColor = texelFetch(PatchReflectance, texel, 0).rgb;
    vec3 delta = ReceivedFromEach();
#if MARKED
    if (!Shooting && all(equal(delta, vec3(0.0))))
        discard;   // adds nothing: the renderbuffers keep the last copy's value
#endif
    // GL_ADD: the lightmap texel plus the new energy (alpha, the polygon ID + 1, kept). A
    // shooting texel starts from its remainder instead, and keeps what the pass's other shooters
    // send it (its own polygon sends it nothing).
    vec4 radiosity = texelFetch(LightmapRadiosity, texel, 0);
    vec4 unshot = texelFetch(LightmapUnshot, texel, 0);
    NewRadiosity = vec4(radiosity.rgb + delta, radiosity.a);
    vec3 left = RecvPatch ? Remainder : vec3(0.0);
    NewUnshot = vec4((Shooting ? left : unshot.rgb) + delta, unshot.a);
#endif
}
