#!/usr/bin/env python3
"""Check the bundled test scenes (scenes/*/*.obj + .mtl) against CONVENTIONS.md.

Run from anywhere:  python3 scenes/check_scenes.py   (exit status 0 = all checks passed, 1 = some failed)

For every polygon: the normal from its vertex order (Newell's method; counter-clockwise seen from the front,
right-hand rule), its area, its planarity (max distance of a vertex from the Newell plane through the
centroid, relative to the polygon's diameter = largest vertex-to-vertex distance; must be < 1e-3) and
convexity, then a per-scene orientation rule:
  cornell  walls/floor/ceiling face the interior (towards ~(278,274,280)), light faces -y,
           block tops face +y, block sides face away from their own block's centre;
  box      every face points towards (0.5,0.5,0.5), and the cube is closed and consistently oriented;
  shadow   floor faces +y, light and occluder face -y.
Also: the first line is a parsable '# camera' comment with the expected values, mtllib resolves next to
the OBJ, every usemtl is defined, the materials hold the expected Kd/Ke, every face is a quad, and the
Cornell vertices equal the measured data in CONVENTIONS.md; the ceiling is cut into 4 quads around the light,
which sits in the ceiling's plane (y=548.8).

Known exception (explicit, not a tolerance fudge): the measured Cornell red wall is not planar. Its four
measured corners are twisted by 3.2 mm (0.80 mm from the best-fit plane, 1.02e-3 of its 783.5 mm diameter),
because the floor's right edge runs from x=552.8 to 549.6 while the ceiling's stays at x=556. Keeping the
measured data exact (and the box watertight) wins; that single polygon gets its own bound below and is
reported as KNOWN rather than OK. Any other non-planar polygon, or a bigger twist there, still fails.
Pure Python 3, no third-party modules.
"""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
PLANARITY_REL_TOL = 1e-3
# (scene, object) -> max allowed absolute deviation from the plane, in scene units. See docstring.
PLANARITY_KNOWN = {("cornell", "red_wall"): 0.81}

failures = []


def fail(msg):
    failures.append(msg)
    print("  FAIL: " + msg)


# ---------------------------------------------------------------- vector helpers
def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def add(a, b): return (a[0] + b[0], a[1] + b[1], a[2] + b[2])
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a): return math.sqrt(dot(a, a))
def scale(a, s): return (a[0] * s, a[1] * s, a[2] * s)
def mean(ps): return scale(tuple(map(sum, zip(*ps))), 1.0 / len(ps))
def close(a, b, eps=1e-9): return all(abs(x - y) <= eps for x, y in zip(a, b))
def fv(v): return "(" + ", ".join(f"{x:+.4f}" for x in v) + ")"


def newell(ps):
    """Area vector of a polygon (|n| = area, direction by the right-hand rule)."""
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(ps):
        b = ps[(i + 1) % len(ps)]
        n[0] += (a[1] - b[1]) * (a[2] + b[2])
        n[1] += (a[2] - b[2]) * (a[0] + b[0])
        n[2] += (a[0] - b[0]) * (a[1] + b[1])
    return scale(tuple(n), 0.5)


# ---------------------------------------------------------------- parsers
def parse_camera(line):
    """'# camera eye x y z target x y z up x y z fov deg' -> dict, or raise ValueError."""
    toks = line.split()
    if toks[:2] != ["#", "camera"]:
        raise ValueError("first line does not start with '# camera'")
    arity = {"eye": 3, "target": 3, "up": 3, "fov": 1}
    cam, i = {}, 2
    while i < len(toks):
        key = toks[i]
        if key not in arity:
            raise ValueError(f"unknown camera key {key!r}")
        if key in cam:
            raise ValueError(f"duplicate camera key {key!r}")
        vals = toks[i + 1:i + 1 + arity[key]]
        if len(vals) != arity[key]:
            raise ValueError(f"camera key {key!r} needs {arity[key]} numbers")
        cam[key] = tuple(float(v) for v in vals)  # raises ValueError on a non-number
        i += 1 + arity[key]
    missing = set(arity) - set(cam)
    if missing:
        raise ValueError(f"camera keys missing: {sorted(missing)}")
    return cam


