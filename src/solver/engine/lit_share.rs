//! What share of the patches the last shot lit, estimated from a fixed sample of them in the
//! unshot atlas read back after every shot: the signal that decides whether the next pass runs
//! the marking pass (`Tuning::marking_below`). A patch lit by a shot has its unshot radiance
//! changed by ΔL; one hidden from every shooter keeps it.

/// Sample every `STRIDE`-th patch texel: enough for a share to about a per cent on the rooms,
/// and cheap beside the readback itself. Odd, so that it does not follow the atlas's rows.
const STRIDE: usize = 13;

pub(crate) struct LitShare {
    /// Offsets of the sampled patch texels in an RGBA atlas.
    samples: Vec<usize>,
    /// Their unshot radiance at the last readback.
    before: Vec<[f32; 3]>,
    /// The share of them that changed at the last readback (0 before the first shot).
    share: f32,
    /// Reconstruction passes since the last readback (`passed`), and in the shot before it.
    passes: u32,
    passes_of_shot: u32,
}

impl LitShare {
    /// Sample the patch texels (alpha, the polygon ID + 1, not 0) of `unshot`, the atlas as
    /// initialised.
    pub(crate) fn new(unshot: &[f32]) -> Self {
        let samples: Vec<usize> = (unshot.chunks_exact(4).enumerate())
            .filter(|(_, t)| t[3] != 0.0)
            .map(|(i, _)| 4 * i)
            .step_by(STRIDE)
            .collect();
        let before = samples.iter().map(|&i| rgb(unshot, i)).collect();
        LitShare {
            samples,
            before,
            share: 0.0,
            passes: 0,
            passes_of_shot: 1,
        }
    }

    /// Take the readback after a shot: the share of the samples whose unshot radiance changed.
    pub(crate) fn observe(&mut self, unshot: &[f32]) {
        let mut changed = 0;
        for (&i, before) in self.samples.iter().zip(&mut self.before) {
            let now = rgb(unshot, i);
            changed += (now != *before) as usize;
            *before = now;
        }
        self.share = changed as f32 / self.samples.len().max(1) as f32;
        self.passes_of_shot = self.passes.max(1);
        self.passes = 0;
    }

    /// Count a reconstruction pass.
    pub(crate) fn passed(&mut self) {
        self.passes += 1;
    }

    /// The share of the sampled patches the last shot changed, 0 to 1, over its passes: the
    /// least share a pass of it lit on average (its passes may have lit the same patches or
    /// others). A shot of many small cells (the accurate mode's) lights much in all, little
    /// in each pass.
    pub(crate) fn per_pass(&self) -> f32 {
        self.share / self.passes_of_shot as f32
    }
}

fn rgb(atlas: &[f32], i: usize) -> [f32; 3] {
    [atlas[i], atlas[i + 1], atlas[i + 2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_the_sampled_patches_whose_unshot_radiance_changed() {
        // 26 patches (IDs 1 and 2) and 4 texels that are no patch: samples at patches 0 and 13.
        let mut atlas: Vec<f32> = (0..30)
            .flat_map(|i| {
                [
                    0.5,
                    0.5,
                    0.5,
                    if i < 26 { 1.0 + (i % 2) as f32 } else { 0.0 },
                ]
            })
            .collect();
        let mut lit = LitShare::new(&atlas);
        assert_eq!(lit.samples, vec![0, 4 * 13]);
        assert_eq!(lit.per_pass(), 0.0);
        atlas[4 * 13 + 1] += 0.25;
        lit.passed();
        lit.observe(&atlas);
        assert_eq!(lit.per_pass(), 0.5);
        // Over two passes: at least a quarter each.
        atlas[2] = 1.0;
        lit.passed();
        lit.passed();
        lit.observe(&atlas);
        assert_eq!(lit.per_pass(), 0.25);
        // Unchanged since: nothing lit.
        lit.observe(&atlas);
        assert_eq!(lit.per_pass(), 0.0);
        // A texel that is not sampled changes nothing.
        atlas[4] = 2.0;
        lit.observe(&atlas);
        assert_eq!(lit.per_pass(), 0.0);
    }
}
