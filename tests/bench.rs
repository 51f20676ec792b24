//! `radiosity bench table1` runs both solvers on a Table 1 room and reports the paper's counts
//! beside its own timings (a short stopping rule here: speed is measured by the bench itself,
//! never by tests).

use std::process::Command;

#[test]
fn table1_reports_the_rooms_counts_and_both_solvers() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("table1.json");
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args([
            "bench",
            "table1",
            "--scenes",
            "simple",
            "--threshold",
            "0.5",
            "--json",
        ])
        .arg(&json)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{stdout}");
    assert!(
        stdout.contains("| simple | 1602 | 6431 | 2 | 14445 |"),
        "{stdout}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = &report["rows"][0];
    assert_eq!(row["paper_cpu_seconds"], 4.0);
    assert_eq!(row["paper_gpu_seconds"], 2.0);
    for key in ["cpu_seconds", "gpu_seconds", "ratio"] {
        assert!(row[key].as_f64().unwrap() > 0.0, "{key}");
    }
    assert!(report["peak_memory_mib"].as_f64().unwrap() > 0.0);
    assert!(report["gl_renderer"].as_str().is_some());
}
