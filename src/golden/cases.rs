//! The golden cases, each named for the GL paths it exercises, and how each is rendered into a
//! picture. Whole solves cover everything together; the probes single out the paths a driver
//! regression would break, so that a failure names the path.

use super::compare::Metric;
use crate::display::Image;
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::pipeline::{self, SolverKind};
use crate::scene::{bundled, Scene};
use crate::solver::{GpuSolver, SolveOptions, Tuning, VisibilityKind};
use anyhow::{Context, Result};

/// What a case runs.
#[derive(Clone, Copy, Debug)]
pub enum Probe {
    /// Solve to 1 % unshot with 1,024 patches and render [`SIZE`] from the scene's camera.
    Render {
        /// The bundled scene.
        scene: &'static str,
        /// The solve's mode.
        mode: Mode,
    },
    /// One visibility pass from the scene's first shooter: the item buffer's polygon IDs.
    Ids {
        /// The bundled scene.
        scene: &'static str,
        /// The visibility pass's kind (hemicube or hemispherical projection).
        visibility: VisibilityKind,
        /// The item buffer's resolution.
        res: u32,
    },
    /// `shots` shots: the radiance and unshot atlases side by side, as read back.
    Shots {
        /// The bundled scene.
        scene: &'static str,
        /// The solve's mode.
        mode: Mode,
        /// Shots made before the read-back.
        shots: u32,
    },
    /// Host uploads into a texture that queued draws sample (`upload_order`).
    UploadOrder,
}

/// The solve's mode of a case, as in `radiosity solve --mode`. Every mode but `AccurateWalked`
/// draws its item buffers through the driver, which is what the cases hold to account.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// `SolveOptions::paper`: the paper as written.
    Paper,
    /// `SolveOptions::accurate`, the default, with the llvmpipe engine's views drawn
    /// (`Tuning::drawing`): its culled draws, guard band, marking pass and wide points, but no
    /// item buffer written by the walk.
    Accurate,
    /// The default with the llvmpipe engine's walk writing every item buffer, at every side
    /// (`Tuning::walk_up_to` 0; uploaded with glTexSubImage2D, not drawn): the path of the
    /// small shots that `auto` runs on llvmpipe, held to account in every shot.
    AccurateWalked,
}

impl Mode {
    fn options(self) -> SolveOptions {
        match self {
            Mode::Paper => SolveOptions::paper(),
            Mode::Accurate => SolveOptions {
                tuning: Tuning::llvmpipe().drawing(),
                ..SolveOptions::accurate()
            },
            Mode::AccurateWalked => SolveOptions {
                tuning: Tuning {
                    walk_up_to: 0,
                    ..Tuning::llvmpipe()
                },
                ..SolveOptions::accurate()
            },
        }
    }
}

/// A golden case: what it runs and what it exercises.
pub struct Case {
    /// Its name, also the reference file's (tests/golden/NAME.exr).
    pub name: &'static str,
    /// The GL paths it exercises, for the report.
    pub exercises: &'static str,
    /// What it runs.
    pub probe: Probe,
}

/// A rendered case: RGB values, `width` pixels a row.
pub struct Picture {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// RGB, three floats per pixel (IDs: polygon ID + 1 in each channel, 0 for none).
    pub rgb: Vec<f32>,
    /// How it is compared with its reference.
    pub metric: Metric,
}

/// The size of the rendered cases, pixels: small enough for the whole set in seconds.
pub const SIZE: (u32, u32) = (96, 96);
const PATCHES: u32 = 1024;

const RENDER: &str = "a whole solve to 1 % (visibility, reconstruction, copies, readbacks, \
                      every shot) and the display pass sampling the atlas into a float image";

