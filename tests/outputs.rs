//! Hostile conditions around `solve`'s outputs (issue 20, classes 1, 2 and 7's full disk): symlinks
//! planted at temporary names, two runs into one folder, SIGINT/SIGTERM during the solve and during
//! the writing, a read-only folder, a full disk. Each ends in a correct result or a clear error
//! with status 1; the folder always holds one complete set and nothing else of ours; nothing
//! outside it is touched.

mod common;

use common::snapshot;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const SET: [&str; 4] = ["image.exr", "image.png", "lightmap.exr", "stats.json"];

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
}

/// A quick solve: the CPU solver on a coarse Cornell box, a small image.
fn quick(out: &Path, patches: &str, size: &str) -> Vec<String> {
    [
        "solve",
        "--solver",
        "cpu",
        "--patches",
        patches,
        "--size",
        size,
        "--out",
        out.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec()
}

fn run(args: &[String]) -> Output {
    bin().args(args).output().expect("the binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn names(dir: &Path) -> Vec<String> {
    snapshot(dir).into_keys().collect()
}

fn assert_clean_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "exit status 1: {err}");
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "no panic: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "the message should mention '{n}': {err}");
    }
}

#[test]
fn symlinks_at_temporary_names_are_not_followed() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let outside = tmp.path().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let victim = outside.join("victim");
    std::fs::write(&victim, "keep").unwrap();
    std::fs::write(outside.join(".set"), "stats.json\n").unwrap();
    std::fs::write(outside.join("stats.json"), "outside").unwrap();
    let first = run(&quick(&out, "150", "40x30"));
    assert!(first.status.success(), "{}", stderr(&first));
    // The fixed names of earlier versions, our folder prefixes, and the outputs themselves.
    let mut planted = Vec::new();
    for f in SET.iter().chain(&["convergence.png"]) {
        let ext = f.rsplit('.').next().unwrap();
        planted.push(format!(".{f}.partial.{ext}"));
    }
    for p in &planted {
        std::os::unix::fs::symlink(&victim, out.join(p)).unwrap();
    }
    for p in [
        ".radiosity-staging-planted",
        ".radiosity-publishing-planted",
    ] {
        std::os::unix::fs::symlink(&outside, out.join(p)).unwrap();
        planted.push(p.to_string());
    }
    std::fs::remove_file(out.join("image.png")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("image.png")).unwrap();
    let outside_before = snapshot(&outside);
    let mut args = quick(&out, "150", "40x30");
    args.push("--plot".into());
    let second = run(&args);
    assert!(second.status.success(), "{}", stderr(&second));
    assert_eq!(
        snapshot(&outside),
        outside_before,
        "a file outside was touched"
    );
    // image.png is now the new file, not the symlink.
    let png = std::fs::symlink_metadata(out.join("image.png")).unwrap();
    assert!(png.is_file());
    let mut expected: Vec<String> = SET.iter().map(|s| s.to_string()).collect();
    expected.push("convergence.png".into());
    expected.extend(planted);
    expected.sort();
    assert_eq!(names(&out), expected);
}

