//! Which [`Tuning`] a GPU solve runs, chosen by renderer (`--tuning auto|paper|llvmpipe|gpu`):
//! the llvmpipe engine where the "GPU" is Mesa's software rasteriser, which is a CPU and pays for
//! the walk and the culling, and the GPU profile, the paper's data flow, on any other renderer.
//! The choice is made once the GL context exists (its `GL_RENDERER`), and the run says which
//! profile ran and why (the header, `stats.json`, the bench rows).

use super::Tuning;
use crate::gl::context::is_software_rasteriser;

/// What `--tuning` asks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TuningChoice {
    /// `llvmpipe` on Mesa's software rasterisers, `gpu` on any other renderer; `paper` in the
    /// paper's mode.
    #[default]
    Auto,
    /// The paper's passes as written (`Tuning::none`, what `--mode paper` runs).
    Paper,
    /// The llvmpipe engine (`Tuning::llvmpipe`): culling, the hidden-polygon walk, seen
    /// receivers, the marking pass.
    Llvmpipe,
    /// The paper's data flow done fast on a GPU (`Tuning::gpu`): every item buffer drawn.
    Gpu,
}

/// A profile that runs (what [`TuningChoice`] resolves to).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// [`Tuning::none`].
    Paper,
    /// [`Tuning::llvmpipe`].
    Llvmpipe,
    /// [`Tuning::gpu`].
    Gpu,
}

impl Profile {
    /// Its switches.
    pub fn tuning(self) -> Tuning {
        match self {
            Profile::Paper => Tuning::none(),
            Profile::Llvmpipe => Tuning::llvmpipe(),
            Profile::Gpu => Tuning::gpu(),
        }
    }

    /// Its name, as `--tuning` and `stats.json` spell it.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Paper => "paper",
            Profile::Llvmpipe => "llvmpipe",
            Profile::Gpu => "gpu",
        }
    }

    /// The profile `auto` picks for `renderer` (GL_RENDERER): the llvmpipe engine on Mesa's
    /// software rasterisers (llvmpipe, softpipe, swrast, zink over lavapipe), else the GPU one.
    pub fn for_renderer(renderer: &str) -> Profile {
        if is_software_rasteriser(renderer) {
            Profile::Llvmpipe
        } else {
            Profile::Gpu
        }
    }
}

/// The tuning a run used and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChosenTuning {
    /// The profile; `None` for the CPU solver, which draws no item buffer.
    pub profile: Option<Profile>,
    /// Why, in a few words (`stats.json`'s `tuning_reason`).
    pub reason: String,
}

impl ChosenTuning {
    /// The profile's name, or `none` (the CPU solver).
    pub fn name(&self) -> &'static str {
        self.profile.map_or("none", Profile::name)
    }

    /// The switches to solve with (the paper's for the CPU solver, which reads none).
    pub fn tuning(&self) -> Tuning {
        self.profile.map_or(Tuning::none(), Profile::tuning)
    }

    /// The header line: `tuning: NAME (REASON)`.
    pub fn line(&self) -> String {
        format!("tuning: {} ({})", self.name(), self.reason)
    }
}