/// Every golden case, in the order `radiosity check` runs them.
pub const CASES: &[Case] = &[
    Case {
        name: "cornell-paper",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "cornell",
            mode: Mode::Paper,
        },
    },
    Case {
        name: "cornell-accurate",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "cornell",
            mode: Mode::Accurate,
        },
    },
    Case {
        name: "cornell-accurate-walked",
        exercises: "a whole solve to 1 % with the llvmpipe engine's hidden-polygon walk writing \
                    every item buffer (glTexSubImage2D uploads, not draws), the seen receivers \
                    and few-shooter programs it enables; then the display pass",
        probe: Probe::Render {
            scene: "cornell",
            mode: Mode::AccurateWalked,
        },
    },
    Case {
        name: "box-paper",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "box",
            mode: Mode::Paper,
        },
    },
    Case {
        name: "box-accurate",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "box",
            mode: Mode::Accurate,
        },
    },
    Case {
        name: "shadow-paper",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "shadow",
            mode: Mode::Paper,
        },
    },
    Case {
        name: "shadow-accurate",
        exercises: RENDER,
        probe: Probe::Render {
            scene: "shadow",
            mode: Mode::Accurate,
        },
    },
    Case {
        name: "ids-hemicube",
        exercises: "the visibility pass through five perspective hemicube faces into the \
                    texture-attachment FBO (depth test, scissored viewports), and the polygon \
                    IDs read back from RGBA8 as exact integers",
        probe: Probe::Ids {
            scene: "shadow",
            visibility: VisibilityKind::Hemicube,
            res: 64,
        },
    },
    Case {
        name: "ids-hemisphere",
        exercises: "the paper's hemispherical projection in the vertex shader (one view, \
                    polygons drawn whole) into the texture-attachment FBO, IDs read back exactly",
        probe: Probe::Ids {
            scene: "shadow",
            visibility: VisibilityKind::Hemisphere,
            res: 128,
        },
    },
    Case {
        name: "shot-float-copy",
        exercises: "one shot of the paper's mode: the reconstruction pass into RGBA32F \
                    renderbuffers (float render targets), glCopyTexSubImage2D into the lightmap \
                    textures, glGetTexImage of both atlases",
        probe: Probe::Shots {
            scene: "cornell",
            mode: Mode::Paper,
            shots: 1,
        },
    },
    Case {
        name: "shots-accumulate",
        exercises: "three shots of the accurate mode: each adds its energy onto what the previous \
                    copies left in the textures (additive accumulation), clears its shooter's \
                    unshot texels, and the next shooter is found from the texture",
        probe: Probe::Shots {
            scene: "shadow",
            mode: Mode::Accurate,
            shots: 3,
        },
    },
    Case {
        name: super::upload_order::NAME,
        exercises: "glTexSubImage2D into a texture that queued draws sample, between syncs (the \
                    walk's item-buffer uploads): each draw must see the upload issued before it",
        probe: Probe::UploadOrder,
    },
];

fn load(scene: &str) -> Result<Scene> {
    Ok(bundled::find(scene)
        .with_context(|| format!("no built-in scene '{scene}'"))?
        .load()?)
}

/// Run a case on `ctx`.
pub fn render(ctx: &GlContext, case: &Case) -> Result<Picture> {
    match case.probe {
        Probe::Render { scene, mode } => {
            let scene = load(scene)?;
            let layout = PatchLayout::try_new(&scene, Resolution::Patches(PATCHES))?;
            let solution = pipeline::solve(
                ctx,
                &scene,
                &layout,
                SolverKind::Gpu,
                mode.options(),
                0,
                |_| {},
            )?;
            let (atlas, _) = solution.display_atlas(&scene, &layout, false);
            let camera = scene.camera_or_default();
            let Image { width, height, rgb } =
                pipeline::render(ctx, &scene, &layout, &atlas, &camera, SIZE)?;
            Ok(Picture {
                width,
                height,
                rgb,
                metric: Metric::Radiance,
            })
        }
        Probe::Ids {
            scene,
            visibility,
            res,
        } => {
            let scene = load(scene)?;
            let layout = PatchLayout::try_new(&scene, Resolution::Patches(PATCHES))?;
            let base = match visibility {
                VisibilityKind::Hemisphere => SolveOptions::paper(),
                // One shot at `res` alone: without the per-shot item-buffer sizes of the default.
                VisibilityKind::Hemicube => SolveOptions::accurate_alone(),
            };
            let mut options = SolveOptions {
                hemi_res: res,
                ..base
            };
            // This case holds the driver's drawing to account: the item buffer drawn, not
            // written by the walk (`Tuning::walk_item_buffers`).
            options.tuning = options.tuning.drawing();
            let mut solver = GpuSolver::new(ctx, &scene, &layout, options)?;
            let polygon = solver
                .next_polygon()
                .context("the scene has nothing to shoot")?;
            let shooters = solver.shooters_of(polygon);
            solver.shoot(&shooters[..1])?;
            let ids = solver.backend().visibility.read_ids();
            let height = res;
            let width = (ids.len() as u32) / height;
            let rgb = ids
                .iter()
                .flat_map(|id| {
                    let v = id.map_or(0.0, |n| n as f32 + 1.0);
                    [v, v, v]
                })
                .collect();
            Ok(Picture {
                width,
                height,
                rgb,
                metric: Metric::Ids,
            })
        }
        Probe::Shots { scene, mode, shots } => {
            let scene = load(scene)?;
            let layout = PatchLayout::try_new(&scene, Resolution::Patches(PATCHES))?;
            let mut solver = GpuSolver::new(ctx, &scene, &layout, mode.options())?;
            for _ in 0..shots {
                solver.step()?;
            }
            let (w, h) = (layout.atlas_width as usize, layout.atlas_height as usize);
            let (radiosity, unshot) = (solver.radiosity_atlas(), solver.unshot_atlas());
            let mut rgb = Vec::with_capacity(2 * w * h * 3);
            for row in 0..h {
                for atlas in [&radiosity, &unshot] {
                    for px in atlas[row * w * 4..(row + 1) * w * 4].chunks_exact(4) {
                        rgb.extend_from_slice(&px[..3]);
                    }
                }
            }
            Ok(Picture {
                width: 2 * w as u32,
                height: h as u32,
                rgb,
                metric: Metric::Radiance,
            })
        }
        Probe::UploadOrder => super::upload_order::render(ctx),
    }
}
