//! Convex solids: OBJ objects whose polygons bound a convex volume, closed either by themselves
//! or by a polygon of another object that covers their opening (a book standing on a shelf has
//! no bottom: the shelf closes it). Seen from a point outside such a volume, a polygon of it
//! that faces away can never be the first thing a ray meets: a ray reaching it from behind is
//! inside the volume, so it entered earlier through a face that faces the point (or through the
//! cap, which is met first). The hemicube's visibility pass leaves such polygons out
//! (`Tuning::cull_solids`), and its item buffer stays the same; not the hemispherical
//! projection's, whose straight-drawn edges do not let the near faces cover the far ones
//! exactly.

use crate::geometry::{mean, Plane};
use crate::scene::Scene;
use glam::Vec3;
use std::collections::HashMap;

/// Most distinct face planes an object may have to be tested as a convex solid.
pub const MAX_SOLID_PLANES: usize = 4096;

/// The convex solids of a scene (see the module's note), and which polygons belong to each.
#[derive(Clone, Debug, Default)]
pub struct Solids {
    /// Per solid: the planes bounding it (its faces' and its cap's), normals outwards.
    pub planes: Vec<Vec<Plane>>,
    /// Per polygon: the solid it belongs to, if any.
    pub solid_of: Vec<Option<usize>>,
    /// Distances within this count as on a plane (float noise: 1e-5 of the scene's size).
    pub slack: f32,
}

impl Solids {
    /// Find the scene's convex solids.
    pub fn find(scene: &Scene) -> Solids {
        let slack = scene.plane_slack();
        let plane_of = |p: usize| scene.polygons[p].plane();
        let mut objects: HashMap<&str, Vec<usize>> = HashMap::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            objects.entry(p.object.as_str()).or_default().push(i);
        }
        let mut names: Vec<&str> = objects.keys().copied().collect();
        names.sort_unstable();
        let mut solids = Solids {
            planes: Vec::new(),
            solid_of: vec![None; scene.polygons.len()],
            slack,
        };
        for name in names {
            let members = &objects[name];
            if members.len() < 3 {
                continue;
            }
            // The convexity test below costs distinct planes x distinct corners: a flat grid of
            // 40,000 tiles (one plane, counted 40,000 times against 160,000 corners) took 20 s.
            // Count each plane and corner once, and leave objects with more distinct planes
            // than MAX_SOLID_PLANES out (culling them is a speed trick, not needed).
            let mut distinct: HashMap<[i64; 4], ()> = HashMap::new();
            let mut planes: Vec<Plane> = Vec::new();
            for &p in members {
                let pl = plane_of(p);
                let n = pl.normal * 1e5;
                let key = [
                    n.x.round() as i64,
                    n.y.round() as i64,
                    n.z.round() as i64,
                    (pl.offset / slack.max(f32::MIN_POSITIVE)).round() as i64,
                ];
                if distinct.insert(key, ()).is_none() {
                    planes.push(pl);
                }
            }
            if planes.len() > MAX_SOLID_PLANES {
                continue;
            }
            let mut seen = std::collections::HashSet::new();
            let corners: Vec<Vec3> = members
                .iter()
                .flat_map(|&p| scene.polygons[p].vertices.iter().copied())
                .filter(|v| seen.insert(v.to_array().map(f32::to_bits)))
                .collect();
            // Convex: every corner on or behind every face's plane.
            if !planes
                .iter()
                .all(|pl| corners.iter().all(|&c| pl.distance(c) <= slack))
            {
                continue;
            }
            // Closed: each edge run both ways (once per face that shares it). Edges run one way
            // only are the opening, which another object's polygon must cover.
            let key = |v: Vec3| v.to_array().map(f32::to_bits);
            let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
            for &p in members {
                let v = &scene.polygons[p].vertices;
                for k in 0..v.len() {
                    let (a, b) = (key(v[k]), key(v[(k + 1) % v.len()]));
                    *edges.entry((a, b)).or_default() += 1;
                    *edges.entry((b, a)).or_default() -= 1;
                }
            }
            let open: Vec<Vec3> = edges
                .iter()
                .filter(|(_, &n)| n > 0)
                .map(|((a, _), _)| Vec3::from_array(a.map(f32::from_bits)))
                .collect();
            if edges.values().any(|&n| n.abs() > 1) {
                continue; // more than two faces at an edge: not a simple closed surface
            }
            if !open.is_empty() {
                let inside = mean(&corners);
                let cap = (0..scene.polygons.len())
                    .filter(|&p| scene.polygons[p].object != name)
                    .find(|&p| covers(scene, p, &open, inside, slack));
                match cap {
                    // Seen from the volume, the cap's plane faces outwards the other way.
                    Some(p) => planes.push(plane_of(p).flipped()),
                    None => continue,
                }
            }
            let id = solids.planes.len();
            solids.planes.push(planes);
            for &p in members {
                solids.solid_of[p] = Some(id);
            }
        }
        solids
    }

    /// Whether `point` lies outside solid `s` by more than `margin` in front of one of its planes
    /// (so at least that far from all of it): only then do its far sides hide nothing. The
    /// margin keeps the solid clear of a near plane that would clip its near faces away.
    pub fn clear_of(&self, s: usize, point: Vec3, margin: f32) -> bool {
        let margin = margin.max(self.slack);
        self.planes[s].iter().any(|pl| pl.distance(point) > margin)
    }

    /// How many solids were found.
    pub fn count(&self) -> usize {
        self.planes.len()
    }
}