impl TuningChoice {
    /// Resolve this choice for a solve in the paper's mode or not (`paper_mode`) on `renderer`
    /// (GL_RENDERER of the solve's context; `None`: the CPU solver, which has no renderer).
    pub fn resolve(self, paper_mode: bool, renderer: Option<&str>) -> ChosenTuning {
        let Some(renderer) = renderer else {
            return ChosenTuning {
                profile: None,
                reason: "the CPU solver casts rays; it draws no item buffer, so no renderer \
                         chooses a tuning"
                    .into(),
            };
        };
        let (profile, reason) = match self {
            TuningChoice::Auto if paper_mode => (
                Profile::Paper,
                "auto: --mode paper runs the paper's passes as written".to_string(),
            ),
            TuningChoice::Auto => {
                let profile = Profile::for_renderer(renderer);
                let why = match profile {
                    Profile::Llvmpipe => "is Mesa's software rasteriser",
                    _ => "is not one of Mesa's software rasterisers",
                };
                (profile, format!("auto: renderer '{renderer}' {why}"))
            }
            TuningChoice::Paper => (Profile::Paper, "--tuning paper".into()),
            TuningChoice::Llvmpipe => (Profile::Llvmpipe, "--tuning llvmpipe".into()),
            TuningChoice::Gpu => (Profile::Gpu, "--tuning gpu".into()),
        };
        ChosenTuning {
            profile: Some(profile),
            reason,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hardware_renderers_get_the_gpu_profile_and_mesas_software_ones_the_llvmpipe_engine() {
        for r in [
            "NVIDIA GeForce RTX 3080/PCIe/SSE2",
            "AMD Radeon RX 6800 (radeonsi, navi21, LLVM 15.0.6, DRM 3.49, 6.1.0)",
            "Mesa Intel(R) UHD Graphics 620 (KBL GT2)",
            "zink Vulkan 1.3(NVIDIA GeForce RTX 3080 (NVIDIA_PROPRIETARY))",
        ] {
            assert_eq!(Profile::for_renderer(r), Profile::Gpu, "{r}");
        }
        for r in [
            "llvmpipe (LLVM 15.0.6, 256 bits)",
            "softpipe",
            "Gallium 0.4 on softpipe",
            "Mesa X11",
            "Mesa OffScreen",
            "zink Vulkan 1.3(llvmpipe (LLVM 15.0.6, 256 bits) (MESA_LLVMPIPE))",
            "zink (llvmpipe (LLVM 15.0.6, 256 bits))",
        ] {
            assert_eq!(Profile::for_renderer(r), Profile::Llvmpipe, "{r}");
        }
    }

    #[test]
    fn each_choice_resolves_to_its_profile_and_says_why() {
        let llvmpipe = "llvmpipe (LLVM 15.0.6, 256 bits)";
        let auto = TuningChoice::Auto.resolve(false, Some(llvmpipe));
        assert_eq!(auto.profile, Some(Profile::Llvmpipe));
        assert_eq!(
            auto.line(),
            "tuning: llvmpipe (auto: renderer 'llvmpipe (LLVM 15.0.6, 256 bits)' is Mesa's \
             software rasteriser)"
        );
        let nvidia = TuningChoice::Auto.resolve(false, Some("NVIDIA GeForce RTX 3080/PCIe/SSE2"));
        assert_eq!(nvidia.name(), "gpu");
        assert!(nvidia.reason.contains("NVIDIA"), "{}", nvidia.reason);
        // The paper's mode stays the paper's unless asked otherwise.
        assert_eq!(
            TuningChoice::Auto.resolve(true, Some(llvmpipe)).name(),
            "paper"
        );
        assert_eq!(
            TuningChoice::Gpu.resolve(true, Some(llvmpipe)).name(),
            "gpu"
        );
        for (choice, tuning) in [
            (TuningChoice::Paper, Tuning::none()),
            (TuningChoice::Llvmpipe, Tuning::llvmpipe()),
            (TuningChoice::Gpu, Tuning::gpu()),
        ] {
            assert_eq!(choice.resolve(false, Some(llvmpipe)).tuning(), tuning);
        }
        let cpu = TuningChoice::Llvmpipe.resolve(false, None);
        assert_eq!((cpu.profile, cpu.name()), (None, "none"));
        assert!(cpu.reason.contains("CPU solver"), "{}", cpu.reason);
    }

    #[test]
    fn every_profile_is_a_combination_that_works() {
        for p in [Profile::Paper, Profile::Llvmpipe, Profile::Gpu] {
            assert_eq!(p.tuning().check(), Ok(()), "{p:?}");
        }
        // The GPU profile draws every item buffer: no walk, nothing that needs it.
        let gpu = Tuning::gpu();
        assert_eq!(gpu.walk, crate::solver::Walk::Off);
        assert!(!(0..=1024).any(|side| gpu.walks(side)));
    }

    #[test]
    fn switches_that_need_others_are_refused_without_them() {
        // The walk's levels cannot be written apart (`Walk`), nor the receivers' choices
        // (`ReceiverChoice`); few-shooter programs and the unclipped variant need the marking
        // pass.
        let few = Tuning {
            marking_pass: false,
            ..Tuning::llvmpipe()
        };
        assert!(few.check().unwrap_err().contains("few_shooter_programs"));
        let skip = Tuning {
            receivers: crate::solver::ReceiverChoice::InFrontUnclipped,
            ..Tuning::none()
        };
        let e = skip.check().unwrap_err();
        assert!(
            e.contains("skip_needless_clipping needs marking_pass"),
            "{e}"
        );
        assert_eq!(Tuning::llvmpipe().drawing().check(), Ok(()));
        let guard = Tuning {
            guard_band: 0,
            ..Tuning::none()
        };
        assert!(guard.check().is_err());
    }

    #[test]
    fn the_llvmpipe_engine_walks_small_item_buffers_and_draws_large_ones() {
        let t = Tuning::llvmpipe();
        assert!(t.walks(16) && t.walks(super::super::tuning::WALK_UP_TO));
        assert!(!t.walks(128) && !t.walks(256));
        assert!(!t.drawing().walks(16));
        // Nor does it leave hidden polygons out of the large ones it draws; drawn at every side,
        // it does, at every side.
        assert!(t.walks_hidden(64) && !t.walks_hidden(128));
        assert!(t.drawing().walks_hidden(256));
    }
}
