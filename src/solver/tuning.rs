//! Every choice the solver makes for speed on Mesa's llvmpipe rather than for the paper, in one
//! place, each with its reason. A reader who wants the paper's algorithm can skip this file: with
//! [`Tuning::none`] the passes do exactly what section 3.2 describes, and every switch here
//! leaves the answer the same (bit for bit, or to float rounding where a switch says so; the
//! A/B tests are in `tests/reconstruction_cover.rs` and `tests/data_flow.rs`).
//!
//! Why llvmpipe needs its own tricks: it shades a block of 4×4 fragments at a time, runs both
//! sides of every branch for the whole block, and skips a block's shader only when an early depth
//! test rejects all of it; discards and branches save nothing. So the cost of a pass is the
//! number of blocks drawn and the number of instructions in the shader, whatever the fragments
//! decide.

/// Speed switches of the passes (see the module comment). `Default` is [`Tuning::llvmpipe`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Tuning {
    /// Reconstruction: draw only the lightmaps of polygons that can receive from this shooter
    /// (some of the polygon in front of the shooter and some of the shooter in front of it), plus
    /// the shooter's texels. The others would add exactly zero; their renderbuffer texels keep
    /// what the last `glCopyTexSubImage2D` copied into the textures, which is what the textures
    /// hold. Off: every patch of the atlas is drawn each pass, as the paper draws the scene.
    pub receivers_only: bool,
    /// Reconstruction: a first draw runs only the visibility test and writes depth where a texel
    /// is seen from the shooter; the form factors then run with depth test EQUAL, which llvmpipe
    /// applies before the shader, so it skips every 4×2 group with nothing visible (about half of
    /// them). The texels that receive nothing are not written, and keep the last copy's value
    /// (which is the texture's). Off: every drawn texel tests visibility in the one shader.
    pub marking_pass: bool,
    /// Reconstruction: the blocks whose polygons all have the whole shooter above their plane are
    /// drawn with a shader variant that does not clip the shooter to the receiver's tangent plane
    /// (a third fewer instructions). Same sums up to float rounding (within 1e-6).
    pub skip_needless_clipping: bool,
    /// Reconstruction: quadrilateral shooters (the rooms' usual case) use a variant compiled for
    /// four corners, whose loops unroll (llvmpipe fetches a uniform array indexed by a run-time
    /// count lane by lane). Bit-identical; about 5 % less time per pass.
    pub unroll_quads: bool,
}

impl Tuning {
    /// Everything on: the default for the accurate mode and the benchmarks.
    pub const fn llvmpipe() -> Self {
        Tuning {
            receivers_only: true,
            marking_pass: true,
            skip_needless_clipping: true,
            unroll_quads: true,
        }
    }

    /// Everything off: the passes as the paper describes them (`--mode paper`). Each
    /// reconstruction pass then clears its renderbuffers and recomputes every texel from the
    /// lightmap textures, so that everything the copies carry was computed in that pass.
    pub const fn none() -> Self {
        Tuning {
            receivers_only: false,
            marking_pass: false,
            skip_needless_clipping: false,
            unroll_quads: false,
        }
    }

    /// Whether a reconstruction pass writes every texel of the atlas (so that its renderbuffers
    /// can be cleared first): only when it neither leaves receivers out nor skips unmarked
    /// texels.
    pub fn writes_every_texel(&self) -> bool {
        !self.receivers_only && !self.marking_pass
    }
}

impl Default for Tuning {
    fn default() -> Self {
        Self::llvmpipe()
    }
}
