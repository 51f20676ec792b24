//! Every choice the solver makes for speed on Mesa's llvmpipe rather than for the paper, in one
//! place, each with its reason. A reader who wants the paper's algorithm can skip this file: with
//! [`Tuning::none`] the passes do exactly what section 3.2 describes, and every switch here
//! leaves the answer the same (bit for bit, or to float rounding where a switch says so; the
//! A/B tests are in `tests/tuning.rs` and `tests/data_flow.rs`). The few that
//! change the item buffer beyond depth ties stay on in [`Tuning::none`], and say why; one,
//! [`Walk::ItemBuffersWritten`], writes the item buffer on the CPU instead of
//! drawing it, which moves pixel centres on edges (`tests/item_buffer.rs` counts them).
//!
//! Why llvmpipe needs its own tricks: it shades a block of 4×4 fragments at a time, runs both
//! sides of every branch for the whole block, and skips a block's shader only when an early depth
//! test rejects all of it; discards and branches save nothing. So the cost of a pass is the
//! number of blocks drawn and the number of instructions in the shader, whatever the fragments
//! decide.
//!
//! The speed options that do change the answer (overshooting, the item buffer chosen per shot,
//! several shooters per pass) are not here but in [`SolveOptions`](super::SolveOptions), off in
//! both modes, each measured against the accuracy guard (`validate::guard`, paper_notes "Beyond
//! the paper").

