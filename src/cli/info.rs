//! `radiosity info`: which OpenGL backends work here, what they report, and the limits the
//! solver depends on. Each backend is probed in a child process of its own, because EGL and
//! OSMesa each bring their own GL dispatch and are best not mixed in one process.

use crate::gl::{BackendChoice, GlContext, Texture, TextureFormat};
use anyhow::Result;
use glow::HasContext;
use std::process::Command;

#[derive(clap::Args, Debug, Clone)]
pub struct InfoArgs {
    /// Probe this one backend in this process and print its report as JSON (used internally).
    #[arg(long, value_enum, hide = true)]
    pub probe: Option<BackendChoice>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct Report {
    vendor: String,
    renderer: String,
    version: String,
    glsl: String,
    max_texture_size: i32,
    max_renderbuffer_size: i32,
    float_render_target: bool,
    khr_debug: bool,
}

fn probe(choice: BackendChoice) -> Result<Report> {
    let ctx = GlContext::headless(choice)?;
    let info = &ctx.info;
    // Can we render to RGBA32F, the format of the lightmaps and the reconstruction pass?
    let texture = Texture::new(&ctx.gl, 4, 4, TextureFormat::Rgba32F, glow::NEAREST)?;
    let fbo = crate::gl::Framebuffer::new(&ctx.gl)?;
    fbo.attach_texture(glow::COLOR_ATTACHMENT0, &texture);
    let float_render_target = fbo.check_complete("info").is_ok();
    unsafe { ctx.gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    Ok(Report {
        vendor: info.vendor.clone(),
        renderer: info.renderer.clone(),
        version: info.version.clone(),
        glsl: info.glsl_version.clone(),
        max_texture_size: info.max_texture_size,
        max_renderbuffer_size: info.max_renderbuffer_size,
        float_render_target,
        khr_debug: info.khr_debug,
    })
}

pub fn run_info(args: &InfoArgs) -> Result<()> {
    if let Some(choice) = args.probe {
        outln!("{}", serde_json::to_string(&probe(choice)?)?);
        return Ok(());
    }
    let exe = std::env::current_exe()?;
    let mut working = 0;
    for (name, flag) in [("egl", "egl"), ("osmesa", "osmesa")] {
        let out = Command::new(&exe)
            .args(["info", "--probe", flag])
            .output()?;
        let report: Option<Report> = out
            .status
            .success()
            .then(|| serde_json::from_slice(&out.stdout).ok())
            .flatten();
        match report {
            Some(r) => {
                working += 1;
                outln!("{name}: works");
                outln!("  vendor      {}", r.vendor);
                outln!("  renderer    {}", r.renderer);
                outln!("  version     {} (GLSL {})", r.version, r.glsl);
                outln!(
                    "  max texture {0}x{0}, max renderbuffer {1}x{1}",
                    r.max_texture_size,
                    r.max_renderbuffer_size
                );
                outln!(
                    "  float render targets (RGBA32F): {}",
                    if r.float_render_target { "yes" } else { "NO" }
                );
                outln!("  KHR_debug: {}", if r.khr_debug { "yes" } else { "no" });
            }
            None => {
                let why = String::from_utf8_lossy(&out.stderr);
                outln!(
                    "{name}: not available: {}",
                    why.trim().trim_start_matches("error: ")
                );
            }
        }
    }
    anyhow::ensure!(working > 0, "no OpenGL backend works on this machine");
    Ok(())
}
