//! Golden images (src/golden/): the bundled scenes in both modes, rendered small, against
//! tests/golden/. `UPDATE_GOLDEN=1 cargo test --release --test golden` regenerates them on
//! purpose; a failure writes difference images to target/golden-diff/.

mod common;

use std::path::Path;

#[test]
fn renders_match_the_golden_images() {
    let ctx = common::context();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let diff = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/golden-diff");
    let update = std::env::var("UPDATE_GOLDEN").is_ok_and(|v| v == "1");
    let references = gpu_radiosity::golden::References::Dir(&dir);
    let cases = gpu_radiosity::golden::select(&[]).unwrap();
    let outcomes = gpu_radiosity::golden::check(&ctx, &cases, &references, &diff, update).unwrap();
    let results: Vec<_> = outcomes.into_iter().map(|o| o.comparison).collect();
    for r in &results {
        println!(
            "{:<20} RMS {:.4} %  outliers {:.3} %  not identical {:.3} %  {}",
            r.case,
            100.0 * r.rms,
            100.0 * r.outliers,
            100.0 * r.differing,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    assert_eq!(results.len(), gpu_radiosity::golden::CASES.len());
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.pass)
        .map(|r| r.case.as_str())
        .collect();
    assert!(
        failed.is_empty(),
        "golden cases differ: {failed:?} (see {})",
        diff.display()
    );
}

fn compare(name: &str, got: &[f32], reference: &[f32]) -> gpu_radiosity::golden::Comparison {
    gpu_radiosity::golden::compare(
        name,
        gpu_radiosity::golden::Metric::Radiance,
        96,
        got,
        reference,
    )
}

#[test]
fn the_metric_catches_a_changed_image() {
    let reference: Vec<f32> = (0..96 * 96 * 3)
        .map(|i| 0.1 + (i % 7) as f32 * 0.05)
        .collect();
    let same = compare("same", &reference, &reference);
    assert!(same.pass && same.rms == 0.0);
    // 3 % brighter everywhere: the RMS criterion fails.
    let brighter: Vec<f32> = reference.iter().map(|v| v * 1.03).collect();
    let c = compare("brighter", &brighter, &reference);
    assert!(!c.pass, "{c:?}");
    // One bright speck in 100 pixels: the outlier criterion fails.
    let mut speckled = reference.clone();
    for px in speckled.chunks_exact_mut(3).step_by(100) {
        px[0] += 1.0;
    }
    let c = compare("speckled", &speckled, &reference);
    assert!(!c.pass && c.outliers > 0.005, "{c:?}");
}
