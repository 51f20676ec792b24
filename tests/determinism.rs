//! The same scene and options give bit-identical image.exr and lightmap.exr on the same driver:
//! across runs, and with llvmpipe on one thread (LP_NUM_THREADS=1) or its default.

use std::path::Path;
use std::process::Command;

fn solve(out: &Path, lp_threads: Option<&str>, extra: &[&str]) -> (Vec<u8>, Vec<u8>) {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.obj");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_radiosity"));
    cmd.args([
        "solve",
        scene.to_str().unwrap(),
        "--patches",
        "1200",
        "--size",
        "128x128",
        "--out",
    ]);
    cmd.arg(out).args(extra);
    if let Some(n) = lp_threads {
        cmd.env("LP_NUM_THREADS", n);
    }
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (
        std::fs::read(out.join("image.exr")).unwrap(),
        std::fs::read(out.join("lightmap.exr")).unwrap(),
    )
}

#[test]
fn runs_and_llvmpipe_thread_counts_give_identical_files() {
    let dir = tempfile::tempdir().unwrap();
    for mode in ["accurate", "paper"] {
        let extra = ["--mode", mode];
        let a = solve(&dir.path().join(format!("{mode}-a")), None, &extra);
        let b = solve(&dir.path().join(format!("{mode}-b")), None, &extra);
        let one = solve(&dir.path().join(format!("{mode}-1")), Some("1"), &extra);
        assert!(a == b, "{mode}: two runs differ");
        assert!(
            a == one,
            "{mode}: LP_NUM_THREADS=1 differs from the default"
        );
    }
}

#[test]
fn the_cpu_solver_is_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let one = solve(
        &dir.path().join("t1"),
        None,
        &["--solver", "cpu", "--threads", "1"],
    );
    let two = solve(
        &dir.path().join("t2"),
        None,
        &["--solver", "cpu", "--threads", "2"],
    );
    assert!(
        one.1 == two.1,
        "lightmap.exr differs between 1 and 2 CPU threads"
    );
    assert!(
        one.0 == two.0,
        "image.exr differs between 1 and 2 CPU threads"
    );
}
