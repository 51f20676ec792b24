//! A polygon's outline as convex pieces, the unit the walk covers pixel centres with: the
//! coverage test of a convex piece is a few edge functions, where a concave outline would need
//! its triangles (more pieces, each covering fewer centres whole).

use crate::scene::triangulate;
use glam::Vec3;

/// The most corners a convex outline may have to be one piece (more: `convex_pieces`).
pub(super) const MAX_PIECE: usize = 16;

/// `outline` (counter-clockwise about `normal`, concave) as convex pieces of corner indices:
/// its triangles, merged across their shared edges while the union stays convex and within
/// [`MAX_PIECE`] corners (Hertel and Mehlhorn's greedy pass: at most four times the fewest
/// pieces). A merged voxel wall becomes a few rectangles instead of dozens of triangles, and
/// fewer pieces cover more pixel centres whole.
pub(super) fn convex_pieces(outline: &[Vec3], normal: Vec3) -> Vec<Vec<usize>> {
    let mut pieces: Vec<Option<Vec<usize>>> = triangulate(outline, normal)
        .into_iter()
        .map(|t| Some(t.to_vec()))
        .collect();
    let corners = |piece: &[usize]| piece.iter().map(|&k| outline[k]).collect::<Vec<_>>();
    // Directed edge → the piece that has it.
    let mut edges = std::collections::HashMap::new();
    for (i, piece) in pieces.iter().enumerate() {
        let piece = piece.as_ref().expect("every piece is live at first");
        for k in 0..piece.len() {
            edges.insert((piece[k], piece[(k + 1) % piece.len()]), i);
        }
    }
    for i in 0..pieces.len() {
        let mut k = 0;
        while let Some(piece) = &pieces[i] {
            if k >= piece.len() {
                break;
            }
            let (a, b) = (piece[k], piece[(k + 1) % piece.len()]);
            let Some(&j) = edges.get(&(b, a)) else {
                k += 1;
                continue;
            };
            let other = pieces[j].as_ref().expect("edges name live pieces");
            // This piece from b round to a, then the other's corners after a up to b.
            let at_b = (k + 1) % piece.len();
            let mut merged: Vec<usize> = (0..piece.len())
                .map(|m| piece[(at_b + m) % piece.len()])
                .collect();
            let at_a = other.iter().position(|&c| c == a).expect("the shared edge");
            merged.extend((1..other.len() - 1).map(|m| other[(at_a + m) % other.len()]));
            if j == i || merged.len() > MAX_PIECE || !convex(&corners(&merged), normal) {
                k += 1;
                continue;
            }
            let other = pieces[j].take().expect("live");
            for m in 0..other.len() {
                edges.remove(&(other[m], other[(m + 1) % other.len()]));
            }
            for m in 0..merged.len() {
                edges.insert((merged[m], merged[(m + 1) % merged.len()]), i);
            }
            edges.remove(&(a, b));
            pieces[i] = Some(merged);
            k = 0;
        }
    }
    pieces.into_iter().flatten().collect()
}

/// `outline` without repeated corners and spikes (a corner whose two neighbours coincide: an
/// edge walked out and back, as a plate's outline has where a member filled a notch). Drawn, a
/// spike is a sliver of no area; as a piece's edges it would squeeze the piece to a line.
pub(super) fn without_spikes(outline: &[Vec3]) -> Vec<Vec3> {
    let mut corners: Vec<Vec3> = outline.to_vec();
    loop {
        let n = corners.len();
        if n < 3 {
            return corners;
        }
        let repeated = (0..n).find(|&i| corners[i] == corners[(i + 1) % n]);
        let spike = || (0..n).find(|&i| corners[(i + n - 1) % n] == corners[(i + 1) % n]);
        match repeated.or_else(spike) {
            Some(i) => {
                corners.remove(i);
            }
            None => return corners,
        }
    }
}

/// Whether `outline` (counter-clockwise about `normal`) is convex: no corner turns the other way.
pub(super) fn convex(outline: &[Vec3], normal: Vec3) -> bool {
    let n = outline.len();
    (0..n).all(|i| {
        let (a, b, c) = (outline[i], outline[(i + 1) % n], outline[(i + 2) % n]);
        (b - a).cross(c - b).dot(normal) >= 0.0
    })
}
