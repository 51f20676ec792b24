//! The paper's data flow, proven on the GL calls a solve makes: `apitrace` records
//! `radiosity solve --max-shots 3` and this test reads the dump. In both modes: every shader is
//! GLSL 1.30, the context asks for OpenGL 3.0 compatibility, each shot draws the item buffer into
//! an FBO with a texture attachment, then draws the receivers into an FBO with renderbuffer
//! attachments while the lightmap textures are bound for sampling and blending is off, then
//! copies the renderbuffers into those textures with glCopyTexSubImage2D, and every copy is read
//! (by the next pass's draws or by glGetTexImage) before anything overwrites it. The paper's
//! mode has one visibility and one reconstruction pass per shot, and Find_Max_Energy reads the
//! unshot texture after every shot.
//!
//! Needs `apitrace` (Debian: `apt-get install apitrace`; `.ci/run` installs it).

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

/// One GL call of the dump: its name and its argument text.
struct Call {
    index: u64,
    name: String,
    args: String,
}

fn calls(dump: &str) -> Vec<Call> {
    // A call starts a line: "<index> <name>(<args>) [= result]"; shader sources continue on
    // lines of their own, which never start that way.
    dump.lines()
        .filter_map(|line| {
            let (index, rest) = line.split_once(' ')?;
            let index = index.parse().ok()?;
            let (name, args) = rest.split_once('(')?;
            name.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_')
                .then(|| Call {
                    index,
                    name: name.to_string(),
                    args: args.to_string(),
                })
        })
        .collect()
}

/// The value of `key = value` in a call's arguments.
fn arg<'a>(args: &'a str, key: &str) -> Option<&'a str> {
    let at = args.find(&format!("{key} = "))? + key.len() + 3;
    let value = &args[at..];
    let end = value.find([',', ')']).unwrap_or(value.len());
    Some(value[..end].trim())
}

fn number(args: &str, key: &str) -> u32 {
    arg(args, key).and_then(|v| v.parse().ok()).unwrap_or(0)
}

/// What the data flow needs of the trace, in call order.
#[derive(Debug, Clone, PartialEq)]
enum Event {
    /// A draw into `fbo`, with the textures bound to any unit and the blend state.
    Draw {
        fbo: u32,
        textures: BTreeSet<u32>,
        blend: bool,
    },
    /// glCopyTexSubImage2D into `texture` from the read framebuffer `fbo`.
    Copy { texture: u32, fbo: u32 },
    /// glGetTexImage of `texture`.
    Read { texture: u32 },
    /// glTexSubImage2D into `texture` (the item buffer the walk wrote, `Tuning::walk_item_buffers`).
    Upload { texture: u32 },
    /// glClearBufferfv of a colour buffer of `fbo` (a visibility pass clears its item buffer).
    Clear { fbo: u32 },
}

struct Trace {
    shader_sources: Vec<String>,
    context_attributes: Vec<String>,
    /// Framebuffers with a texture colour attachment, and with a renderbuffer one.
    texture_fbos: BTreeSet<u32>,
    /// The textures attached to framebuffers as colour (the item buffers).
    attached_textures: BTreeSet<u32>,
    renderbuffer_fbos: BTreeSet<u32>,
    events: Vec<(u64, Event)>,
}

