//! Diagnostics of face-cluster shots (not a test).
//! `fc_probe regions SCENE.obj A.exr [B.exr ...] REF.exr`: per material, incident-power-like
//! sums (Σ L·texel area over the material's patches) of each lightmap against the reference.
//! `fc_probe shots SCENE.obj N [MATERIAL]`: N sampled root face clusters (of MATERIAL's polygons
//! if given), each shot with unit radiance (E_i = A_i) in several ways, exact visibility (CPU):
//! S0 members alone (no fc); S1 members alone along the mean normal (direction error only);
//! S2 one point unlifted, rectangle; S3 the solver's shooter (lifted); S4 S3 with the rectangle
//! shrunk to |Σ A n|. Prints the fraction of Σ E received on the cluster's members, on other
//! polygons of the lead's material within 2 cell widths, and elsewhere.
use glam::Vec3;
use gpu_radiosity::patches::PatchLayout;
use gpu_radiosity::pipeline;
use gpu_radiosity::scene::bvh::Bvh;
use gpu_radiosity::scene::Scene;
use gpu_radiosity::solver::clusters::cluster_shooter;
use gpu_radiosity::solver::cpu::reconstruction::{self, delta, Receiver};
use gpu_radiosity::solver::face_clusters::{FaceClusters, FLAT};
use gpu_radiosity::solver::{FormFactorKind, Shooter, MAX_CORNERS};
use rayon::prelude::*;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (scene, _) = pipeline::load_scene(Some(Path::new(&args[2]))).unwrap();
    let layout = pipeline::lay_out(&scene, None, None).unwrap();
    match args[1].as_str() {
        "regions" => regions(&scene, &layout, &args[3..]),
        "worst" => worst(
            &scene,
            &layout,
            &args[3],
            &args[4],
            args[5].parse().unwrap(),
        ),
        "shots" => shots(&scene, &layout, args[3].parse().unwrap(), args.get(4), None),
        "of" => {
            let ps: Vec<usize> = args[3..].iter().map(|a| a.parse().unwrap()).collect();
            shots(&scene, &layout, usize::MAX, None, Some(ps))
        }
        _ => panic!("regions or shots"),
    }
}

fn regions(scene: &Scene, layout: &PatchLayout, files: &[String]) {
    let w = layout.atlas_width as usize;
    let h = layout.atlas_height as usize;
    let maps: Vec<Vec<f32>> = files
        .iter()
        .map(|f| {
            let i = image::open(f).unwrap().into_rgba32f();
            assert_eq!((i.width() as usize, i.height() as usize), (w, h));
            i.into_raw()
        })
        .collect();
    let nm = scene.materials.len();
    // per material: [file] (Σ L·a, Σ |L - Lref|·a), texels, area
    let mut sums = vec![vec![(0f64, 0f64); files.len()]; nm];
    let mut texels = vec![0usize; nm];
    let mut area = vec![0f64; nm];
    let r = maps.len() - 1;
    for (t, &owner) in layout.owner.iter().enumerate() {
        if owner == 0 {
            continue;
        }
        let p = owner as usize - 1;
        let m = scene.polygons[p].material;
        let a = if std::env::var("TEXEL").is_ok() {
            1.0
        } else {
            scene.polygons[p].area as f64 / layout.patches_per_polygon[p].max(1) as f64
        };
        let (x, y) = (t % w, t / w);
        let at = ((h - 1 - y) * w + x) * 4; // EXR rows top down
        let l = |k: usize| {
            let v = &maps[k][at..at + 3];
            (v[0] as f64 + v[1] as f64 + v[2] as f64) / 3.0
        };
        texels[m] += 1;
        area[m] += a;
        for (k, s) in sums[m].iter_mut().enumerate() {
            s.0 += l(k) * a;
            s.1 += (l(k) - l(r)).abs() * a;
        }
    }
    let total: Vec<f64> = (0..maps.len())
        .map(|k| sums.iter().map(|s| s[k].0).sum())
        .collect();
    println!("files: {files:?}");
    println!("all: Σ L·a {:?}", total);
    for k in 0..r {
        println!(
            "  file {k}: Σ L·a vs ref {:+.3} %, Σ |ΔL|·a / Σ Lref·a {:.3} %",
            100.0 * (total[k] / total[r] - 1.0),
            100.0 * sums.iter().map(|s| s[k].1).sum::<f64>() / total[r]
        );
    }
    let mut order: Vec<usize> = (0..nm).collect();
    order.sort_by(|&a, &b| sums[b][r].0.total_cmp(&sums[a][r].0));
    println!("material texels area | ref Σ L·a (share) | per file: Σ vs ref %, Σ|Δ|/Σref %, (Σ - ref) / total ref %");
    for m in order {
        if texels[m] == 0 {
            continue;
        }
        let mut line = format!(
            "{:22} {:6} {:8.2} | {:8.3} ({:5.2} %)",
            scene.materials[m].name,
            texels[m],
            area[m],
            sums[m][r].0,
            100.0 * sums[m][r].0 / total[r]
        );
        for k in 0..r {
            line += &format!(
                " | {:+7.2} {:6.2} {:+6.3}",
                100.0 * (sums[m][k].0 / sums[m][r].0 - 1.0),
                100.0 * sums[m][k].1 / sums[m][r].0,
                100.0 * (sums[m][k].0 - sums[m][r].0) / total[r]
            );
        }
        println!("{line}");
    }
}

