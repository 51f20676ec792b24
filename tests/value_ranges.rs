//! Issue 20, hostile values: every numeric or vector flag of every subcommand, and the scene's
//! `# camera` line, is checked before anything is solved. Each case ends with exit status 2 (a
//! usage error: the flag and its range in the message) or 1 (a scene file's line, or a size
//! this driver cannot hold, named with its GL limit), never a panic, a hang or a wrong picture.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn radiosity(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

/// Run every case; each must exit with `code` and mention every needle, quickly (before the
/// solve: the slowest here makes a GL context and a trial render target).
fn expect(cases: &[(&[&str], i32, &[&str])], cwd: &Path) {
    let mut failures = Vec::new();
    for (args, code, needles) in cases {
        let start = Instant::now();
        let out = radiosity(args, cwd);
        let took = start.elapsed();
        let err = String::from_utf8_lossy(&out.stderr);
        let message = err.lines().find(|l| l.starts_with("error")).unwrap_or("");
        println!("{:?} -> {:?}: {message}", args, out.status.code());
        let mut wrong = Vec::new();
        if out.status.code() != Some(*code) {
            wrong.push(format!("exit {:?}, expected {code}", out.status.code()));
        }
        if err.contains("panicked") || err.contains("RUST_BACKTRACE") {
            wrong.push("a panic".into());
        }
        for n in *needles {
            if !err.contains(n) {
                wrong.push(format!("no '{n}' in the message"));
            }
        }
        if took > Duration::from_secs(20) {
            wrong.push(format!("took {took:?}: it should fail before solving"));
        }
        if !wrong.is_empty() {
            failures.push(format!("{args:?}: {}\n{err}", wrong.join(", ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn solve_refuses_values_out_of_range_with_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let s = |extra: &'static [&'static str]| -> Vec<&'static str> {
        let mut a = vec!["solve", "--out", "o"];
        a.extend_from_slice(extra);
        a
    };
    let cases: Vec<(Vec<&str>, i32, &[&str])> = vec![
        (s(&["--fov", "0"]), 2, &["--fov", "1 to 179"]),
        (s(&["--fov", "180"]), 2, &["--fov", "1 to 179"]),
        (s(&["--fov", "nan"]), 2, &["--fov", "1 to 179"]),
        (s(&["--fov", "-50"]), 2, &["--fov", "1 to 179"]),
        (
            s(&["--exposure", "nan"]),
            2,
            &["--exposure", "greater than 0"],
        ),
        (
            s(&["--exposure", "-1"]),
            2,
            &["--exposure", "greater than 0"],
        ),
        (s(&["--exposure", "inf"]), 2, &["--exposure", "finite"]),
        (
            s(&["--exposure", "0"]),
            2,
            &["--exposure", "greater than 0"],
        ),
        (s(&["--threshold", "nan"]), 2, &["--threshold", "0 < F < 1"]),
        (s(&["--threshold", "-1"]), 2, &["--threshold", "0 < F < 1"]),
        (
            s(&["--max-shots", "2000000"]),
            2,
            &["--max-shots", "0..=1000000"],
        ),
        (s(&["--patches", "0"]), 2, &["--patches", "1..=1048576"]),
        (
            s(&["--patches", "100000000"]),
            2,
            &["--patches", "1..=1048576"],
        ),
        (
            s(&["--patch-size", "0"]),
            2,
            &["--patch-size", "greater than 0"],
        ),
        (
            s(&["--patch-size", "-1"]),
            2,
            &["--patch-size", "greater than 0"],
        ),
        (
            s(&["--patch-size", "nan"]),
            2,
            &["--patch-size", "greater than 0"],
        ),
        (s(&["--hemi-res", "16384"]), 2, &["--hemi-res", "16..=4096"]),
        (s(&["--hemi-res", "8"]), 2, &["--hemi-res", "16..=4096"]),
        (s(&["--tessellate", "1e-9"]), 2, &["--tessellate", "0.5"]),
        (s(&["--tessellate", "nan"]), 2, &["--tessellate", "0 (off)"]),
        (
            s(&["--shooter-cell", "4294967295"]),
            2,
            &["--shooter-cell", "0..=16384"],
        ),
        (
            s(&["--emitter-cell", "99999"]),
            2,
            &["--emitter-cell", "0..=16384"],
        ),
        (
            s(&["--dump-passes", "1,0"]),
            2,
            &["--dump-passes", "1..=1000000"],
        ),
        (
            s(&["--smooth-angle", "90"]),
            2,
            &["--smooth-angle", "0 ≤ DEG < 90"],
        ),
        (
            s(&["--smooth-angle", "nan"]),
            2,
            &["--smooth-angle", "0 ≤ DEG < 90"],
        ),
        (
            s(&["--shot-triangles", "-1"]),
            2,
            &["--shot-triangles", "invalid"],
        ),
        (
            s(&["--shot-triangles", "1e9"]),
            2,
            &["--shot-triangles", "invalid"],
        ),
        (s(&["--size", "0x10"]), 2, &["--size", "1x1"]),
        (s(&["--size", "20000x10"]), 2, &["--size", "16384x16384"]),
        (s(&["--eye", "1,2,nan"]), 2, &["--eye", "finite"]),
        // The view, after parsing: eye and target together, up against the view direction.
        (
            s(&["--eye", "1,2,3", "--target", "1,2,3"]),
            2,
            &["--eye, --target", "same point"],
        ),
        (s(&["--up", "0,0,0"]), 2, &["--up", "up vector is zero"]),
        // The Cornell box's camera looks along +z.
        (s(&["--up", "0,0,-2"]), 2, &["--up", "parallel"]),
        // A patch size the flag allows, but too fine for the scene (Cornell box: 556 units).
        (
            s(&["--patch-size", "0.5"]),
            1,
            &["--patch-size", "more than 1048576"],
        ),
        // Finer still: no lightmap fits the atlas; the suggestion is a patch size that does.
        (
            s(&["--patch-size", "1e-30"]),
            1,
            &["smallest patch size that fits is about 0.0359"],
        ),
    ];
    let cases: Vec<(&[&str], i32, &[&str])> = cases
        .iter()
        .map(|(a, c, n)| (a.as_slice(), *c, *n))
        .collect();
    expect(&cases, dir.path());
    assert!(
        !dir.path().join("o/stats.json").exists(),
        "nothing is written"
    );
}

/// Sizes within the flags' ranges that llvmpipe cannot hold (its largest texture is 16384 per
/// side; a 16384² RGBA32F picture is 4 GiB): refused after the GL context is made, before the
/// solve, with the limit named.
#[test]
fn sizes_the_driver_cannot_hold_are_refused_before_solving() {
    let dir = tempfile::tempdir().unwrap();
    expect(
        &[
            (
                &["solve", "--out", "o", "--hemi-res", "4096"],
                1,
                &["--hemi-res", "20480x4096", "GL_MAX_TEXTURE_SIZE"],
            ),
            (
                &["solve", "--out", "o", "--size", "16384x16384"],
                1,
                &["--size", "cannot allocate the image", "4096 MiB"],
            ),
        ],
        dir.path(),
    );
    assert!(!dir.path().join("o").join("stats.json").exists());
}

/// Class 5's part: `--threads 100000` ran for minutes; now at most 4 per core.
#[test]
fn threads_are_capped_at_four_per_core() {
    let dir = tempfile::tempdir().unwrap();
    let cores = std::thread::available_parallelism().unwrap().get();
    let max = (4 * cores).to_string();
    let over = (4 * cores + 1).to_string();
    expect(
        &[
            (
                &["solve", "--solver", "cpu", "--threads", "100000"],
                2,
                &["--threads", &format!("more than {max}")],
            ),
            (
                &["solve", "--solver", "cpu", "--threads", &over],
                2,
                &["--threads", "4 per core"],
            ),
            (
                &["bench", "table1", "--threads", "100000"],
                2,
                &["--threads", "4 per core"],
            ),
            (&["solve", "--threads", "-1"], 2, &["--threads"]),
        ],
        dir.path(),
    );
}

/// The other subcommands' numeric flags: `bench`, and the viewer's (refused while parsing, so
/// without a display).
#[test]
fn bench_and_view_flags_are_checked_while_parsing() {
    let dir = tempfile::tempdir().unwrap();
    expect(
        &[
            (
                &["bench", "table1", "--repeat", "0"],
                2,
                &["--repeat", "1..=1000"],
            ),
            (
                &["bench", "table1", "--threshold", "2"],
                2,
                &["--threshold", "0 < F < 1"],
            ),
            (
                &["bench", "table1", "--threshold", "nan"],
                2,
                &["--threshold"],
            ),
            (
                &["view", "--exposure", "-1"],
                2,
                &["--exposure", "greater than 0"],
            ),
            (&["view", "--exposure", "nan"], 2, &["--exposure"]),
            (
                &["view", "--threshold", "0"],
                2,
                &["--threshold", "0 < F < 1"],
            ),
            (
                &["view", "--patches", "0"],
                2,
                &["--patches", "1..=1048576"],
            ),
            (
                &["view", "--patch-size", "-3"],
                2,
                &["--patch-size", "greater than 0"],
            ),
            (
                &["view", "--shots-per-frame", "0"],
                2,
                &["--shots-per-frame", "1..=64"],
            ),
            (
                &["view", "--shots-per-frame", "1000"],
                2,
                &["--shots-per-frame", "1..=64"],
            ),
            (&["view", "--size", "0x0"], 2, &["--size"]),
            (
                &["view", "--smooth-angle", "-1"],
                2,
                &["--smooth-angle", "0 ≤ DEG < 90"],
            ),
            (
                &[
                    "view",
                    "--screenshot",
                    "s.png",
                    "--after-shots",
                    "4000000000",
                ],
                2,
                &["--after-shots", "0..=1000000"],
            ),
        ],
        dir.path(),
    );
}

/// The scene's `# camera` line gets the same checks, with the file and line.
#[test]
fn scene_camera_lines_are_checked_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let triangle = "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
    let cases = [
        (
            "same.obj",
            "# camera eye 1 2 3 target 1 2 3 up 0 1 0 fov 40",
            "same point",
        ),
        (
            "fov0.obj",
            "# camera eye 0 0 -5 target 0 0 0 up 0 1 0 fov 0",
            "1 to 179",
        ),
        (
            "fov180.obj",
            "# camera eye 0 0 -5 target 0 0 0 up 0 1 0 fov 180",
            "1 to 179",
        ),
        (
            "upzero.obj",
            "# camera eye 0 0 -5 target 0 0 0 up 0 0 0 fov 40",
            "up vector is zero",
        ),
        (
            "parallel.obj",
            "# camera eye 0 0 -5 target 0 0 0 up 0 0 3 fov 40",
            "parallel",
        ),
        (
            "nanfov.obj",
            "# camera eye 0 0 -5 target 0 0 0 up 0 1 0 fov nan",
            "expected `# camera",
        ),
    ];
    for (name, line, _) in &cases {
        std::fs::write(d.join(name), format!("# a scene\n{line}\n{triangle}")).unwrap();
    }
    let runs: Vec<(Vec<String>, String, &str)> = cases
        .iter()
        .map(|(name, _, why)| {
            let args = vec!["solve".into(), name.to_string(), "--out".into(), "o".into()];
            (args, format!("{name}:2"), *why)
        })
        .collect();
    let args: Vec<Vec<&str>> = runs
        .iter()
        .map(|(a, _, _)| a.iter().map(String::as_str).collect())
        .collect();
    let needles: Vec<[&str; 2]> = runs
        .iter()
        .map(|(_, at, why)| [at.as_str(), *why])
        .collect();
    let cases: Vec<(&[&str], i32, &[&str])> = args
        .iter()
        .zip(&needles)
        .map(|(a, n)| (a.as_slice(), 1, n.as_slice()))
        .collect();
    expect(&cases, d);
}

/// The ends of the ranges are accepted and make a picture.
#[test]
fn the_ends_of_the_ranges_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = radiosity(
        &[
            "solve",
            "--out",
            "o",
            "--patches",
            "64",
            "--max-shots",
            "0",
            "--size",
            "8x8",
            "--fov",
            "179",
            "--exposure",
            "1e-3",
            "--threads",
            "0",
            "--hemi-res",
            "16",
            "--up",
            "0.01,1,0",
            "--smooth-angle",
            "89.99",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("o/image.png").exists());
}
