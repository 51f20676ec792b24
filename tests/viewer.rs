//! The teaching pictures: `radiosity view --screenshot` under Xvfb (the lit scene and the panel,
//! the scene matching the headless render of the same shots; at 1280×720 every control of the
//! panel in view or reachable by scrolling), and the pass pictures of
//! `radiosity solve --dump-passes` (the item buffer's IDs where the geometry puts them).
//!
//! The viewer tests need `xvfb-run` (Debian: `apt-get install xvfb xauth`; `.ci/run` installs
//! it) and fail, saying so, when it is missing.

mod common;

use gpu_radiosity::display::passes::colour_id;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_radiosity");

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the command runs");
    assert!(
        out.status.success(),
        "{:?} failed:\n{}",
        cmd,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn xvfb_run() -> PathBuf {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join("xvfb-run"))
            .find(|p| p.is_file())
    });
    found.unwrap_or_else(|| {
        panic!(
            "xvfb-run is not installed, so the viewer cannot be tested: install it with \
             `apt-get install xvfb xauth` (.ci/run does)"
        )
    })
}

/// `radiosity view ARGS` in a fresh Xvfb server with a 24-bit screen, scale factor 1. One at a
/// time: parallel `xvfb-run -a` can pick the same display number.
fn view(args: &[&str]) -> Output {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    run(Command::new(xvfb_run())
        .args(["-a", "-s", "-screen 0 1280x1024x24", BIN, "view"])
        .args(args)
        .env("WINIT_X11_SCALE_FACTOR", "1"))
}

fn load_rgb(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

/// Per-channel 8-bit differences between the window's scene region (its left `w` columns) and
/// the headless image.
fn differences(window: &image::RgbImage, headless: &image::RgbImage) -> Vec<u8> {
    let (w, h) = headless.dimensions();
    let mut d = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let (a, b) = (window.get_pixel(x, y), headless.get_pixel(x, y));
            for c in 0..3 {
                d.push(a[c].abs_diff(b[c]));
            }
        }
    }
    d
}

/// The panel's controls as `radiosity view --screenshot` reports them from the panel's layout
/// of its last frame: the points in view and in all, and the names in view, reachable by
/// scrolling, and out of reach.
struct PanelReach {
    view_points: f64,
    content_points: f64,
    in_view: Vec<String>,
    by_scrolling: Vec<String>,
    out_of_reach: Vec<String>,
}

fn panel_reach(stderr: &str) -> PanelReach {
    // panel (716 of 938 points in view): in view: A, B; by scrolling: C; out of reach: none
    let line = stderr
        .lines()
        .find(|l| l.starts_with("panel ("))
        .unwrap_or_else(|| panic!("no panel line in:\n{stderr}"));
    let list = |key: &str| {
        let start = line.find(key).unwrap_or_else(|| panic!("{key} in {line}")) + key.len();
        let rest = &line[start..];
        match rest[..rest.find(';').unwrap_or(rest.len())].trim() {
            "none" => vec![],
            names => names.split(", ").map(String::from).collect(),
        }
    };
    let points: Vec<f64> = line["panel (".len()..line.find(" points").unwrap()]
        .split(" of ")
        .map(|n| n.parse().unwrap_or_else(|e| panic!("{n} in {line}: {e}")))
        .collect();
    PanelReach {
        view_points: points[0],
        content_points: points[1],
        in_view: list("in view:"),
        by_scrolling: list("by scrolling:"),
        out_of_reach: list("out of reach:"),
    }
}