/// Speed switches of the passes (see the module comment). `Default` is [`Tuning::llvmpipe`];
/// `radiosity` chooses among [`Tuning::none`], [`Tuning::llvmpipe`] and [`Tuning::gpu`] by
/// renderer (`profile.rs`, `--tuning`). [`Tuning::check`] refuses switches that need others.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Tuning {
    /// Reconstruction: which polygons a pass draws by where they lie ([`ReceiverChoice`]; the
    /// walk's reach, `Walk::ReceiversFound`, overrides it).
    pub receivers: ReceiverChoice,
    /// Reconstruction: a first draw runs only the visibility test and writes depth where a texel
    /// is seen from the shooter; the form factors then run with depth test EQUAL, which llvmpipe
    /// applies before the shader, so it skips every 4×2 group with nothing visible (about half of
    /// them). The texels that receive nothing are not written, and keep the last copy's value
    /// (which is the texture's). Off: every drawn texel tests visibility in the one shader.
    pub marking_pass: bool,
    /// Reconstruction: run the marking pass only after a shot that lit fewer than this many per
    /// cent of the patches per pass (sampled from the unshot atlas read back after each shot,
    /// `engine::lit_share`); 100: before every pass. Marking pays where most texels are
    /// hidden from every shooter of the pass and costs a second draw where most are lit: on
    /// llvmpipe at four shooters per pass it saved about 10 % in the complex room, where a shot
    /// lights about a quarter of the patches, and cost about 6 % in the simple room, where it
    /// lights about half; at eight, where a pass lights more, the rule measured neutral on both
    /// (docs/perf-log.md). Same lightmaps either way, bit for bit.
    pub marking_below: u8,
    /// Reconstruction: quadrilateral shooters (the rooms' usual case) use a variant compiled for
    /// four corners, whose loops unroll (llvmpipe fetches a uniform array indexed by a run-time
    /// count lane by lane). Bit-identical; about 5 % less time per pass.
    pub unroll_quads: bool,
    /// Reconstruction: the solve's fixed choices (the form factor, the visibility kind, the
    /// robust test) compiled into the programs as constants rather than read from uniforms.
    /// llvmpipe runs both sides of a branch even when its condition is a uniform, so with
    /// uniforms every texel also computed the point factor and the hemispherical lookup for
    /// each shooter. Bit-identical; a few per cent less time per pass. The programs then serve
    /// only the options they were set up with (a pass run with others is refused).
    pub compile_choices: bool,
    /// Reconstruction: each square of whole 4×4 blocks is drawn as one point, which llvmpipe
    /// rasterises in one piece, block by block; off, as two triangles, whose shared diagonal
    /// makes llvmpipe shade the blocks it crosses twice. The pass draws triangles anyway where
    /// the driver's largest point is smaller than a block. Bit-identical.
    pub squares_as_points: bool,
    /// Visibility (hemicube): each face is drawn in a viewport `guard_band` times its size (an
    /// odd number; even ones round down, and the driver's largest viewport may cap it), centred
    /// on the face, with its frustum widened to match and the scissor keeping its own pixels.
    /// llvmpipe clips every triangle that reaches outside the viewport and sends the whole draw
    /// through its slow clipping path if one does; this way the triangles that cross the edge of
    /// a face (most of the walls) need no clipping. 1: no guard band. The same pixels up to float
    /// rounding of the vertices (the widened projection and the clipped edges round apart).
    pub guard_band: u32,
    /// Visibility: each view draws only the polygons whose bounding sphere reaches in front of
    /// the shooter and (hemicube) into the face's frustum, and not the shooter's own (which the
    /// shaders put beyond the far plane): on llvmpipe, transforming and clipping the whole scene
    /// five times cost more than filling the pixels. What is left out would be clipped away
    /// whole. Bit-identical.
    pub cull_views: bool,
    /// Visibility (hemicube): each face draws the polygons wholly inside its guarded frustum in
    /// a draw of their own, before the others: llvmpipe takes its fast path for a draw with
    /// nothing to clip. The draw order changes, which only depth ties can tell.
    pub split_unclipped: bool,
    /// Visibility (hemicube): the side faces fill only their upper halves, the part above the
    /// shooter's horizon that the reconstruction pass looks up (`front_half`). The pixels it
    /// reads are the same. Bit-identical.
    pub half_side_faces: bool,
    /// Visibility (hemicube with the robust test): coplanar neighbours outside the convex
    /// solids (floor planks, ceiling tiles) are merged into convex plates and drawn as one
    /// polygon under the first one's ID (`engine::plates`): a few large triangles cost
    /// llvmpipe much less to set up and bin than hundreds of small ones. The robust test reads
    /// only the shown polygon's plane, which a plate shares; the pixels that change are those
    /// whose centres lie on the joints merging removed (depth ties).
    pub plates: bool,
    /// Visibility (hemicube): the faces of convex solids turned away from a shooter outside them
    /// are left out (`engine::solids`): they can never be the first thing seen. The pixels
    /// that change are those whose centres lie on an edge where a near and a far face meet (a
    /// depth tie; 715 of 37.5 million on the simple room).
    pub cull_solids: bool,
    /// Visibility (hemicube): each view leaves out the polygons whose projected corners span no
    /// pixel centre across or none up and down (`engine::samples`): the item buffer has one
    /// sample per pixel, so they would make no fragment. Small shots draw 16² to 60² pixels
    /// per face, where a book's spine is a fraction of a pixel, and llvmpipe sets up and bins
    /// every triangle it is given on one thread. Bit-identical.
    pub cull_between_samples: bool,
    /// Visibility (hemicube): how far the hidden-polygon walk goes ([`Walk`]); each level needs
    /// the ones before it, so that a combination that cannot work cannot be written.
    pub walk: Walk,
    /// Visibility (with `cull_hidden`), in passes of one shooter: the hidden-polygon walk runs
    /// (leaving hidden polygons out, and with `walk_item_buffers` writing the item buffer)
    /// only for shots whose item buffer is at most this many pixels a side; larger ones are
    /// drawn with the other culling, as before the walk. The walk was tuned for the 16–45 px
    /// item buffers of Lost Empire's small shots; a 128² hemicube of Table 1's paper-faithful
    /// row measured 25 % cheaper drawn without it ([`WALK_UP_TO`]). 0: every side. Passes of
    /// several shooters (`VisibilityPass::with_slots`) walk every side: drawing Lost Empire's
    /// shots above 64² with the default's eight shooters a pass measured 6–9 % slower, the
    /// reach found by the walk being lost for the whole pass. A pass that mixes walked and drawn
    /// item buffers draws the whole atlas with the marking pass (`receivers_seen` is known for
    /// walked slots only). 0: no limit.
    pub walk_up_to: u32,
    /// Visibility: a glFlush at the end of the pass, so that llvmpipe rasterises the item
    /// buffer while the CPU picks the receivers (otherwise it waits until the reconstruction
    /// binds the item buffer). Bit-identical.
    pub flush_visibility: bool,
    /// Visibility: 32-bit float depth rather than 24-bit integers: llvmpipe tests it without
    /// converting (2 % of the pass's rasteriser instructions), and near-coplanar surfaces are
    /// told apart at least as well. On in [`Tuning::none`] too: 24-bit depth quantises
    /// differently, so the item buffer may change where surfaces lie close together (not only
    /// at depth ties; the two rooms' lightmaps came out bit-identical, which nothing promises
    /// for other scenes), and the paper's mode keeps the answers it has always given.
    pub float_depth: bool,
}