fn outline_shooter(p: usize, position: Vec3, normal: Vec3, pts: &[Vec3], e: Vec3) -> Shooter {
    let mut corners = [Vec3::ZERO; MAX_CORNERS];
    let n = pts.len().min(MAX_CORNERS);
    corners[..n].copy_from_slice(&pts[..n]);
    // area by the shoelace in 3D about the normal
    let mut s = Vec3::ZERO;
    for i in 0..n {
        s += pts[i].cross(pts[(i + 1) % n]);
    }
    let area = 0.5 * s.dot(normal).abs();
    Shooter {
        polygon: p,
        texels: [0; 4],
        patches: 1,
        position,
        normal,
        energy: e,
        corners,
        corner_count: n,
        area,
        remainder: Vec3::ZERO,
        hemi_res: 0,
        turn: 0.0,
        parts: Default::default(),
    }
}

fn shots(
    scene: &Scene,
    layout: &PatchLayout,
    n: usize,
    material: Option<&String>,
    of: Option<Vec<usize>>,
) {
    let fc = FaceClusters::new(scene, layout, 8, 20f32.to_radians());
    let slack = scene.plane_slack();
    let bvh = Bvh::new(scene);
    // Unit reflectance: ΔL is then the incident radiance.
    let receivers: Vec<Receiver> = (reconstruction::receivers(scene, layout).into_iter())
        .map(|r| Receiver {
            rho: Vec3::ONE,
            ..r
        })
        .collect();
    let area: Vec<f64> = (receivers.iter())
        .map(|r| r.polygon as usize)
        .map(|p| scene.polygons[p].area as f64 / layout.patches_per_polygon[p].max(1) as f64)
        .collect();
    let want = material.map(|m| scene.materials.iter().position(|x| &x.name == m).unwrap());
    let mut roots: Vec<u32> = fc
        .roots()
        .filter(|&r| fc.nodes()[r as usize].cone > FLAT)
        .filter(|&r| want.is_none_or(|m| scene.polygons[fc.members(r)[0]].material == m))
        .collect();
    if let Some(ps) = &of {
        roots = Vec::new();
        for &p in ps {
            let mut at = fc.leaf_of(p).expect("a leaf");
            while let Some(up) = fc.nodes()[at as usize].parent {
                at = up;
            }
            roots.push(at);
        }
    }
    roots.sort_unstable();
    roots.dedup();
    println!(
        "{} roots (cone > FLAT){}; sampling {n}",
        roots.len(),
        material.map_or(String::new(), |m| format!(" of {m}"))
    );
    let step = (roots.len() / n.max(1)).max(1);
    let names = [
        "S0 alone",
        "S1 alone,mean n",
        "S2 rect unlifted",
        "S3 solver",
        "S4 S3 hull outline",
        "S5 S0, vis from point",
        "S6 S5 in front of the point's plane",
        "S7 S6 within 3 extents, S3 beyond",
    ];
    // totals over clusters: [variant][members, same material near, elsewhere]
    let mut total = [[0f64; 4]; 8];
    let mut moved = [0f64; 8];
    let mut all_e = 0f64;
    let mut k = 0;
    for &root in roots.iter().step_by(step).take(n) {
        let members = fc.members(root);
        let node = &fc.nodes()[root as usize];
        let mean = node.normal();
        let lead_mat = scene.polygons[members[0]].material;
        let e: Vec<(usize, Vec3)> = members
            .iter()
            .map(|&p| (p, Vec3::splat(scene.polygons[p].area)))
            .collect();
        let sum_e: f64 = e.iter().map(|&(_, x)| x.x as f64).sum();
        // convexity: the most any member's corner stands in front of another member's plane
        let mut front = 0f32;
        for &i in &members {
            let pi = &scene.polygons[i];
            for &j in &members {
                for &v in &scene.polygons[j].vertices {
                    front = front.max(pi.normal.dot(v - pi.centroid));
                }
            }
        }
        let extent = (node.hi - node.lo).max_element();
        let Some(s3) = cluster_shooter(scene, &layout.patches_per_polygon, &e, Some(mean)) else {
            continue;
        };
        let lead = &scene.polygons[s3.polygon];
        let s0: Vec<Shooter> = e
            .iter()
            .map(|&(p, x)| {
                let q = &scene.polygons[p];
                outline_shooter(p, q.centroid, q.normal, &q.vertices, x)
            })
            .collect();
        let s1: Vec<Shooter> = e
            .iter()
            .map(|&(p, x)| {
                let q = &scene.polygons[p];
                let proj: Vec<Vec3> = (q.vertices.iter())
                    .map(|&v| v - mean * mean.dot(v - q.centroid))
                    .collect();
                outline_shooter(p, q.centroid, mean, &proj, x)
            })
            .collect();
        // S2: the same rectangle on the plane through the lead's centroid
        let drop = (s3.position - lead.centroid).dot(mean);
        let mut s2 = s3;
        s2.position = lead.centroid;
        for c in &mut s2.corners[..4] {
            *c -= mean * drop;
        }
        let target = node.normal_sum.length();
        let (u, v) = mean.any_orthonormal_pair();
        let plane = mean * mean.dot(s3.position);
        let pts2: Vec<glam::Vec2> = (members.iter())
            .flat_map(|&p| scene.polygons[p].vertices.iter())
            .map(|&x| glam::Vec2::new(x.dot(u), x.dot(v)))
            .collect();
        let hull = convex_hull(pts2);
        let to3 = |q: glam::Vec2| plane + u * q.x + v * q.y;
        let hull_area = 0.5
            * (0..hull.len())
                .map(|i| hull[i].perp_dot(hull[(i + 1) % hull.len()]))
                .sum::<f32>();
        let mut s4 = s3;
        if hull.len() <= MAX_CORNERS && hull.len() >= 3 && hull_area > 1e-9 {
            for (c, &q) in s4.corners.iter_mut().zip(&hull) {
                *c = to3(q);
            }
            s4.corner_count = hull.len();
            s4.area = hull_area;
        }
        // oriented minimal rectangle from the hull's edges
        let mut best = (f32::MAX, [glam::Vec2::ZERO; 4]);
        for i in 0..hull.len() {
            let d = (hull[(i + 1) % hull.len()] - hull[i]).normalize_or_zero();
            if d == glam::Vec2::ZERO {
                continue;
            }
            let e = d.perp();
            let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
            for &q in &hull {
                let a = glam::Vec2::new(q.dot(d), q.dot(e));
                lo = lo.min(a);
                hi = hi.max(a);
            }
            let area = (hi - lo).x * (hi - lo).y;
            if area < best.0 {
                let c = |x: f32, y: f32| d * x + e * y;
                best = (
                    area,
                    [c(lo.x, lo.y), c(hi.x, lo.y), c(hi.x, hi.y), c(lo.x, hi.y)],
                );
            }
        }
        let mut s5 = s3;
        if best.0 < f32::MAX && best.0 > 0.0 {
            for (c, &q) in s5.corners.iter_mut().zip(&best.1) {
                *c = to3(q);
            }
            s5.area = best.0;
        }
        let _ = s5;
        // S5 now: members' own outlines and normals, visibility from the cluster's one point
        let s6: Vec<Shooter> = s0
            .iter()
            .map(|m| Shooter {
                position: s3.position,
                ..*m
            })
            .collect();
        let variants: [Vec<Shooter>; 6] = [s0, s1, vec![s2], vec![s3], vec![s4], s6];
        let mut deltas: Vec<Vec<f64>> = variants
            .iter()
            .map(|v| {
                receivers
                    .par_iter()
                    .map(|r| {
                        v.iter()
                            .map(|s| {
                                delta(r, s, &[], FormFactorKind::Polygon, slack, &bvh).x as f64
                            })
                            .sum::<f64>()
                    })
                    .collect()
            })
            .collect();
        let reach = (3.0 * extent).max(layout.patch_size);
        // S6: the item buffer's hemisphere sees nothing behind the point's plane; S7: the
        // members' outlines only near the cluster, its flat rectangle beyond.
        let front_of = |r: &Receiver| (r.centre - s3.position).dot(mean) > 0.0;
        let s6d: Vec<f64> = (receivers.iter().zip(&deltas[5]))
            .map(|(r, &d)| if front_of(r) { d } else { 0.0 })
            .collect();
        let s7d: Vec<f64> = (receivers.iter().enumerate())
            .map(|(i, r)| {
                if (r.centre - s3.position).length() < reach {
                    s6d[i]
                } else {
                    deltas[3][i]
                }
            })
            .collect();
        deltas.push(s6d);
        deltas.push(s7d);
        // clearance: nearest non-member polygon in front of the raised plane within the node's box
        // grown by its extent: distance from the shooter's point (approx: to its vertices/centroid)
        let top = s3.position.dot(mean);
        let grow = extent;
        let (glo, ghi) = (node.lo - grow, node.hi + grow);
        let mut clearance = f32::MAX;
        let mut crowded25 = false;
        let mut crowded_other = false;
        let (mut nf1, mut nf2) = (0f32, 0f32);
        for (q, poly) in scene.polygons.iter().enumerate() {
            if members.binary_search(&q).is_ok() {
                continue;
            }
            let (qlo, qhi) = (poly.vertices.iter())
                .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |b, &v| {
                    (b.0.min(v), b.1.max(v))
                });
            if qlo.cmpgt(ghi).any() || qhi.cmplt(glo).any() {
                continue;
            }
            // near-field factor: unoccluded form factor from the point (along the mean normal)
            // to polygons within k × extent of it (bounds distance)
            let gap = (qlo - s3.position)
                .max(s3.position - qhi)
                .max(Vec3::ZERO)
                .length();
            if gap < 2.0 * extent {
                let f = gpu_radiosity::solver::form_factor::polygon(
                    s3.position,
                    mean,
                    &poly.vertices,
                    poly.normal,
                    slack,
                );
                nf2 += f;
                if gap < extent {
                    nf1 += f;
                }
            }
            let pts = poly
                .vertices
                .iter()
                .copied()
                .chain(std::iter::once(poly.centroid));
            for v in pts {
                if v.dot(mean) > top + 1e-4 {
                    clearance = clearance.min((v - s3.position).length());
                }
            }
            let m25 = 0.25 * extent;
            let (l2, h2) = (qlo.max(node.lo - m25), qhi.min(node.hi + m25));
            if !l2.cmpgt(h2).any() {
                let far = Vec3::select(mean.cmpgt(Vec3::ZERO), h2, l2);
                if far.dot(mean) > top + 1e-3 * m25 {
                    crowded25 = true;
                    if poly.material != lead_mat {
                        crowded_other = true;
                    }
                }
            }
        }
        let mut line = format!(
            "#{k} root {root} mat {} members {} cone {:.1}° extent {:.3} front/extent {:.3} rect/|ΣAn| {:.2} hull/|ΣAn| {:.2} orect/|ΣAn| {:.2} ΣA/|ΣAn| {:.3} lift {:.4} clear {:.4} crowded25 {} other {} E {:.5} nf1 {:.4} nf2 {:.4}:",
            scene.materials[lead_mat].name,
            members.len(),
            node.cone.to_degrees(),
            extent,
            front / extent,
            s3.area / target,
            hull_area / target,
            best.0 / target,
            node.area / target,
            drop,
            clearance,
            crowded25 as u8,
            crowded_other as u8,
            sum_e,
            nf1,
            nf2
        );
        for (vi, d) in deltas.iter().enumerate() {
            let mut cat = [0f64; 4];
            let mut mv = 0f64;
            for (ri, r) in receivers.iter().enumerate() {
                let p = r.polygon as usize;
                let c = if members.binary_search(&p).is_ok() {
                    0
                } else if (scene.polygons[p].centroid - lead.centroid).length() >= reach {
                    3
                } else if scene.polygons[p].material == lead_mat {
                    1
                } else {
                    2
                };
                cat[c] += d[ri] * area[ri];
                mv += (d[ri] - deltas[0][ri]).abs() * area[ri];
            }
            for c in 0..4 {
                total[vi][c] += cat[c];
            }
            moved[vi] += mv;
            line += &format!(
                " [{}: {:.3} {:.3} {:.3} {:.3} mv {:.3}]",
                vi,
                cat[0] / sum_e,
                cat[1] / sum_e,
                cat[2] / sum_e,
                cat[3] / sum_e,
                mv / sum_e
            );
        }
        all_e += sum_e;
        println!("{line}");
        if of.is_some() {
            println!(
                "  point {:?} normal {:?} lead {} rect {:?}",
                s3.position,
                mean,
                s3.polygon,
                &s3.corners[..4]
            );
            for &p in &members {
                let q = &scene.polygons[p];
                println!(
                    "  member {p} n {:?} c {:?} area {:.4} h {:.4}",
                    q.normal,
                    q.centroid,
                    q.area,
                    (q.centroid - s3.position).dot(mean)
                );
            }
            let mut idx: Vec<usize> = (0..receivers.len()).collect();
            let d = |ri: usize, v: usize| deltas[v][ri] * area[ri] / sum_e;
            idx.sort_by(|&a, &b| {
                (d(b, 3) - d(b, 0))
                    .abs()
                    .total_cmp(&(d(a, 3) - d(a, 0)).abs())
            });
            for &ri in idx.iter().take(12) {
                let p = receivers[ri].polygon as usize;
                let q = &scene.polygons[p];
                println!(
                    "    recv poly {p} {} n {:?} c {:?} dist {:.4}: S0 {:.4} S1 {:.4} S2 {:.4} S3 {:.4} S4 {:.4}",
                    scene.materials[q.material].name, q.normal, receivers[ri].centre,
                    (receivers[ri].centre - s3.position).length(),
                    d(ri, 0), d(ri, 1), d(ri, 2), d(ri, 3), d(ri, 4)
                );
            }
        }
        k += 1;
    }
    println!("totals over {k} clusters, fractions of Σ E: members / near same material / near other / far / all ; moved vs S0");
    for (vi, t) in total.iter().enumerate() {
        println!(
            "{:20} {:.4} {:.4} {:.4} {:.4} {:.4} ; moved {:.4}",
            names[vi],
            t[0] / all_e,
            t[1] / all_e,
            t[2] / all_e,
            t[3] / all_e,
            (t[0] + t[1] + t[2] + t[3]) / all_e,
            moved[vi] / all_e
        );
    }
}