/// The panel's scroll bar in the window's rightmost columns: egui's solid bar, its handle (grey
/// 60) from the top over its track (grey 10) down to the bottom. Returns the handle's share of
/// the bar's length, or `None` if no column holds such a bar.
fn scroll_bar_handle(window: &image::RgbImage) -> Option<f64> {
    let (width, h) = window.dimensions();
    let grey = |x: u32, y: u32, lo: u8, hi: u8| {
        let p = window.get_pixel(x, y).0;
        p[0] == p[1] && p[1] == p[2] && (lo..=hi).contains(&p[0])
    };
    (width - 24..width).find_map(|x| {
        // The bar's ends are rounded and inset by a few pixels.
        let top = (0..8).find(|&y| grey(x, y, 50, 70))?;
        let handle = (top..h).take_while(|&y| grey(x, y, 50, 70)).count() as u32;
        let track = (top + handle..h).take_while(|&y| grey(x, y, 0, 16)).count() as u32;
        let length = handle + track;
        (handle > 20 && track > 20 && top + length + 8 >= h).then(|| handle as f64 / length as f64)
    })
}

#[test]
fn viewer_screenshot_shows_the_panel_and_the_same_scene_as_the_headless_render() {
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("window.png");
    let shots = "6";
    let (w, h) = (400u32, 400u32);
    let size = format!("{w}x{h}");
    view(&[
        "--screenshot",
        shot.to_str().unwrap(),
        "--after-shots",
        shots,
        "--size",
        &size,
        "--overlays",
        "none",
    ]);
    let headless = dir.path().join("headless");
    run(Command::new(BIN).args([
        "solve",
        "--max-shots",
        shots,
        "--size",
        &size,
        "--out",
        headless.to_str().unwrap(),
    ]));
    let window = load_rgb(&shot);
    let image = load_rgb(&headless.join("image.png"));
    assert_eq!(window.height(), h);
    assert!(
        window.width() > w + 200,
        "no room for the panel: {}",
        window.width()
    );

    // Not blank: the scene region has light and dark, and colour (the red and green walls).
    let scene: Vec<&image::Rgb<u8>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| window.get_pixel(x, y))
        .collect();
    let luma: Vec<f64> = scene
        .iter()
        .map(|p| (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0)
        .collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    let sd = (luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / luma.len() as f64).sqrt();
    assert!(
        mean > 20.0 && sd > 15.0,
        "scene region looks blank: mean {mean:.1}, sd {sd:.1}"
    );
    let red = scene
        .iter()
        .filter(|p| p[0] as i32 > p[1] as i32 + 40)
        .count();
    let green = scene
        .iter()
        .filter(|p| p[1] as i32 > p[0] as i32 + 20)
        .count();
    assert!(
        red > 2000 && green > 2000,
        "walls: {red} red, {green} green pixels"
    );

    // The panel: egui's dark background (grey 27) with grey text (140) and the plot on it, right
    // of the scene (measured: 89 % dark, 5 % text).
    let panel: Vec<&image::Rgb<u8>> = (0..h)
        .flat_map(|y| (w + 20..window.width() - 5).map(move |x| (x, y)))
        .map(|(x, y)| window.get_pixel(x, y))
        .collect();
    let dark = panel.iter().filter(|p| p.0.iter().all(|&c| c < 40)).count();
    let text = panel
        .iter()
        .filter(|p| p.0.iter().all(|&c| c > 100))
        .count();
    assert!(
        dark as f64 > 0.5 * panel.len() as f64 && text as f64 > 0.02 * panel.len() as f64,
        "panel: {dark} dark, {text} light of {} pixels",
        panel.len()
    );

    // The scene region is the headless render of the same shots: same solver, same display
    // pass; only the tone mapping moved from the CPU (image.png) to the viewer's shader.
    // Tolerance: README's "at most 1 level of 255 apart on llvmpipe" on any channel (rounding
    // in the sRGB encoding), mean under 0.05 levels.
    let d = differences(&window, &image);
    let worst = *d.iter().max().unwrap();
    let mean = d.iter().map(|&v| v as f64).sum::<f64>() / d.len() as f64;
    eprintln!("window vs headless: worst {worst} levels, mean {mean:.5}");
    assert!(
        worst <= 1 && mean < 0.05,
        "scene region differs from the headless render: worst {worst}, mean {mean:.4}"
    );
}

