//! The check's results for CI systems: JUnit XML (one testsuite per driver, one testcase per
//! case; GitLab, Jenkins and others display it) and JSON with the same data.

use super::drivers::{DriverRun, Status};
use super::Case;
use anyhow::{Context, Result};
use quick_junit::{NonSuccessKind, Property, Report, TestCase, TestCaseStatus, TestSuite};
use std::path::Path;
use std::time::Duration;

/// The figures of one outcome, as a line.
pub fn figures(o: &super::Outcome) -> String {
    let c = &o.comparison;
    let again = match &o.rerun {
        None => String::new(),
        Some(r) => format!(
            "; again: {:.3} % of values differ, {:.1} s",
            100.0 * r.differing,
            r.seconds
        ),
    };
    format!(
        "RMS {:.4} % (pixel against pixel {:.4} %), outliers {:.3} %, not identical {:.3} %, \
         {:.1} s{again}",
        100.0 * c.rms,
        100.0 * c.rms_plain,
        100.0 * c.outliers,
        100.0 * c.differing,
        o.seconds
    )
}

/// JUnit XML for `runs`; `cases` are the cases each run was asked for (an unavailable driver's
/// cases are listed as skipped, a crashed driver's missing ones as errors).
pub fn junit(runs: &[DriverRun], cases: &[&Case]) -> Result<String> {
    let mut report = Report::new("radiosity check");
    for run in runs {
        let name = run.driver.name();
        let mut suite = TestSuite::new(name);
        suite.set_time(Duration::from_secs_f64(run.seconds));
        for (key, value) in [
            ("renderer", run.renderer.as_str()),
            ("version", run.version.as_str()),
            ("vendor", run.vendor.as_str()),
        ] {
            if !value.is_empty() {
                suite.add_property(Property::new(key, value));
            }
        }
        for (k, v) in &run.environment {
            suite.add_property(Property::new(format!("env.{k}"), v.as_str()));
        }
        for case in cases {
            let outcome = run.outcomes.iter().find(|o| o.comparison.case == case.name);
            let status = match (run.status, outcome) {
                (_, Some(o)) if o.comparison.pass => TestCaseStatus::success(),
                (_, Some(o)) => {
                    let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                    s.set_message(o.comparison.message.as_str());
                    s.set_type("golden mismatch");
                    s.set_description(figures(o));
                    s
                }
                (Status::Unavailable, None) => {
                    let mut s = TestCaseStatus::skipped();
                    s.set_message(format!("{name} is unavailable: {}", run.reason));
                    s
                }
                (_, None) => {
                    let mut s = TestCaseStatus::non_success(NonSuccessKind::Error);
                    s.set_message(format!("no result: {}", run.reason));
                    s.set_type("crash");
                    s
                }
            };
            let mut test = TestCase::new(case.name, status);
            test.set_classname(format!("golden.{name}"));
            if let Some(o) = outcome {
                test.set_time(Duration::from_secs_f64(o.seconds));
                test.set_system_out(format!("{}; exercises {}", figures(o), case.exercises));
            }
            suite.add_test_case(test);
        }
        report.add_test_suite(suite);
    }
    report.to_string().context("cannot write the JUnit XML")
}

/// Write `text` to `path` (through a temporary file, so a reader never sees half of it).
pub fn write(path: &Path, text: &str) -> Result<()> {
    crate::display::output::write_atomic(path, crate::display::output::Payload::Text(text.into()))
}
