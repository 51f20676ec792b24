//! `--tuning auto|paper|llvmpipe|gpu`: the profile is chosen by renderer once the GL context
//! exists, and the run says which ran and why, in its header and in stats.json (`tuning`,
//! `tuning_reason`, the switches in `tuning_switches`).

use std::process::Command;

/// `radiosity solve ARGS` on the Cornell box (a few shots, a small image): its stderr and
/// stats.json.
fn solve(args: &[&str]) -> (String, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "--max-shots", "3", "--size", "32x32", "--out"])
        .arg(dir.path())
        .args(args)
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {stderr}");
    let text = std::fs::read_to_string(dir.path().join("stats.json")).unwrap();
    (stderr, serde_json::from_str(&text).unwrap())
}

/// The `tuning: …` line of the header.
fn header_line(stderr: &str) -> &str {
    (stderr.lines())
        .find(|l| l.starts_with("tuning: "))
        .unwrap_or_else(|| panic!("no tuning line in {stderr}"))
}

#[test]
fn auto_picks_the_llvmpipe_engine_on_mesas_software_rasteriser_and_says_why() {
    let (stderr, stats) = solve(&[]);
    let renderer = stats["gl_renderer"].as_str().unwrap();
    let software = ["llvmpipe", "softpipe", "swrast", "lavapipe"]
        .iter()
        .any(|r| renderer.to_lowercase().contains(r));
    let (profile, why) = if software {
        ("llvmpipe", "is Mesa's software rasteriser")
    } else {
        ("gpu", "is not one of Mesa's software rasterisers")
    };
    let reason = format!("auto: renderer '{renderer}' {why}");
    assert_eq!(stats["tuning"], profile, "{renderer}");
    assert_eq!(stats["tuning_reason"], reason.as_str());
    assert_eq!(
        header_line(&stderr),
        format!("tuning: {profile} ({reason})")
    );
    // The header says it before the solve does.
    let at = |s: &str| stderr.find(s).unwrap_or_else(|| panic!("{s} in {stderr}"));
    assert!(at("tuning: ") < at("solved: "), "{stderr}");
    // The switches that ran are the profile's.
    let walk = stats["tuning_switches"]["walk"].as_str();
    let expected = if software {
        "few_shooter_programs"
    } else {
        "off"
    };
    assert_eq!(walk, Some(expected), "{}", stats["tuning_switches"]);
}

#[test]
fn each_forced_profile_runs_and_is_named() {
    for (flag, walk, marks) in [
        ("gpu", "off", false),
        ("paper", "off", false),
        ("llvmpipe", "few_shooter_programs", true),
    ] {
        let (stderr, stats) = solve(&["--tuning", flag]);
        assert_eq!(stats["tuning"], flag);
        assert_eq!(stats["tuning_reason"], format!("--tuning {flag}").as_str());
        assert_eq!(
            header_line(&stderr),
            format!("tuning: {flag} (--tuning {flag})")
        );
        let switches = &stats["tuning_switches"];
        assert_eq!(switches["walk"], walk, "{flag}");
        assert_eq!(switches["marking_pass"], marks, "{flag}");
    }
    // The paper's mode keeps the paper's passes under `auto`; a named profile overrides it.
    let (_, paper) = solve(&["--mode", "paper"]);
    assert_eq!(paper["tuning"], "paper");
    assert!(paper["tuning_reason"]
        .as_str()
        .unwrap()
        .contains("--mode paper"));
    let (_, gpu) = solve(&["--mode", "paper", "--tuning", "gpu"]);
    assert_eq!(gpu["tuning"], "gpu");
    // The CPU solver draws no item buffer: no renderer to choose for, and it says so.
    let (stderr, cpu) = solve(&["--solver", "cpu", "--tuning", "gpu"]);
    assert_eq!(cpu["tuning"], "none");
    assert!(header_line(&stderr).contains("CPU solver"), "{stderr}");
}

#[test]
fn an_unknown_profile_is_refused_with_the_names() {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "--tuning", "fast"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    for name in ["auto", "paper", "llvmpipe", "gpu"] {
        assert!(stderr.contains(name), "{stderr}");
    }
}