def parse_obj(path):
    verts, faces, mtllibs = [], [], []
    obj = grp = mat = None
    with open(path) as fh:
        lines = fh.read().splitlines()
    for ln, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        t = line.split()
        if t[0] == "v":
            verts.append(tuple(float(x) for x in t[1:4]))
        elif t[0] == "f":
            idx = []
            for tok in t[1:]:
                i = int(tok.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            faces.append({"obj": obj, "group": grp, "mat": mat, "idx": idx, "line": ln})
        elif t[0] == "o":
            obj = line[1:].strip()
        elif t[0] == "g":
            grp = line[1:].strip()
        elif t[0] == "usemtl":
            mat = line.split(None, 1)[1].strip()
        elif t[0] == "mtllib":
            mtllibs.append(line.split(None, 1)[1].strip())
        elif t[0] in ("vt", "vn", "s"):
            pass
        else:
            raise ValueError(f"{path}:{ln}: unexpected statement {t[0]!r}")
    return lines[0] if lines else "", verts, faces, mtllibs


def parse_mtl(path):
    mats, cur = {}, None
    with open(path) as fh:
        for raw in fh:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            t = line.split()
            if t[0] == "newmtl":
                cur = line.split(None, 1)[1].strip()
                mats[cur] = {}
            elif cur is not None:
                mats[cur][t[0]] = tuple(float(x) for x in t[1:]) if len(t) > 1 else ()
    return mats


# ---------------------------------------------------------------- per-scene expectations
INTERIOR = (278.0, 274.0, 280.0)
CORNELL_MEASURED = {
    "floor": [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)],
    "light": [(343, 548.8, 227), (343, 548.8, 332), (213, 548.8, 332), (213, 548.8, 227)],
    "back_wall": [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)],
    "red_wall": [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)],
    "green_wall": [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)],
}
CORNELL_TOPS = {
    "short_block": [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)],
    "tall_block": [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)],
}

SCENES = {
    "cornell": {
        "camera": {"eye": (278, 273, -800), "target": (278, 273, 0), "up": (0, 1, 0), "fov": (39.3077,)},
        "materials": {"white": ((0.73,) * 3, (0, 0, 0)), "red": ((0.63, 0.065, 0.05), (0, 0, 0)),
                      "green": ((0.14, 0.45, 0.091), (0, 0, 0)), "light": ((0.78,) * 3, (17, 12, 4))},
        # object -> (material, number of faces)
        "objects": {"floor": ("white", 1), "ceiling": ("white", 4), "light": ("light", 1),
                    "back_wall": ("white", 1), "red_wall": ("red", 1), "green_wall": ("green", 1),
                    "short_block": ("white", 5), "tall_block": ("white", 5)},
    },
    "box": {
        "camera": {"eye": (0.5, 0.5, 0.05), "target": (0.5, 0.5, 1), "up": (0, 1, 0), "fov": (90,)},
        "materials": {"grey": ((0.5,) * 3, (0, 0, 0)), "lamp": ((0.5,) * 3, (1, 1, 1))},
        "objects": {"floor": ("grey", 1), "ceiling": ("lamp", 1), "wall_x0": ("grey", 1),
                    "wall_x1": ("grey", 1), "wall_z0": ("grey", 1), "wall_z1": ("grey", 1)},
    },
    "shadow": {
        "camera": {"eye": (0, 3, 3), "target": (0, 0, 0), "up": (0, 1, 0), "fov": (50,)},
        "materials": {"grey": ((0.5,) * 3, (0, 0, 0)), "light": ((0, 0, 0), (10, 10, 10))},
        "objects": {"floor": ("grey", 1), "light": ("light", 1), "occluder": ("grey", 1)},
    },
}


