//! The driver matrix (`radiosity check --drivers`, src/golden/drivers.rs): every software
//! driver Debian 12 gives headless passes the golden cases, the JUnit XML and JSON agree with
//! the rows printed, a deliberately broken GL path fails its named case on every driver, a case
//! whose second render differs from its first fails, a driver that cannot start is reported as
//! such, and each driver is deterministic on its own.
//!
//! llvmpipe, softpipe and OSMesa must be available (the CI installs them); zink is required
//! where lavapipe is installed (mesa-vulkan-drivers) and must be reported unavailable otherwise.

mod common;

use gpu_radiosity::golden::drivers::Driver;
use std::path::Path;
use std::process::{Command, Output};

const EXE: &str = env!("CARGO_BIN_EXE_radiosity");

/// Every case but the two slow whole solves of the accurate mode (softpipe takes minutes on
/// them): each GL path is still covered, by shadow-accurate and the probes. tests/golden.rs runs
/// all cases on llvmpipe.
const CASES: &str = "cornell-paper,box-paper,shadow-paper,shadow-accurate,ids-hemicube,\
                     ids-hemisphere,shot-float-copy,shots-accumulate,upload-order";

fn lavapipe_installed() -> bool {
    std::fs::read_dir("/usr/share/vulkan/icd.d")
        .map(|dir| {
            dir.flatten()
                .any(|e| e.file_name().to_string_lossy().starts_with("lvp_icd"))
        })
        .unwrap_or(false)
}

fn check(args: &[&str], fault: Option<&str>, dir: &Path) -> Output {
    let mut command = Command::new(EXE);
    command.arg("check").args(args).current_dir(dir);
    match fault {
        Some(f) => command.env("RADIOSITY_FAULT", f),
        None => command.env_remove("RADIOSITY_FAULT"),
    };
    command.output().unwrap()
}

/// The printed rows: (driver, case, result).
fn rows(stdout: &str) -> Vec<(String, String, String)> {
    stdout
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .filter(|w| w.len() >= 3 && Driver::ALL.iter().any(|d| d.name() == w[0]))
        .map(|w| {
            (
                w[0].to_string(),
                w[1].to_string(),
                w.last().unwrap().to_string(),
            )
        })
        .collect()
}