fn worst(scene: &Scene, layout: &PatchLayout, a: &str, r: &str, n: usize) {
    let w = layout.atlas_width as usize;
    let h = layout.atlas_height as usize;
    let load = |f: &str| image::open(f).unwrap().into_rgba32f().into_raw();
    let (ma, mr) = (load(a), load(r));
    let np = scene.polygons.len();
    let mut sa = vec![0f64; np];
    let mut sr = vec![0f64; np];
    for (t, &owner) in layout.owner.iter().enumerate() {
        if owner == 0 {
            continue;
        }
        let p = owner as usize - 1;
        let ar = scene.polygons[p].area as f64 / layout.patches_per_polygon[p].max(1) as f64;
        let (x, y) = (t % w, t / w);
        let at = ((h - 1 - y) * w + x) * 4;
        let l = |m: &Vec<f32>| (m[at] as f64 + m[at + 1] as f64 + m[at + 2] as f64) / 3.0;
        sa[p] += l(&ma) * ar;
        sr[p] += l(&mr) * ar;
    }
    let fc = FaceClusters::new(scene, layout, 8, 20f32.to_radians());
    let total: f64 = sr.iter().sum();
    let mut order: Vec<usize> = (0..np).collect();
    order.sort_by(|&x, &y| (sa[x] - sr[x]).total_cmp(&(sa[y] - sr[y])));
    let show = |p: usize| {
        let q = &scene.polygons[p];
        println!(
            "{p:6} {:18} {:28} patches {:3} area {:.4} c {:6.3} {:6.3} {:6.3} n {:5.2} {:5.2} {:5.2} leaf {:5} | {:+.3} % of total, {:+.1} % own",
            scene.materials[q.material].name,
            q.object.chars().take(28).collect::<String>(),
            layout.patches_per_polygon[p],
            q.area,
            q.centroid.x, q.centroid.y, q.centroid.z,
            q.normal.x, q.normal.y, q.normal.z,
            fc.leaf_of(p).is_some(),
            100.0 * (sa[p] - sr[p]) / total,
            100.0 * (sa[p] / sr[p] - 1.0)
        );
    };
    println!("largest losses:");
    for &p in order.iter().take(n) {
        show(p);
    }
    println!("largest gains:");
    for &p in order.iter().rev().take(n) {
        show(p);
    }
    let (lo, hi) = scene.bounds();
    println!("scene bounds {lo:?} {hi:?}, patch {}", layout.patch_size);
}

fn convex_hull(mut p: Vec<glam::Vec2>) -> Vec<glam::Vec2> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: glam::Vec2, a: glam::Vec2, b: glam::Vec2| (a - o).perp_dot(b - o);
    let mut h: Vec<glam::Vec2> = Vec::new();
    for &q in p.iter().chain(p.iter().rev().skip(1)) {
        while h.len() >= 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
            h.pop();
        }
        h.push(q);
    }
    h.pop();
    h
}
