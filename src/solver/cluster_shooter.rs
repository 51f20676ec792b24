//! The one shooter of a cluster of polygons, coplanar (`clusters.rs`) or not
//! (`face_clusters.rs`): a flat emitter of the members' summed energy.

use super::{Shooter, MAX_CORNERS};
use crate::scene::Scene;
use glam::Vec3;

/// The one shooter of cluster members `members` (each polygon with its unshot energy, Σ L·A RGB,
/// of one sign: every channel ≥ 0, or every one ≤ 0; not all zero), owning no texels (the solver
/// clears the members' own): it shoots their summed energy from the centroid of the member
/// nearest their power-weighted centre (raised along a face cluster's `normal` to the highest
/// member corner), along `normal` (a face cluster's mean normal, `face_clusters.rs`) or else
/// that member's normal, with the rectangle around the members projected on the plane through
/// that point as its outline (a flat emitter of their energy: by
/// reciprocity it sends no more than it carries). `patches[p]` is polygon p's patch count.
/// `None` when nothing is left to shoot. Its item-buffer side (`hemi_res`) and turn are the
/// caller's to set (0 here).
pub fn cluster_shooter(
    scene: &Scene,
    patches: &[u32],
    members: &[(usize, Vec3)],
    normal: Option<Vec3>,
) -> Option<Shooter> {
    let weight = |e: Vec3| (e.x + e.y + e.z).abs() as f64;
    let total: f64 = members.iter().map(|&(_, e)| weight(e)).sum();
    if members.is_empty() || total <= 0.0 {
        return None;
    }
    let centre = members.iter().fold(glam::DVec3::ZERO, |sum, &(p, e)| {
        sum + scene.polygons[p].centroid.as_dvec3() * weight(e)
    }) / total;
    let centre = centre.as_vec3();
    let lead = members.iter().map(|&(p, _)| p).min_by(|&a, &b| {
        let d = |p: usize| scene.polygons[p].centroid.distance_squared(centre);
        d(a).total_cmp(&d(b)).then(a.cmp(&b))
    })?;
    let polygon = &scene.polygons[lead];
    let given = normal;
    let normal = normal.unwrap_or(polygon.normal);
    // (u, v, normal) is right-handed, so the rectangle's corners in (u, v) order run
    // counter-clockwise seen from the front.
    let (u, v) = normal.any_orthonormal_pair();
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for &(p, _) in members {
        for &x in &scene.polygons[p].vertices {
            let at = glam::Vec2::new(x.dot(u), x.dot(v));
            lo = lo.min(at);
            hi = hi.max(at);
        }
    }
    // A face cluster's point is raised along its mean normal to its highest member corner: from
    // the lead's centroid, a convex cluster's light towards receivers between the lead's plane
    // and the mean plane was blocked by the cluster itself (the living room's small shots
    // delivered 2 points less of what they carried); above every member nothing of it is.
    let lift = (given.is_some() && members.len() > 1).then(|| {
        let height = |p: usize| scene.polygons[p].vertices.iter();
        (members.iter().flat_map(|&(p, _)| height(p)))
            .map(|&x| (x - polygon.centroid).dot(normal))
            .fold(0f32, f32::max)
    });
    let position = polygon.centroid + normal * lift.unwrap_or(0.0);
    let plane = normal * normal.dot(position);
    let mut corners = [Vec3::ZERO; MAX_CORNERS];
    for (c, (a, b)) in
        corners
            .iter_mut()
            .zip([(lo.x, lo.y), (hi.x, lo.y), (hi.x, hi.y), (lo.x, hi.y)])
    {
        *c = plane + u * a + v * b;
    }
    let area = (hi.x - lo.x) * (hi.y - lo.y);
    // Slivers in a line along the normal's plane would spread the energy over no area.
    if area.is_nan() || area <= 0.0 {
        return None;
    }
    let energy = members.iter().fold(Vec3::ZERO, |sum, &(_, e)| sum + e);
    Some(Shooter {
        polygon: lead,
        texels: [0; 4],
        patches: members.iter().map(|&(p, _)| patches[p]).sum(),
        position,
        normal,
        energy,
        corners,
        corner_count: 4,
        area,
        remainder: Vec3::ZERO,
        hemi_res: 0,
        turn: 0.0,
        parts: Default::default(),
    })
}