/// Which polygons a reconstruction pass draws, by where they lie (`Tuning::receivers`). Each
/// choice does what the one before does, and more: skipping the clipping needs the receivers'
/// flags that choosing them sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReceiverChoice {
    /// Every polygon with patches, each pass, as the paper draws the scene.
    Every,
    /// `receivers_only`: draw only the lightmaps of polygons that can receive from this shooter
    /// (some of the polygon in front of the shooter and some of the shooter in front of it), plus
    /// the shooter's texels. The others would add exactly zero; their renderbuffer texels keep what
    /// the last `glCopyTexSubImage2D` copied into the textures, which is what the textures hold.
    /// Off in [`Tuning::llvmpipe`] too: with the marking pass, a texel the shooter cannot see costs
    /// only its visibility test, while choosing the receivers costs the main thread time before
    /// each draw and breaks the cover into more, smaller squares; drawing everything measured about
    /// 5 % faster on both rooms (docs/perf-log.md). Kept, and tested, for a driver where shading
    /// costs more than choosing.
    InFront,
    /// `skip_needless_clipping`: as `InFront`, and the blocks whose polygons all have the whole
    /// shooter above their plane are drawn with a shader variant that does not clip the shooter to
    /// the receiver's tangent plane (a third fewer instructions). Same sums up to float rounding
    /// (within 1e-6). Needs the marking pass too, and is off in [`Tuning::llvmpipe`] with it:
    /// drawing everything with the clipping shader measured faster than splitting the cover between
    /// the two.
    InFrontUnclipped,
}

/// How far the hidden-polygon walk goes (hemicube only; `Tuning::walk`, `engine::occlusion`).
/// Each level does what the one before does, and more: writing the item buffer needs the walk,
/// and finding the receivers needs the item buffer written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Walk {
    /// No walk: the views are drawn with whatever the rest of the culling leaves out.
    Off,
    /// `cull_hidden`: the polygons hidden behind nearer ones are left out (`engine::occlusion`): a
    /// cube of directions around the shooter records how near a drawn triangle covers each cell
    /// wholly, and what lies behind that in every cell it reaches cannot show. A small shot on Lost
    /// Empire shows about 200 of the 17,000 polygons in front of it. Bit-identical.
    HiddenLeftOut,
    /// `walk_item_buffers`: as `HiddenLeftOut`, and the item buffer is not drawn but written. The
    /// hidden-polygon walk already projects every polygon it keeps onto the shot's own pixel
    /// centres; it also records there the ID of the nearest one (each piece clipped to the near
    /// plane as the GPU clips it, no margins), and the pass uploads those IDs into the item-buffer
    /// texture with glTexSubImage2D. llvmpipe is a CPU too: drawing cost the issuing thread Mesa's
    /// vertex, clipping and set-up path and the rasteriser threads their share, about 60 % of the
    /// CPU time of Lost Empire's visibility pass (docs/perf-log.md). The pixels differ from drawn
    /// ones only where a centre lies on an edge, which the GPU's fill rule gives to one side and
    /// the walk to the nearer (or first) polygon, and the answer moves as little as with the other
    /// depth-tie switches.
    ItemBuffersWritten,
    /// `walk_receivers`: as `ItemBuffersWritten`, and the reconstruction draws only the lightmaps
    /// of the polygons that the pass's item buffers let receive (`engine::seen_receivers`), plus
    /// the shooting texels. The walk knows each pixel's polygon on the CPU, so a box of patches can
    /// be left out when every pixel it can look up shows a polygon whose plane puts it behind, by
    /// the reconstruction shader's own robust test. On Lost Empire a small shot reaches a few
    /// hundred of 17,000 polygons, and the marking pass had run eight shooters' visibility tests on
    /// every patch of the atlas, two thirds of the pass (docs/perf-log.md). The receivers are a
    /// superset of those with a texel the shader finds visible: bit-identical.
    ReceiversFound,
    /// `few_shooter_programs`: as `ReceiversFound`, and (with several shooters a pass and the
    /// marking pass) the blocks that two to four of the pass's shooters may reach are shaded, for
    /// the sets of shooters that reach the most blocks, by a program compiled for just those
    /// shooters, rather than by the one for every shooter of the pass. llvmpipe runs each shooter's
    /// visibility test and form factor for every fragment whatever they decide, and on Lost Empire
    /// most such blocks are reached by two or three of the eight: the eight-shooter program spent
    /// most of its time on shooters that add exactly zero there (docs/perf-log.md). Those shooters
    /// add +0.0, so the sums are the same bit for bit.
    FewShooterPrograms,
}