def expected_direction(scene, face, ps, all_ps_of_obj):
    """Return (description, predicate(unit_normal, centroid) -> bool)."""
    o = face["obj"]
    if scene == "cornell":
        if o == "light":
            return "-y", lambda n, c: n[1] < -0.999999
        if o in CORNELL_TOPS:
            if all(abs(p[1] - ps[0][1]) < 1e-9 and p[1] > 0 for p in ps):
                return "+y (block top)", lambda n, c: n[1] > 0.999999
            centre = mean(all_ps_of_obj)
            return "away from block centre " + fv(centre), \
                lambda n, c: dot(n, sub(c, centre)) > 0 and abs(n[1]) < 1e-6
        return "towards interior " + fv(INTERIOR), lambda n, c: dot(n, sub(INTERIOR, c)) > 0
    if scene == "box":
        return "towards (0.5,0.5,0.5)", lambda n, c: dot(n, sub((0.5, 0.5, 0.5), c)) > 0
    if scene == "shadow":
        if o == "floor":
            return "+y", lambda n, c: n[1] > 0.999999
        return "-y", lambda n, c: n[1] < -0.999999
    raise KeyError(scene)


# ---------------------------------------------------------------- checks
def check_scene(scene, spec):
    obj_path = os.path.join(HERE, scene, scene + ".obj")
    print(f"== {os.path.relpath(obj_path, os.path.dirname(HERE))}")
    if not os.path.isfile(obj_path):
        fail(f"{obj_path} missing")
        return
    first, verts, faces, mtllibs = parse_obj(obj_path)

    # camera
    try:
        cam = parse_camera(first)
    except ValueError as e:
        fail(f"{scene}: camera comment: {e}: {first!r}")
        cam = None
    if cam:
        for k, v in spec["camera"].items():
            if not close(cam[k], v, 1e-9):
                fail(f"{scene}: camera {k} {cam[k]} != expected {v}")
        d = sub(cam["target"], cam["eye"])
        if norm(d) == 0 or norm(cross(d, cam["up"])) < 1e-6 * norm(d) * norm(cam["up"]):
            fail(f"{scene}: camera view direction is zero or parallel to up")
        if not 0 < cam["fov"][0] < 180:
            fail(f"{scene}: camera fov out of (0,180)")
        print(f"  camera: eye {cam['eye']} target {cam['target']} up {cam['up']} fov {cam['fov'][0]}")
        if scene == "cornell" and abs(cam["fov"][0] - math.degrees(2 * math.atan(12.5 / 35))) > 1e-4:
            fail("cornell: fov != 2*atan(12.5/35)")
        if scene == "box" and not all(0 < x < 1 for x in cam["eye"]):
            fail(f"box: eye {cam['eye']} not strictly inside the cube")

    # materials
    if mtllibs != [scene + ".mtl"]:
        fail(f"{scene}: mtllib {mtllibs} != ['{scene}.mtl']")
    mtl_path = os.path.join(HERE, scene, scene + ".mtl")
    mats = parse_mtl(mtl_path) if os.path.isfile(mtl_path) else {}
    if not mats:
        fail(f"{scene}: {mtl_path} missing or empty")
    for name, (kd, ke) in spec["materials"].items():
        m = mats.get(name)
        if m is None:
            fail(f"{scene}: material {name!r} not defined")
            continue
        if not close(m.get("Kd", ()), kd) or len(m.get("Kd", ())) != 3:
            fail(f"{scene}: {name} Kd {m.get('Kd')} != {kd}")
        if not close(m.get("Ke", ()), ke) or len(m.get("Ke", ())) != 3:
            fail(f"{scene}: {name} Ke {m.get('Ke')} != {ke}")
    for name, m in mats.items():
        if name not in spec["materials"]:
            fail(f"{scene}: unexpected material {name!r}")
        if not all(0 <= x < 1 for x in m.get("Kd", (1,))):
            fail(f"{scene}: {name} Kd not in [0,1)")
        if not all(x >= 0 for x in m.get("Ke", (-1,))):
            fail(f"{scene}: {name} Ke missing or negative")

    # objects: names, groups, materials, face counts
    counts = {}
    for f in faces:
        counts[f["obj"]] = counts.get(f["obj"], 0) + 1
        if f["group"] != f["obj"]:
            fail(f"{scene}: line {f['line']}: group {f['group']!r} != object {f['obj']!r}")
        exp = spec["objects"].get(f["obj"])
        if exp and f["mat"] != exp[0]:
            fail(f"{scene}: {f['obj']} uses material {f['mat']!r}, expected {exp[0]!r}")
        if f["mat"] not in mats:
            fail(f"{scene}: line {f['line']}: usemtl {f['mat']!r} not defined in {scene}.mtl")
    if {k: v[1] for k, v in spec["objects"].items()} != counts:
        fail(f"{scene}: objects/face counts {counts} != expected "
             f"{ {k: v[1] for k, v in spec['objects'].items()} }")

    # per polygon
    obj_points = {}
    for f in faces:
        obj_points.setdefault(f["obj"], set()).update(verts[i] for i in f["idx"])
    total_area = 0.0
    for k, f in enumerate(faces):
        idx = f["idx"]
        ps = [verts[i] for i in idx]
        tag = f"{scene}:{f['obj']}[{k}]"
        if len(ps) != 4:
            fail(f"{tag}: {len(ps)} vertices, expected a quad")
        if len(set(idx)) != len(idx) or len(set(ps)) != len(ps):
            fail(f"{tag}: repeated vertex")
        a = newell(ps)
        area = norm(a)
        if area <= 0:
            fail(f"{tag}: zero area")
            continue
        n = scale(a, 1 / area)
        c = mean(ps)
        diam = max(norm(sub(p, q)) for p in ps for q in ps)
        dev = max(abs(dot(sub(p, c), n)) for p in ps)
        convex = all(dot(cross(sub(ps[(i + 1) % len(ps)], ps[i]),
                               sub(ps[(i + 2) % len(ps)], ps[(i + 1) % len(ps)])), n) > 0
                     for i in range(len(ps)))
        desc, ok_dir = expected_direction(scene, f, ps, sorted(obj_points[f["obj"]]))
        status = "OK"
        if not ok_dir(n, c):
            fail(f"{tag}: normal {fv(n)} does not point {desc}")
            status = "BAD-ORIENTATION"
        known = PLANARITY_KNOWN.get((scene, f["obj"]))
        if dev / diam >= PLANARITY_REL_TOL:
            if known is not None and dev <= known:
                status += " (KNOWN non-planar: measured data)"
            else:
                fail(f"{tag}: non-planar, max deviation {dev:.4g} = {dev / diam:.3g} of size {diam:.4g}")
                status = "NON-PLANAR"
        if not convex:
            fail(f"{tag}: not a convex polygon")
            status = "NOT-CONVEX"
        total_area += area
        print(f"  {tag:<24} n={fv(n)} area={area:<12.6g} planarity={dev / diam:.2e} expect {desc:<40} {status}")
    print(f"  total area {total_area:.6g}, {len(faces)} faces, {len(verts)} vertices")

    # scene-specific geometry
    if scene == "cornell":
        by_obj = {}
        for f in faces:
            by_obj.setdefault(f["obj"], []).append([verts[i] for i in f["idx"]])
        for name, want in CORNELL_MEASURED.items():
            got = by_obj.get(name, [[]])[0]
            # same cycle (any starting vertex), same direction
            if not any(all(close(got[(s + i) % 4], want[i]) for i in range(4)) for s in range(4)) \
                    or len(got) != 4:
                fail(f"cornell: {name} vertices {got} != measured {want} (up to rotation)")
        # The ceiling is the measured rectangle with the light's rectangle cut out, in 4 quads
        # wound like the measured ceiling: together with the light they tile it exactly.
        ceiling = by_obj.get("ceiling", [])
        want_area = 556 * 559.2 - 130 * 105
        got_area = sum(abs(p[0][0] - p[2][0]) * abs(p[0][2] - p[2][2]) for p in ceiling if len(p) == 4)
        if abs(got_area - want_area) > 1e-6 * want_area or not all(
                all(abs(q[1] - 548.8) < 1e-9 and 0 <= q[0] <= 556 and 0 <= q[2] <= 559.2 for q in p)
                for p in ceiling):
            fail(f"cornell: ceiling quads do not tile the measured ceiling minus the light ({got_area} != {want_area})")
        for name, top in CORNELL_TOPS.items():
            polys = by_obj.get(name, [])
            tops = [p for p in polys if all(abs(q[1] - top[0][1]) < 1e-9 for q in p)]
            if len(tops) != 1 or set(tops[0]) != set(map(tuple, map(lambda v: tuple(map(float, v)), top))):
                fail(f"cornell: {name} top != measured {top}")
            want_sides = set()
            for i in range(4):
                a, b = top[i], top[(i + 1) % 4]
                want_sides.add(frozenset([a, b, (a[0], 0, a[2]), (b[0], 0, b[2])]))
            got_sides = {frozenset(p) for p in polys if p not in tops}
            if got_sides != {frozenset(tuple(map(float, v)) for v in s) for s in want_sides}:
                fail(f"cornell: {name} sides are not the quads from consecutive top vertices to y=0")
        xs = [p[0] for p in by_obj.get("red_wall", [[(0, 0, 0)]])[0]]
        if not all(540 < x < 560 for x in xs):
            fail("cornell: red wall not at x~550")
        if not all(p[0] == 0 for p in by_obj.get("green_wall", [[(1, 0, 0)]])[0]):
            fail("cornell: green wall not at x=0")

    if scene == "box":
        # closed and consistently oriented: every directed edge appears once, its reverse exactly once
        edges = {}
        for f in faces:
            ps = [verts[i] for i in f["idx"]]
            for i in range(len(ps)):
                e = (ps[i], ps[(i + 1) % len(ps)])
                edges[e] = edges.get(e, 0) + 1
        bad = [e for e, cnt in edges.items() if cnt != 1 or edges.get((e[1], e[0])) != 1]
        if bad:
            fail(f"box: not closed/consistently oriented, {len(bad)} bad edges, e.g. {bad[0]}")
        else:
            print("  closed: every edge shared by exactly two faces in opposite directions")
        if any(not all(c in (0.0, 1.0) for c in v) for v in verts):
            fail("box: vertices are not the unit cube's corners")
        if abs(total_area - 6) > 1e-12:
            fail(f"box: total area {total_area} != 6")

    if scene == "shadow":
        want = {"floor": (0.0, 2.0), "light": (2.0, 0.5), "occluder": (1.0, 0.6)}  # (y, side)
        for f in faces:
            ps = [verts[i] for i in f["idx"]]
            y, side = want[f["obj"]]
            xs, zs = [p[0] for p in ps], [p[2] for p in ps]
            if not (all(abs(p[1] - y) < 1e-12 for p in ps)
                    and abs(min(xs) + side / 2) < 1e-12 and abs(max(xs) - side / 2) < 1e-12
                    and abs(min(zs) + side / 2) < 1e-12 and abs(max(zs) - side / 2) < 1e-12):
                fail(f"shadow: {f['obj']} is not a {side}x{side} square at y={y} centred on the y axis")


def main():
    for scene, spec in SCENES.items():
        check_scene(scene, spec)
    print()
    if failures:
        print(f"{len(failures)} check(s) FAILED")
        return 1
    print("all scene checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