/// A laptop's window, 1280×720: the scene 950×720 and the 330-pixel panel, which is taller than
/// the window. Every control of the panel is in view or reachable by scrolling (the panel's own
/// layout of the frame saved), the overlays' switches among them, and the scroll bar is drawn,
/// its handle as long as the share of the panel in view. (The comparison with the headless
/// render stays at 400×400 above: at 720 pixels high, a few dozen pixels on the blocks' edges
/// go to another polygon in the window than in the headless render.)
#[test]
fn viewer_at_1280_by_720_has_every_panel_control_in_view_or_reachable_by_scrolling() {
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("window.png");
    let out = view(&[
        "--screenshot",
        shot.to_str().unwrap(),
        "--after-shots",
        "2",
        "--size",
        "950x720",
        "--overlays",
        "shooter,atlas",
    ]);
    let window = load_rgb(&shot);
    assert_eq!(window.dimensions(), (1280, 720));

    let stderr = String::from_utf8_lossy(&out.stderr);
    let panel = panel_reach(&stderr);
    assert!(panel.out_of_reach.is_empty(), "{stderr}");
    assert!(
        panel.content_points > panel.view_points && !panel.by_scrolling.is_empty(),
        "the panel fits at 720 pixels, so this tests no scrolling: {stderr}"
    );
    let reachable = [&panel.in_view[..], &panel.by_scrolling[..]].concat();
    assert_eq!(reachable.len(), 20, "the panel's controls: {reachable:?}");
    // By name: the run buttons, the overlays (the teaching view of each pass), the settings.
    for name in [
        "Run/Pause",
        "Step one shot",
        "Reset",
        "Camera",
        "overlays (keys 1-5)",
        "shooter",
        "item-buffer",
        "heat-map",
        "atlas",
        "borders",
        "settings",
        "shots per frame",
        "threshold",
        "exposure",
        "paper",
        "accurate",
        "patch size",
    ] {
        assert!(reachable.iter().any(|n| n == name), "{name}: {stderr}");
    }

    let share = panel.view_points / panel.content_points;
    let handle = scroll_bar_handle(&window).expect("no scroll bar at the panel's right edge");
    eprintln!("panel: {share:.3} in view; scroll bar handle {handle:.3} of the bar");
    assert!(
        (handle - share).abs() < 0.03,
        "handle {handle:.3} of the bar, {share:.3} of the panel in view"
    );
}

#[test]
fn viewer_overlays_draw_the_item_buffer_and_the_atlas() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.png");
    let over = dir.path().join("overlays.png");
    let base = ["--after-shots", "2", "--size", "300x300", "--mode", "paper"];
    view(
        &[
            &base[..],
            &[
                "--screenshot",
                plain.to_str().unwrap(),
                "--overlays",
                "none",
            ],
        ]
        .concat(),
    );
    view(
        &[
            &base[..],
            &[
                "--screenshot",
                over.to_str().unwrap(),
                "--overlays",
                "shooter,item-buffer,atlas,borders",
            ],
        ]
        .concat(),
    );
    let (a, b) = (load_rgb(&plain), load_rgb(&over));
    let changed = |x0: u32, y0: u32, x1: u32, y1: u32| {
        let mut n = 0;
        for y in y0..y1 {
            for x in x0..x1 {
                n += (a.get_pixel(x, y) != b.get_pixel(x, y)) as u32;
            }
        }
        n as f64 / ((x1 - x0) * (y1 - y0)) as f64
    };
    // Insets: the item buffer at the top left, the atlas at the bottom left.
    assert!(changed(12, 12, 80, 80) > 0.8, "no item-buffer inset");
    assert!(changed(12, 220, 80, 288) > 0.8, "no atlas inset");
    // Highlight and borders change the scene elsewhere too.
    assert!(changed(100, 100, 290, 200) > 0.3, "no in-scene overlays");
}