impl Tuning {
    /// Everything that pays on llvmpipe (all but `receivers_only` and `skip_needless_clipping`):
    /// the default for the accurate mode and the benchmarks.
    pub const fn llvmpipe() -> Self {
        Tuning {
            receivers: ReceiverChoice::Every,
            marking_pass: true,
            marking_below: 40,
            unroll_quads: true,
            compile_choices: true,
            squares_as_points: true,
            guard_band: 7,
            cull_views: true,
            split_unclipped: true,
            half_side_faces: true,
            plates: true,
            cull_solids: true,
            cull_between_samples: true,
            walk: Walk::FewShooterPrograms,
            walk_up_to: WALK_UP_TO,
            flush_visibility: true,
            float_depth: true,
        }
    }

    /// Everything off that leaves the answer as it is (all but `float_depth`): the passes as
    /// the paper describes them (`--mode paper`). Each reconstruction pass then clears its
    /// renderbuffers and recomputes every texel from the lightmap textures, so that everything
    /// the copies carry was computed in that pass; each view of the visibility pass draws the
    /// whole scene in one draw.
    pub const fn none() -> Self {
        Tuning {
            receivers: ReceiverChoice::Every,
            marking_pass: false,
            marking_below: 100,
            unroll_quads: false,
            compile_choices: false,
            squares_as_points: false,
            guard_band: 1,
            cull_views: false,
            split_unclipped: false,
            half_side_faces: false,
            plates: false,
            cull_solids: false,
            cull_between_samples: false,
            walk: Walk::Off,
            walk_up_to: 0,
            flush_visibility: false,
            float_depth: true,
        }
    }

    /// The paper's data flow done fast on a GPU (`--tuning gpu`, and `auto` on any renderer but
    /// Mesa's software rasterisers): the GPU draws every item buffer whole and shades every
    /// receiver; the CPU walks, culls and selects nothing. On, because they pay on any
    /// rasteriser:
    /// - `compile_choices`: constants instead of uniform branches, fewer instructions and
    ///   registers on any shader compiler;
    /// - `unroll_quads`: a loop of constant count over four corners unrolls anywhere;
    /// - `half_side_faces`: half the side faces' pixels are never looked up, so never drawn;
    /// - `float_depth`: as in the paper's mode (precision, not speed).
    ///
    /// Off, because their gain rests on llvmpipe being a CPU: the walk and what needs it
    /// (`walk_item_buffers`, `walk_receivers`, `few_shooter_programs`, `cull_hidden`); the
    /// per-shot culling on the CPU (`cull_views`, `cull_solids`, `cull_between_samples`, which
    /// cost the CPU a pass over the scene and an index upload per shot, while a GPU transforms
    /// and clips the whole scene five times in well under a millisecond); `plates` (fewer
    /// triangles to set up and bin on one thread); `split_unclipped` and `guard_band` (GPUs clip
    /// in hardware, with their own guard band); `squares_as_points` (llvmpipe's shared-diagonal
    /// cost; a GPU's point sizes are capped and vary); `marking_pass` (a second draw and the lit
    /// share read on the CPU to skip llvmpipe's 4×4 blocks, while a GPU shades the whole atlas
    /// in microseconds); `receivers_only`, `skip_needless_clipping` (CPU selection before each
    /// draw); `flush_visibility` (nothing runs on the CPU between the two passes to overlap).
    pub const fn gpu() -> Self {
        Tuning {
            compile_choices: true,
            unroll_quads: true,
            half_side_faces: true,
            ..Self::none()
        }
    }

    /// This tuning with the views drawn instead of walked: the walk no further than
    /// [`Walk::HiddenLeftOut`] (no item buffer written, so no receivers found), at every side.
    pub fn drawing(self) -> Self {
        Tuning {
            walk: self.walk.min(Walk::HiddenLeftOut),
            walk_up_to: 0,
            ..self
        }
    }

