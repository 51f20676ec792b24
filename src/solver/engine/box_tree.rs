//! A tree of axis-aligned boxes around polygons, for the walks that skip whole groups of them at
//! once: the hidden-polygon walk (`occlusion`) and the receivers' (`seen_receivers`).

use glam::Vec3;

/// A box of the tree, around the polygons `order[start..end]`; an inner node's children are
/// `children` and `children + 1`, a leaf has `children` 0 (the root is no one's child).
#[derive(Clone, Copy, Debug)]
pub struct Node {
    pub lo: Vec3,
    pub hi: Vec3,
    pub children: u32,
    pub start: u32,
    pub end: u32,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.children == 0
    }
}

/// The tree: nodes root first, and the polygons in leaf order.
#[derive(Clone, Debug, Default)]
pub struct BoxTree {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
}

impl BoxTree {
    /// The tree around `polygons`, each in its box `boxes[p]` (lower, upper corner), split at
    /// the median of their centres along the widest axis down to leaves of at most `leaf`.
    /// Empty without polygons.
    pub fn new(boxes: &[(Vec3, Vec3)], mut polygons: Vec<u32>, leaf: usize) -> BoxTree {
        let mut tree = BoxTree {
            nodes: Vec::new(),
            order: Vec::with_capacity(polygons.len()),
        };
        if !polygons.is_empty() {
            tree.nodes.push(Node {
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                children: 0,
                start: 0,
                end: 0,
            });
            tree.build(0, boxes, &mut polygons, leaf.max(1));
        }
        tree
    }

    /// Make node `at` the box around `polygons` (which end up in `order`).
    fn build(&mut self, at: usize, boxes: &[(Vec3, Vec3)], polygons: &mut [u32], leaf: usize) {
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let (mut clo, mut chi) = (lo, hi);
        for &p in polygons.iter() {
            let (a, b) = boxes[p as usize];
            lo = lo.min(a);
            hi = hi.max(b);
            clo = clo.min(a + b);
            chi = chi.max(a + b);
        }
        let start = self.order.len() as u32;
        if polygons.len() <= leaf {
            self.order.extend_from_slice(polygons);
            self.nodes[at] = Node {
                lo,
                hi,
                children: 0,
                start,
                end: self.order.len() as u32,
            };
            return;
        }
        let axis = (chi - clo).max_position();
        let centre = |p: &u32| {
            let (a, b) = boxes[*p as usize];
            a[axis] + b[axis]
        };
        let half = polygons.len() / 2;
        polygons.select_nth_unstable_by(half, |a, b| centre(a).total_cmp(&centre(b)));
        let children = self.nodes.len();
        let empty = self.nodes[at];
        self.nodes.extend([empty, empty]);
        let (left, right) = polygons.split_at_mut(half);
        self.build(children, boxes, left, leaf);
        self.build(children + 1, boxes, right, leaf);
        self.nodes[at] = Node {
            lo,
            hi,
            children: children as u32,
            start,
            end: self.order.len() as u32,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_node_holds_the_boxes_of_its_range_and_its_children_split_it() {
        let boxes: Vec<(Vec3, Vec3)> = (0..37)
            .map(|i| {
                let c = Vec3::new((i * 7 % 11) as f32, (i * 3 % 5) as f32, i as f32 * 0.5);
                (c, c + Vec3::splat(0.25 + (i % 3) as f32))
            })
            .collect();
        let tree = BoxTree::new(&boxes, (0..37).collect(), 4);
        let mut sorted = tree.order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..37).collect::<Vec<_>>());
        for node in &tree.nodes {
            for &p in &tree.order[node.start as usize..node.end as usize] {
                let (a, b) = boxes[p as usize];
                assert!(node.lo.cmple(a).all() && b.cmple(node.hi).all());
            }
            if node.is_leaf() {
                assert!(node.end - node.start <= 4);
            } else {
                let (l, r) = (
                    tree.nodes[node.children as usize],
                    tree.nodes[node.children as usize + 1],
                );
                assert_eq!((l.start, l.end, r.end), (node.start, r.start, node.end));
            }
        }
        assert!(BoxTree::new(&boxes, Vec::new(), 4).nodes.is_empty());
    }
}