/// scenes/shadow, paper mode, shot 1 (the light, shooting straight down from its centre at
/// height 2): the hemispherical projection puts a direction at angle θ from the light's normal
/// at radius sin θ on the unit disk. The occluder (0.6 x 0.6 at height 1) covers the centre
/// (θ < 16.7°), the floor (2 x 2 at height 0) a ring around it (its edge at θ = 26.6°, corners at
/// 35.3°; drawn with straight edges between projected corners: radius 0.41 to 0.58), then nothing.
#[test]
fn dumped_item_buffer_has_the_expected_ids_in_the_expected_places() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::scene_path("shadow");
    run(Command::new(BIN).args([
        "solve",
        scene.to_str().unwrap(),
        "--mode",
        "paper",
        "--max-shots",
        "2",
        "--dump-passes",
        "1,2",
        "--plot",
        "--out",
        dir.path().to_str().unwrap(),
    ]));
    for f in [
        "shot-001-itembuffer.png",
        "shot-001-delta.png",
        "shot-001-atlas-before.png",
        "shot-001-atlas-after.png",
        "shot-001.json",
        "shot-002-itembuffer.png",
        "convergence.png",
    ] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
    let (floor, light, occluder) = (0u32, 1u32, 2u32);
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("shot-001.json")).unwrap())
            .unwrap();
    assert_eq!(info["shooter"], light);
    assert_eq!(info["shooter_object"], "light");

    let img = load_rgb(&dir.path().join("shot-001-itembuffer.png"));
    assert_eq!(img.dimensions(), (512, 512), "paper mode: 512² hemisphere");
    let r = 512.0f32;
    // The ID at disk coordinates (x, y) in [-1, 1] (y up; the PNG's rows run top to bottom).
    let id_at = |x: f32, y: f32| {
        let px = (((x + 1.0) * 0.5 * r) as u32).min(511);
        let py = (((1.0 - y) * 0.5 * r) as u32).min(511);
        colour_id(img.get_pixel(px, py).0)
    };
    let mut counts = [0usize; 4];
    for p in img.pixels() {
        match colour_id(p.0) {
            Some(id) if id < 3 => counts[id as usize] += 1,
            Some(_) => panic!("an ID that is no polygon of the scene: {:?}", p.0),
            None => counts[3] += 1,
        }
    }
    assert_eq!(
        counts[light as usize], 0,
        "the shooter is not in its own item buffer"
    );
    assert!(counts[floor as usize] > 10_000 && counts[occluder as usize] > 10_000);

    assert_eq!(
        id_at(0.0, 0.0),
        Some(occluder),
        "straight down: the occluder"
    );
    for (dx, dy) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
        assert_eq!(id_at(0.15 * dx, 0.15 * dy), Some(occluder));
        assert_eq!(id_at(0.34 * dx, 0.34 * dy), Some(floor), "ring at r = 0.34");
        assert_eq!(id_at(0.7 * dx, 0.7 * dy), None, "beyond the floor's edge");
    }
    for (dx, dy) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
        let k = std::f32::consts::FRAC_1_SQRT_2;
        assert_eq!(
            id_at(0.45 * k * dx, 0.45 * k * dy),
            Some(floor),
            "towards a corner"
        );
        assert_eq!(id_at(0.98 * dx, 0.98 * dy), None, "outside the unit disk");
    }

    // ΔL of shot 1: the floor ring lit, the shadowed centre of the floor not; the atlas before
    // the first shot holds the light only.
    let delta = load_rgb(&dir.path().join("shot-001-delta.png"));
    let lit = delta
        .pixels()
        .filter(|p| p.0.iter().all(|&c| c > 100))
        .count();
    assert!(lit > 1000, "ΔL of the first shot: {lit} lit pixels");
    assert!(info["delta_exposure"].as_f64().unwrap() > 0.0);
}