fn text(out: &Output) -> String {
    format!(
        "status {:?}\n{}\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

#[test]
fn every_driver_passes_and_the_reports_agree() {
    let dir = tempfile::tempdir().unwrap();
    let out = check(
        &[
            "--drivers",
            "all",
            "--cases",
            CASES,
            "--junit",
            "out.xml",
            "--json",
            "out.json",
        ],
        None,
        dir.path(),
    );
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let rows = rows(&stdout);
    let cases: Vec<&str> = CASES.split(',').collect();
    let mut required = vec!["llvmpipe", "softpipe", "osmesa"];
    if lavapipe_installed() {
        required.push("zink");
    } else {
        assert!(
            stdout.contains("zink      -                 unavailable"),
            "{all}"
        );
    }
    for driver in &required {
        for case in &cases {
            assert!(
                rows.iter()
                    .any(|(d, c, r)| d == driver && c == case && r == "pass"),
                "no passing row for {driver} {case}:\n{all}"
            );
        }
    }

    // The JUnit XML, read back by a JUnit parser, has the same counts as the rows.
    let xml = std::fs::read_to_string(dir.path().join("out.xml")).unwrap();
    let report = quick_junit::Report::deserialize_from_str(&xml).unwrap();
    assert_eq!(report.test_suites.len(), Driver::ALL.len(), "{xml}");
    let ran: usize = rows.len();
    let passed = report
        .test_suites
        .iter()
        .flat_map(|s| &s.test_cases)
        .filter(|c| matches!(c.status, quick_junit::TestCaseStatus::Success { .. }))
        .count();
    assert_eq!(passed, ran, "{xml}");
    assert_eq!(report.failures, 0, "{xml}");
    assert_eq!(report.tests, Driver::ALL.len() * cases.len(), "{xml}");
    for suite in &report.test_suites {
        assert_eq!(
            suite.test_cases.len(),
            cases.len(),
            "{}",
            suite.name.as_str()
        );
    }
    // Independently of the parser: one <testcase> element per driver and case.
    assert_eq!(
        xml.matches("<testcase ").count(),
        Driver::ALL.len() * cases.len()
    );

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out.json")).unwrap())
            .unwrap();
    let outcomes: usize = json["drivers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["outcomes"].as_array().unwrap().len())
        .sum();
    assert_eq!(outcomes, ran);
    for d in json["drivers"].as_array().unwrap() {
        let name = d["driver"].as_str().unwrap();
        if required.contains(&name) {
            assert_eq!(d["status"], "ran", "{d}");
            assert!(!d["renderer"].as_str().unwrap().is_empty());
        }
        // The figures README.md and docs/drivers.md quote (box-paper is the worst case of all
        // ten, and one of these).
        let worst = |field: &str| {
            d["outcomes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|o| o[field].as_f64().unwrap())
                .fold(0.0, f64::max)
        };
        match name {
            "llvmpipe" | "osmesa" => {
                assert_eq!(worst("differing"), 0.0, "{name} not bit-identical")
            }
            "softpipe" => {
                common::assert_quoted(
                    "softpipe's worst RMS (README)",
                    100.0 * worst("rms"),
                    "0.06",
                );
                common::assert_quoted(
                    "softpipe's worst RMS (drivers.md)",
                    100.0 * worst("rms"),
                    "0.058",
                );
                common::assert_quoted(
                    "softpipe's plain RMS (drivers.md)",
                    100.0 * worst("rms_plain"),
                    "27.4",
                );
            }
            "zink" if lavapipe_installed() => {
                common::assert_quoted("zink's worst RMS (README)", 100.0 * worst("rms"), "0.02");
                common::assert_quoted(
                    "zink's worst RMS (drivers.md)",
                    100.0 * worst("rms"),
                    "0.024",
                );
            }
            _ => {}
        }
        for o in d["outcomes"].as_array().unwrap() {
            assert_eq!(o["outliers"].as_f64().unwrap(), 0.0, "{name}: {o}");
            // Each case ran twice, and the second render was the first's bit for bit.
            assert_eq!(o["rerun"]["differing"].as_f64(), Some(0.0), "{name}: {o}");
        }
    }
}

#[test]
fn a_broken_gl_path_fails_its_named_case_on_every_driver() {
    let dir = tempfile::tempdir().unwrap();
    for (fault, broken, intact) in [
        (
            "swap-id-bytes",
            ["ids-hemicube", "ids-hemisphere"],
            "shots-accumulate",
        ),
        (
            "skip-accumulation-copy",
            ["shot-float-copy", "shots-accumulate"],
            "ids-hemicube",
        ),
    ] {
        let cases = format!("{},{},{intact}", broken[0], broken[1]);
        let out = check(
            &["--drivers", "all", "--cases", &cases, "--junit", "out.xml"],
            Some(fault),
            dir.path(),
        );
        let all = text(&out);
        assert_eq!(out.status.code(), Some(1), "{fault}: {all}");
        let rows = rows(&String::from_utf8_lossy(&out.stdout));
        for driver in ["llvmpipe", "softpipe", "osmesa"] {
            for case in broken {
                assert!(
                    rows.iter()
                        .any(|(d, c, r)| d == driver && c == case && r == "FAIL"),
                    "{fault}: {driver} {case} did not fail:\n{all}"
                );
            }
            if fault == "skip-accumulation-copy" {
                // The item buffer does not go through the copy: its case still passes.
                assert!(
                    rows.iter()
                        .any(|(d, c, r)| d == driver && c == intact && r == "pass"),
                    "{fault}: {driver} {intact}:\n{all}"
                );
            }
        }
        let xml = std::fs::read_to_string(dir.path().join("out.xml")).unwrap();
        assert!(xml.contains("<failure"), "{xml}");
    }
}

#[test]
fn a_driver_that_differs_from_itself_fails() {
    // The fault drops one texture upload of each case's second render only (as Mesa 25's
    // threaded context let zink's draws sample the walk's item-buffer upload out of order,
    // issue 60): the first render matches its reference exactly, and the case fails all the
    // same. The case that keeps the walk uploads its item buffers (every other whole-solve case
    // draws them); the paper's mode uploads nothing: it stays the same.
    let dir = tempfile::tempdir().unwrap();
    let out = check(
        &[
            "--drivers",
            "llvmpipe,osmesa",
            "--cases",
            "cornell-accurate-walked,shot-float-copy",
            "--json",
            "out.json",
            "--junit",
            "out.xml",
        ],
        Some("stale-upload-on-rerun"),
        dir.path(),
    );
    let all = text(&out);
    assert_eq!(out.status.code(), Some(1), "{all}");
    let rows = rows(&String::from_utf8_lossy(&out.stdout));
    for driver in ["llvmpipe", "osmesa"] {
        for (case, result) in [
            ("cornell-accurate-walked", "FAIL"),
            ("shot-float-copy", "pass"),
        ] {
            assert!(
                rows.iter()
                    .any(|(d, c, r)| d == driver && c == case && r == result),
                "{driver} {case} should {result}:\n{all}"
            );
        }
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out.json")).unwrap())
            .unwrap();
    for d in json["drivers"].as_array().unwrap() {
        for o in d["outcomes"].as_array().unwrap() {
            // Against the reference, both cases are exact (llvmpipe made it; OSMesa is it).
            assert_eq!(o["rms"].as_f64(), Some(0.0), "{o}");
            let again = o["rerun"]["differing"].as_f64().unwrap();
            match o["case"].as_str().unwrap() {
                "cornell-accurate-walked" => {
                    assert!(again > 0.0, "{o}");
                    assert!(
                        o["message"]
                            .as_str()
                            .unwrap()
                            .contains("second render differs"),
                        "{o}"
                    );
                }
                _ => assert_eq!(again, 0.0, "{o}"),
            }
        }
    }
    let xml = std::fs::read_to_string(dir.path().join("out.xml")).unwrap();
    assert!(xml.contains("second render differs"), "{xml}");
}

#[test]
fn a_driver_that_cannot_start_is_reported_not_failed() {
    let dir = tempfile::tempdir().unwrap();
    // With no Vulkan driver to find, zink cannot start (Mesa may fall back to llvmpipe, which
    // the check notices from GL_RENDERER).
    let run = |drivers: &str| {
        Command::new(EXE)
            .args(["check", "--drivers", drivers, "--cases", "ids-hemisphere"])
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let out = run("llvmpipe,zink,osmesa");
    let all = text(&out);
    // Named on its own, a driver that cannot start is an error; the others still ran.
    assert_eq!(out.status.code(), Some(1), "{all}");
    assert!(all.contains("zink could not start"), "{all}");
    assert!(all.contains("unavailable"), "{all}");
    let rows = rows(&String::from_utf8_lossy(&out.stdout));
    for driver in ["llvmpipe", "osmesa"] {
        assert!(
            rows.iter().any(|(d, _, r)| d == driver && r == "pass"),
            "{all}"
        );
    }
    // As part of `all`, it is only reported.
    let out = run("all");
    assert!(out.status.success(), "{}", text(&out));
}

/// `radiosity solve` twice on `driver`: the files are identical.
fn solve_twice(driver: Driver) {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for run in ["a", "b"] {
        let out_dir = dir.path().join(run);
        let mut command = Command::new(EXE);
        command
            .args([
                "solve",
                "--patches",
                "400",
                "--max-shots",
                "40",
                "--size",
                "64x64",
            ])
            .arg("--out")
            .arg(&out_dir);
        let out = driver.select(&mut command).output().unwrap();
        assert!(out.status.success(), "{driver:?}: {}", text(&out));
        files.push(["image.exr", "lightmap.exr"].map(|f| std::fs::read(out_dir.join(f)).unwrap()));
    }
    assert!(
        files[0] == files[1],
        "{driver:?}: two runs gave different files"
    );
}

#[test]
fn each_driver_gives_identical_files_run_after_run() {
    let mut drivers = vec![Driver::Softpipe, Driver::Osmesa];
    if lavapipe_installed() {
        drivers.push(Driver::Zink);
    }
    // llvmpipe: tests/determinism.rs.
    for driver in drivers {
        solve_twice(driver);
    }
}