#[test]
fn concurrent_runs_leave_one_runs_set() {
    let tmp = tempfile::tempdir().unwrap();
    // Two runs that differ in every file: patches (lightmap, stats), size and exposure (images).
    let runs = |out: &Path| {
        // About the same work, so that either may publish last.
        let mut a = quick(out, "150", "320x240");
        let mut b = quick(out, "170", "240x320");
        a.extend(["--exposure".into(), "1".into()]);
        b.extend(["--exposure".into(), "2".into()]);
        [a, b]
    };
    let references: Vec<BTreeMap<String, Vec<u8>>> = (0..2)
        .map(|i| {
            let dir = tmp.path().join(format!("ref-{i}"));
            let o = run(&runs(&dir)[i]);
            assert!(o.status.success(), "{}", stderr(&o));
            snapshot(&dir)
        })
        .collect();
    let patches = |set: &BTreeMap<String, Vec<u8>>| {
        let stats: serde_json::Value = serde_json::from_slice(&set["stats.json"]).unwrap();
        stats["patches"].clone()
    };
    assert_ne!(patches(&references[0]), patches(&references[1]));
    let shared = tmp.path().join("shared");
    let mut winners = Vec::new();
    for trial in 0..6 {
        let children: Vec<Child> = runs(&shared)
            .iter()
            .map(|args| {
                bin()
                    .args(args)
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            assert!(o.status.success(), "trial {trial}: {}", stderr(&o));
        }
        let got = snapshot(&shared);
        assert_eq!(
            got.keys().collect::<Vec<_>>(),
            SET.iter().collect::<Vec<_>>()
        );
        let winner = references
            .iter()
            .position(|r| {
                ["image.exr", "image.png", "lightmap.exr"]
                    .iter()
                    .all(|f| r[*f] == got[*f])
                    && patches(r) == patches(&got)
            })
            .unwrap_or_else(|| panic!("trial {trial}: the set matches neither run"));
        winners.push(winner);
    }
    println!("the last to publish, per trial: {winners:?}");
}

/// Start a solve, wait until `ready` holds for the output folder (polling), send `signals` one
/// right after the other, and return what the run printed.
fn interrupt(
    args: &[String],
    out: &Path,
    signals: &[&str],
    ready: impl Fn(&Path) -> bool,
) -> Output {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !ready(out) {
        if child.try_wait().unwrap().is_some() {
            let o = child.wait_with_output().unwrap();
            panic!("the run ended before the signal: {}", stderr(&o));
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "never got ready"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    for (k, signal) in signals.iter().enumerate() {
        let killed = Command::new("kill")
            .args(["-s", signal, &child.id().to_string()])
            .status()
            .unwrap();
        // A later one may find the run gone, ended by the first.
        assert!(killed.success() || k > 0);
    }
    child.wait_with_output().unwrap()
}

fn staging(out: &Path) -> Option<PathBuf> {
    std::fs::read_dir(out)
        .ok()?
        .flatten()
        .find(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(".radiosity-staging-")
        })
        .map(|e| e.path())
}

#[test]
fn signals_leave_the_old_set_and_no_temporary_files() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let first = run(&quick(&out, "150", "40x30"));
    assert!(first.status.success(), "{}", stderr(&first));
    let mut before = snapshot(&out);
    for signal in ["INT", "TERM"] {
        // During the solve: the GPU solver at 4,096 patches takes many seconds here.
        let long = [
            "solve",
            "--patches",
            "4096",
            "--size",
            "40x30",
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from);
        // A first signal in the solve's loop only stops the loop (tests/stopping.rs); the
        // second, right after it, ends the run at once. Before the loop the first does.
        let other = if signal == "INT" { "TERM" } else { "INT" };
        let o = interrupt(&long, &out, &[signal, other], |d| staging(d).is_some());
        assert_clean_error(&o, &["interrupted by SIG", "earlier outputs"]);
        assert!(!stderr(&o).contains("solved:"), "{}", stderr(&o));
        assert!(
            snapshot(&out) == before,
            "SIG{signal} during the solve changed the folder"
        );

        // During the writing: a large image.exr is being written when the signal comes.
        let big = quick(&out, "150", "2048x2048");
        let o = interrupt(&big, &out, &[signal], |d| {
            staging(d).is_some_and(|s| s.join("image.exr").exists())
        });
        let err = stderr(&o);
        if err.contains("after the outputs were written") {
            // Too late to stop: then the new set is whole.
            println!("SIG{signal} came after the publish");
            assert_eq!(names(&out), SET);
            let _ = std::fs::remove_dir_all(&out);
            let o = run(&quick(&out, "150", "40x30"));
            assert!(o.status.success());
            before = snapshot(&out);
        } else {
            assert_clean_error(
                &o,
                &[&format!("interrupted by SIG{signal}"), "earlier outputs"],
            );
            assert!(
                snapshot(&out) == before,
                "SIG{signal} while writing changed the folder"
            );
        }
    }

    // SIGKILL cannot be handled: the staging folder stays, the set too; the next run clears it.
    let long = quick(&out, "150", "2048x2048");
    let o = interrupt(&long, &out, &["KILL"], |d| {
        staging(d).is_some_and(|s| s.join("image.exr").exists())
    });
    assert!(!o.status.success());
    assert!(staging(&out).is_some());
    for f in SET {
        assert_eq!(before[f], std::fs::read(out.join(f)).unwrap(), "{f}");
    }
    let o = run(&quick(&out, "150", "40x30"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&out), SET, "the dead run's staging folder is removed");
}

/// Run `script` (sh) in a new user and mount namespace, where an unprivileged user is root and
/// may mount a tmpfs; `None` where the system forbids it.
fn in_namespace(script: &str, env: &[(&str, &Path)]) -> Option<Output> {
    let probe = Command::new("unshare")
        .args(["-rm", "true"])
        .output()
        .ok()?;
    if !probe.status.success() {
        println!(
            "skipped: unshare -rm is not permitted here: {}",
            String::from_utf8_lossy(&probe.stderr)
        );
        return None;
    }
    let mut c = Command::new("unshare");
    c.args(["-rm", "sh", "-c", script])
        .env("RADIOSITY", env!("CARGO_BIN_EXE_radiosity"));
    for (k, v) in env {
        c.env(k, v);
    }
    Some(c.output().unwrap())
}

#[test]
fn a_read_only_folder_fails_before_the_solve() {
    let tmp = tempfile::tempdir().unwrap();
    let ro = tmp.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    // Root ignores permission bits: a read-only mount says no to everyone.
    let Some(o) = in_namespace(
        r#"mount -t tmpfs -o ro,size=64k none "$RO" && exec "$RADIOSITY" solve --solver cpu --out "$RO""#,
        &[("RO", &ro)],
    ) else {
        return;
    };
    assert_clean_error(&o, &["output directory", ro.to_str().unwrap(), "read-only"]);
    let err = stderr(&o);
    assert!(
        !err.contains("backend") && !err.contains("solved"),
        "it should fail before the GL context and the solve: {err}"
    );
}

/// A tmpfs too small for the second run's image: run 1 fits, run 2 meets ENOSPC. Found the
/// simplest honest full disk: a real file system, no test hook in the program, and it works
/// unprivileged where user namespaces are allowed (a `/dev/full` unit test covers the message).
#[test]
fn a_full_disk_keeps_the_old_set_and_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let full = tmp.path().join("full");
    let (before, after) = (tmp.path().join("before"), tmp.path().join("after"));
    for d in [&full, &before, &after] {
        std::fs::create_dir(d).unwrap();
    }
    let script = r#"
        mount -t tmpfs -o size=400k none "$FULL" || exit 90
        "$RADIOSITY" solve --solver cpu --patches 150 --size 40x30 --out "$FULL" 2>/dev/null || exit 91
        cp -a "$FULL"/. "$BEFORE"/
        "$RADIOSITY" solve --solver cpu --patches 150 --size 1024x1024 --out "$FULL"
        status=$?
        cp -a "$FULL"/. "$AFTER"/
        exit $status
    "#;
    let Some(o) = in_namespace(
        script,
        &[("FULL", &full), ("BEFORE", &before), ("AFTER", &after)],
    ) else {
        return;
    };
    assert_clean_error(&o, &["no space left", "ENOSPC", "image.exr"]);
    assert!(!stderr(&o).contains("ecod"), "{}", stderr(&o));
    assert_eq!(names(&before), SET);
    assert!(snapshot(&after) == snapshot(&before), "the old set changed");
}