/// Whether polygon `p` (convex) covers every point of `open` (on its plane, within its outline)
/// and faces `inside`, the volume it would close.
fn covers(scene: &Scene, p: usize, open: &[Vec3], inside: Vec3, slack: f32) -> bool {
    let q = &scene.polygons[p];
    let plane = q.plane();
    if plane.distance(inside) <= slack {
        return false;
    }
    if open.iter().any(|&o| plane.distance(o).abs() > slack) {
        return false;
    }
    let n = q.vertices.len();
    open.iter().all(|&o| {
        (0..n).all(|k| {
            let (a, b) = (q.vertices[k], q.vertices[(k + 1) % n]);
            // Left of (or on) each counter-clockwise edge, seen from the front.
            let edge = (b - a).cross(o - a).dot(q.normal);
            edge >= -slack * (b - a).length()
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::test_scene as scene;
    use crate::scene::Polygon;

    fn quad(v: [[f32; 3]; 4], object: &str) -> Polygon {
        Polygon::new(v.map(Vec3::from_array).to_vec(), 0, object.into()).unwrap()
    }

    /// A unit box's faces, counter-clockwise from outside, optionally without its bottom.
    fn cube(o: [f32; 3], name: &str, bottom: bool) -> Vec<Polygon> {
        let p = |x: f32, y: f32, z: f32| [o[0] + x, o[1] + y, o[2] + z];
        let mut faces = vec![
            quad(
                [p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)],
                name,
            ), // +y
            quad(
                [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)],
                name,
            ), // +z
            quad(
                [p(1., 0., 0.), p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.)],
                name,
            ), // -z
            quad(
                [p(1., 0., 1.), p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.)],
                name,
            ), // +x
            quad(
                [p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)],
                name,
            ), // -x
        ];
        if bottom {
            faces.push(quad(
                [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)],
                name,
            ));
        }
        faces
    }

    #[test]
    fn a_closed_box_is_a_solid() {
        let s = Solids::find(&scene(cube([0.0; 3], "box", true)));
        assert_eq!(s.count(), 1);
        assert!(s.solid_of.iter().all(|&x| x == Some(0)));
        assert!(s.clear_of(0, Vec3::new(0.5, 2.0, 0.5), 0.0));
        assert!(!s.clear_of(0, Vec3::new(0.5, 2.0, 0.5), 1.5));
        assert!(!s.clear_of(0, Vec3::splat(0.5), 0.0));
    }

    #[test]
    fn an_open_box_is_a_solid_only_where_a_floor_closes_it() {
        let floor = |y: f32| {
            quad(
                [[-1., y, -1.], [-1., y, 3.], [3., y, 3.], [3., y, -1.]],
                "floor",
            )
        };
        let mut on_floor = cube([0.0; 3], "book", false);
        on_floor.push(floor(0.0));
        let s = Solids::find(&scene(on_floor));
        assert_eq!(s.count(), 1);
        // A point on the floor under the book is inside: nothing may be left out from there.
        assert!(!s.clear_of(0, Vec3::new(0.5, 0.0, 0.5), 0.0));
        assert!(s.clear_of(0, Vec3::new(2.5, 0.0, 2.5), 0.0));

        let mut lifted = cube([0.0; 3], "book", false);
        lifted.push(floor(-0.5));
        assert_eq!(Solids::find(&scene(lifted)).count(), 0);
        assert_eq!(
            Solids::find(&scene(cube([0.0; 3], "book", false))).count(),
            0
        );
    }

    #[test]
    fn a_concave_object_is_not_a_solid() {
        let mut faces = cube([0.0; 3], "l", true);
        faces.extend(cube([1.0, 0.0, 0.0], "l", true));
        faces.extend(cube([0.0, 0.0, 1.0], "l", true));
        assert_eq!(Solids::find(&scene(faces)).count(), 0);
    }
}