    /// Whether a pass draws only the polygons that can receive by where they lie
    /// ([`ReceiverChoice::InFront`] or further).
    pub fn receivers_only(&self) -> bool {
        self.receivers >= ReceiverChoice::InFront
    }

    /// Whether blocks whose polygons have the whole shooter above them are shaded without
    /// clipping ([`ReceiverChoice::InFrontUnclipped`]; with the marking pass).
    pub fn skip_needless_clipping(&self) -> bool {
        self.receivers >= ReceiverChoice::InFrontUnclipped
    }

    /// Whether the walk leaves hidden polygons out ([`Walk::HiddenLeftOut`] or further).
    pub fn cull_hidden(&self) -> bool {
        self.walk >= Walk::HiddenLeftOut
    }

    /// Whether the walk writes the item buffers ([`Walk::ItemBuffersWritten`] or further).
    pub fn walk_item_buffers(&self) -> bool {
        self.walk >= Walk::ItemBuffersWritten
    }

    /// Whether the walk finds the receivers ([`Walk::ReceiversFound`] or further).
    pub fn walk_receivers(&self) -> bool {
        self.walk >= Walk::ReceiversFound
    }

    /// Whether the blocks a few shooters of a pass reach get programs for just those
    /// ([`Walk::FewShooterPrograms`]; with the marking pass).
    pub fn few_shooter_programs(&self) -> bool {
        self.walk >= Walk::FewShooterPrograms
    }

    /// Whether the hidden-polygon walk runs for a shot `side` pixels a side (hemicube only;
    /// `cull_hidden`, `walk_up_to`).
    pub fn walks_hidden(&self, side: u32) -> bool {
        self.cull_hidden() && (self.walk_up_to == 0 || side <= self.walk_up_to)
    }

    /// Whether the walk writes the item buffer of a shot `side` pixels a side (hemicube only;
    /// `walk_item_buffers`, `walk_up_to`).
    pub fn walks(&self, side: u32) -> bool {
        self.walks_hidden(side) && self.walk_item_buffers()
    }

    /// Refuse a combination of switches that cannot work together: each switch that needs
    /// another names it. Some switches are inert for some options (the walk and the solids
    /// need the hemicube); those are not refused here.
    pub fn check(&self) -> Result<(), String> {
        // The walk's levels need one another by construction (`Walk`); what is left are needs
        // across switches.
        let needs = [
            (
                self.few_shooter_programs(),
                "few_shooter_programs",
                self.marking_pass,
                "marking_pass",
            ),
            (
                self.skip_needless_clipping(),
                "skip_needless_clipping",
                self.marking_pass,
                "marking_pass",
            ),
        ];
        for (on, name, given, needed) in needs {
            if on && !given {
                return Err(format!("the tuning switch {name} needs {needed}"));
            }
        }
        if self.marking_below > 100 {
            return Err(format!(
                "the tuning's marking_below {} is a share in per cent (0 to 100)",
                self.marking_below
            ));
        }
        if self.guard_band == 0 {
            return Err("the tuning's guard_band is at least 1 (1: none)".into());
        }
        Ok(())
    }

    /// Whether the marking pass runs (if `marking_pass`) after a shot that lit `lit` (0 to 1)
    /// of the patches.
    pub fn marks_after(&self, lit: f32) -> bool {
        self.marking_below >= 100 || lit * 100.0 < self.marking_below as f32
    }

    /// Whether a reconstruction pass writes every texel of the atlas (so that its renderbuffers
    /// can be cleared first): only when it neither leaves receivers out nor skips unmarked
    /// texels.
    pub fn writes_every_texel(&self) -> bool {
        !self.receivers_only() && !self.walk_receivers() && !self.marking_pass
    }
}

/// The largest item-buffer side the llvmpipe engine's walk writes in passes of one shooter
/// (`Tuning::walk_up_to`); larger shots are drawn. Table 1's paper-faithful row (128², one
/// shooter a pass) on the simple room, interleaved in one process (`examples/interleaved_ab.rs`,
/// 2026-12-07): 5.14 and 5.96 s drawn against 6.84 and 7.93 s walked.
pub const WALK_UP_TO: u32 = 64;

impl Default for Tuning {
    fn default() -> Self {
        Self::llvmpipe()
    }
}