fn read_trace(dump: &str) -> Trace {
    let mut t = Trace {
        shader_sources: Vec::new(),
        context_attributes: Vec::new(),
        texture_fbos: BTreeSet::new(),
        attached_textures: BTreeSet::new(),
        renderbuffer_fbos: BTreeSet::new(),
        events: Vec::new(),
    };
    let (mut unit, mut draw_fbo, mut read_fbo, mut blend) = (0u32, 0u32, 0u32, false);
    let mut bound: BTreeMap<u32, u32> = BTreeMap::new();
    for c in calls(dump) {
        let a = c.args.as_str();
        match c.name.as_str() {
            "eglCreateContext" => t.context_attributes.push(a.to_string()),
            "glShaderSource" => {
                let source = a.split_once("string = &\"").map_or("", |s| s.1);
                t.shader_sources.push(source.chars().take(13).collect());
            }
            "glActiveTexture" => {
                unit = arg(a, "texture")
                    .and_then(|v| v.strip_prefix("GL_TEXTURE"))
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(0)
            }
            "glBindTexture" if a.contains("GL_TEXTURE_2D") => {
                bound.insert(unit, number(a, "texture"));
            }
            "glBindFramebuffer" => {
                let fbo = number(a, "framebuffer");
                let target = arg(a, "target").unwrap_or("");
                if target == "GL_FRAMEBUFFER" || target == "GL_DRAW_FRAMEBUFFER" {
                    draw_fbo = fbo;
                }
                if target == "GL_FRAMEBUFFER" || target == "GL_READ_FRAMEBUFFER" {
                    read_fbo = fbo;
                }
            }
            "glFramebufferTexture2D" if a.contains("GL_COLOR_ATTACHMENT") => {
                t.texture_fbos.insert(draw_fbo);
                t.attached_textures.insert(number(a, "texture"));
            }
            "glTexSubImage2D" => t.events.push((
                c.index,
                Event::Upload {
                    texture: bound.get(&unit).copied().unwrap_or(0),
                },
            )),
            "glFramebufferRenderbuffer" if a.contains("GL_COLOR_ATTACHMENT") => {
                t.renderbuffer_fbos.insert(draw_fbo);
            }
            "glEnable" | "glDisable" if a.contains("GL_BLEND") => blend = c.name == "glEnable",
            // Only the item buffers' clears (their FBOs are set up before any pass runs): the
            // clusters' clears of the unshot renderbuffer belong to the shot around them.
            "glClearBufferfv"
                if a.contains("GL_COLOR")
                    && t.texture_fbos.contains(&draw_fbo)
                    && !t.renderbuffer_fbos.contains(&draw_fbo) =>
            {
                t.events.push((c.index, Event::Clear { fbo: draw_fbo }))
            }
            "glCopyTexSubImage2D" => t.events.push((
                c.index,
                Event::Copy {
                    texture: bound.get(&unit).copied().unwrap_or(0),
                    fbo: read_fbo,
                },
            )),
            "glGetTexImage" => t.events.push((
                c.index,
                Event::Read {
                    texture: bound.get(&unit).copied().unwrap_or(0),
                },
            )),
            name if name.starts_with("glDraw") && !name.starts_with("glDrawBuffer") => {
                t.events.push((
                    c.index,
                    Event::Draw {
                        fbo: draw_fbo,
                        textures: bound.values().copied().filter(|&x| x != 0).collect(),
                        blend,
                    },
                ))
            }
            _ => {}
        }
    }
    t
}

/// Trace `radiosity solve --mode MODE --max-shots 3` and check it; returns the trace.
fn trace_solve(mode: &str) -> Trace {
    let dir = tempfile::tempdir().unwrap();
    trace_run(mode, dir.path(), &["--mode", mode, "--max-shots", "3"])
}

/// Trace `radiosity solve ARGS` on EGL (a 64×64 image into `dir`/out) and check what every
/// solve must hold (`check_common`, named `what`); returns the trace.
fn trace_run(what: &str, dir: &std::path::Path, args: &[&str]) -> Trace {
    let file = dir.join("solve.trace");
    let status = Command::new("apitrace")
        .args(["trace", "--api", "egl", "-o"])
        .arg(&file)
        .arg(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "--backend", "egl"])
        .args(args)
        .args(["--size", "64x64", "--out"])
        .arg(dir.join("out"))
        .output()
        .expect("apitrace runs (Debian: apt-get install apitrace)");
    assert!(
        status.status.success(),
        "apitrace trace failed: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let dump = Command::new("apitrace")
        .args(["dump", "--color=never"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(dump.status.success(), "apitrace dump failed");
    let trace = read_trace(&String::from_utf8_lossy(&dump.stdout));
    check_common(what, &trace);
    trace
}

fn check_common(mode: &str, t: &Trace) {
    assert!(t.shader_sources.len() >= 4, "{mode}: shaders traced");
    for s in &t.shader_sources {
        assert!(
            s.starts_with("#version 130"),
            "{mode}: a shader starts {s:?}"
        );
    }
    assert!(
        !t.context_attributes.is_empty(),
        "{mode}: no eglCreateContext"
    );
    for a in &t.context_attributes {
        assert!(
            a.contains("EGL_CONTEXT_MAJOR_VERSION, 3")
                && a.contains("EGL_CONTEXT_MINOR_VERSION, 0")
                && a.contains("COMPATIBILITY"),
            "{mode}: the context asks for {a}"
        );
    }
    // Every copy comes from a renderbuffer FBO, and is read before it is overwritten.
    let mut unread: BTreeMap<u32, u64> = BTreeMap::new();
    for (index, e) in &t.events {
        match e {
            Event::Copy { texture, fbo } => {
                assert!(
                    t.renderbuffer_fbos.contains(fbo),
                    "{mode}: copy {index} reads framebuffer {fbo}"
                );
                if let Some(earlier) = unread.insert(*texture, *index) {
                    panic!("{mode}: the copy into texture {texture} at call {earlier} is overwritten unread at call {index}");
                }
            }
            Event::Read { texture } => {
                unread.remove(texture);
            }
            Event::Draw { textures, .. } => {
                for x in textures {
                    unread.remove(x);
                }
            }
            Event::Upload { texture } => {
                assert!(
                    !unread.contains_key(texture),
                    "{mode}: upload {index} overwrites an unread copy into texture {texture}"
                );
            }
            Event::Clear { .. } => {}
        }
    }
}

/// The shots of a trace: for each, its events from the first draw after the previous batch of
/// copies to the end of its own batch of copies and reads.
fn shots(t: &Trace) -> Vec<Vec<Event>> {
    let mut shots = vec![Vec::new()];
    let mut copied = false;
    for (_, e) in &t.events {
        let is_copy_or_read = matches!(e, Event::Copy { .. } | Event::Read { .. });
        if copied && !is_copy_or_read {
            shots.push(Vec::new());
        }
        copied = copied && is_copy_or_read || matches!(e, Event::Copy { .. });
        shots.last_mut().unwrap().push(e.clone());
    }
    shots
}

/// The paper's shot, checked in order: visibility draws into the texture FBO; reconstruction
/// draws into the renderbuffer FBO sampling both lightmap textures, no blending; copies into both
/// lightmaps; the unshot lightmap read back (Find_Max_Energy).
fn check_shots(mode: &str, t: &Trace, passes_per_shot: Option<usize>) {
    let all = shots(t);
    // The first group is the initialisation (emission drawn, copied, read): it has no
    // visibility pass. The last is the final output (display).
    let lightmaps: BTreeSet<u32> = all[0]
        .iter()
        .filter_map(|e| match e {
            Event::Copy { texture, .. } => Some(*texture),
            _ => None,
        })
        .collect();
    assert_eq!(lightmaps.len(), 2, "{mode}: radiosity and unshot lightmaps");
    let solved: Vec<_> = all[1..]
        .iter()
        .filter(|s| s.iter().any(|e| matches!(e, Event::Copy { .. })))
        .collect();
    let passes: usize = solved
        .iter()
        .map(|s| s.iter().filter(|e| matches!(e, Event::Copy { .. })).count() / 2)
        .sum();
    assert!(passes >= 3, "{mode}: {passes} reconstruction passes copied");
    let mut shots_with_readback = 0;
    for (k, shot) in solved.iter().enumerate() {
        // Drawn into the item buffer's FBO, or (accurate mode, the walk writing it) uploaded
        // into the texture attached there.
        let visibility = shot.iter().position(|e| match e {
            Event::Draw { fbo, .. } => {
                t.texture_fbos.contains(fbo) && !t.renderbuffer_fbos.contains(fbo)
            }
            Event::Upload { texture } => t.attached_textures.contains(texture),
            _ => false,
        });
        let reconstruction: Vec<&Event> = shot
            .iter()
            .filter(|e| matches!(e, Event::Draw { fbo, .. } if t.renderbuffer_fbos.contains(fbo)))
            .collect();
        let first_copy = shot
            .iter()
            .position(|e| matches!(e, Event::Copy { .. }))
            .unwrap();
        let visibility =
            visibility.unwrap_or_else(|| panic!("{mode}: shot {k} has no visibility pass"));
        assert!(visibility < first_copy, "{mode}: shot {k}");
        assert!(
            !reconstruction.is_empty(),
            "{mode}: shot {k} draws no receivers"
        );
        for e in &reconstruction {
            let Event::Draw {
                textures, blend, ..
            } = e
            else {
                unreachable!()
            };
            assert!(
                lightmaps.is_subset(textures),
                "{mode}: shot {k}: a reconstruction draw samples {textures:?}, not the lightmaps {lightmaps:?}"
            );
            assert!(!blend, "{mode}: shot {k}: blending while reconstructing");
        }
        let copies: BTreeSet<u32> = shot
            .iter()
            .filter_map(|e| match e {
                Event::Copy { texture, .. } => Some(*texture),
                _ => None,
            })
            .collect();
        assert_eq!(copies, lightmaps, "{mode}: shot {k} copies into {copies:?}");
        let copy_count = shot
            .iter()
            .filter(|e| matches!(e, Event::Copy { .. }))
            .count();
        if let Some(n) = passes_per_shot {
            assert_eq!(copy_count, 2 * n, "{mode}: shot {k}: {copy_count} copies");
        }
        let after_copy = &shot[first_copy..];
        if after_copy
            .iter()
            .any(|e| matches!(e, Event::Read { texture } if lightmaps.contains(texture)))
        {
            shots_with_readback += 1;
        }
    }
    assert!(
        shots_with_readback >= 3,
        "{mode}: Find_Max_Energy read the unshot lightmap after {shots_with_readback} shots"
    );
}

#[test]
fn the_papers_mode_follows_the_papers_data_flow() {
    let t = trace_solve("paper");
    check_shots("paper", &t, Some(1));
}

#[test]
fn the_accurate_mode_has_the_same_data_flow_and_no_dead_copy() {
    let t = trace_solve("accurate");
    check_shots("accurate", &t, None);
    // On llvmpipe `--tuning auto` runs the llvmpipe engine, whose walk writes the small shots'
    // item buffers: the GPU profile's test below is not vacuous.
    let (uploads, _, _) = item_buffers(&t);
    assert!(uploads > 0, "the llvmpipe engine uploaded no item buffer");
}

/// In the solve's passes (up to the last copy; the display follows): the uploads into item-buffer
/// textures, the item buffers cleared (visibility passes that draw), and of those the ones drawn
/// into before the next clear or reconstruction.
fn item_buffers(t: &Trace) -> (usize, usize, usize) {
    let last_copy = (t.events.iter())
        .rposition(|(_, e)| matches!(e, Event::Copy { .. }))
        .expect("copies");
    let visibility_fbo =
        |fbo: &u32| t.texture_fbos.contains(fbo) && !t.renderbuffer_fbos.contains(fbo);
    let (mut uploads, mut cleared, mut drawn) = (0, 0, 0);
    let mut open: Option<u32> = None;
    for (_, e) in &t.events[..last_copy] {
        match e {
            Event::Upload { texture } if t.attached_textures.contains(texture) => uploads += 1,
            Event::Clear { fbo } if visibility_fbo(fbo) => {
                cleared += 1;
                open = Some(*fbo);
            }
            Event::Draw { fbo, .. } if open == Some(*fbo) => {
                drawn += 1;
                open = None;
            }
            Event::Draw { .. } => open = None,
            _ => {}
        }
    }
    (uploads, cleared, drawn)
}

/// `--tuning gpu` (the GPU profile, forced on llvmpipe): every item buffer is drawn by the
/// driver into its visibility FBO (each cleared, then drawn into; none uploaded), at least one
/// per reconstruction pass, and the data flow is the paper's, every copy read.
#[test]
fn the_gpu_profile_draws_every_item_buffer() {
    let dir = tempfile::tempdir().unwrap();
    let t = trace_run("gpu", dir.path(), &["--tuning", "gpu", "--max-shots", "3"]);
    check_shots("gpu", &t, None);
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/stats.json")).unwrap())
            .unwrap();
    assert_eq!(stats["tuning"], "gpu");
    let passes = stats["passes"].as_u64().unwrap() as usize;
    let (uploads, cleared, drawn) = item_buffers(&t);
    assert_eq!(uploads, 0, "item buffers uploaded");
    assert_eq!(cleared, drawn, "item buffers cleared, and of those drawn");
    assert!(
        cleared >= passes,
        "{cleared} item buffers for {passes} reconstruction passes"
    );
    println!("--tuning gpu: {cleared} item buffers drawn, {passes} passes, 0 uploaded");
}

/// Clusters (beyond the paper) clear their members' unshot energy before a shot's passes, by
/// scissored clears of the renderbuffer and one copy into the unshot lightmap: that copy, too,
/// comes from the renderbuffer FBO and is read before anything overwrites it (a copy per
/// member's rectangle was overwritten unread by the next).
#[test]
fn cluster_shots_copy_nothing_that_is_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let room = common::write_tiled_room(dir.path(), 32);
    let t = trace_run(
        "clusters",
        dir.path(),
        &[room.to_str().unwrap(), "--max-shots", "60"],
    );
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/stats.json")).unwrap())
            .unwrap();
    assert!(
        stats["cluster_shots"].as_u64().unwrap() > 0,
        "no cluster shot"
    );
    check_shots("clusters", &t, None);
}
