//! Deliberate faults in two GL paths, switched on by the environment variable
//! `RADIOSITY_FAULT` (a comma-separated list), so that a test can prove that the golden check
//! catches a broken driver path and names it (tests/drivers.rs). Never set in normal use; with
//! the variable unset nothing here changes anything.
//!
//! - `skip-accumulation-copy`: the reconstruction pass's sums never reach the radiance
//!   texture (as if glCopyTexSubImage2D did nothing).
//! - `swap-id-bytes`: the item buffer gets each ID with its red and blue bytes swapped (as if a
//!   driver stored RGBA8 as BGRA8).
//! - `stale-upload-on-rerun`: while the driver matrix renders a case the second time
//!   (`golden::check_twice`), the second texture upload is dropped, so that the pass after it
//!   samples the texture as it was (as Mesa 25's threaded context let zink's draws sample an
//!   upload out of order, issue 60): the first render stays right, the second differs.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::OnceLock;

/// A fault `RADIOSITY_FAULT` can plant (see the module's list).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// `skip-accumulation-copy`: the accumulation pass copies nothing.
    SkipAccumulationCopy,
    /// `swap-id-bytes`: the item buffer's IDs with red and blue swapped.
    SwapIdBytes,
    /// `stale-upload-on-rerun`: the second texture upload of a case's second render dropped.
    StaleUploadOnRerun,
}

impl Fault {
    fn name(self) -> &'static str {
        match self {
            Fault::SkipAccumulationCopy => "skip-accumulation-copy",
            Fault::SwapIdBytes => "swap-id-bytes",
            Fault::StaleUploadOnRerun => "stale-upload-on-rerun",
        }
    }
}

/// Whether `fault` is switched on for this process.
pub fn active(fault: Fault) -> bool {
    static LIST: OnceLock<String> = OnceLock::new();
    LIST.get_or_init(|| std::env::var("RADIOSITY_FAULT").unwrap_or_default())
        .split(',')
        .any(|name| name.trim() == fault.name())
}

static RERUN: AtomicBool = AtomicBool::new(false);
static RERUN_UPLOADS: AtomicUsize = AtomicUsize::new(0);

/// Mark the start (`true`) or end of a case's second render (`golden::check_twice`).
pub fn rerun(on: bool) {
    RERUN_UPLOADS.store(0, Ordering::Relaxed);
    RERUN.store(on, Ordering::Relaxed);
}

/// Whether `stale-upload-on-rerun` drops the texture upload about to be made.
pub fn drops_upload() -> bool {
    active(Fault::StaleUploadOnRerun)
        && RERUN.load(Ordering::Relaxed)
        && RERUN_UPLOADS.fetch_add(1, Ordering::Relaxed) == 1
}

/// The item-ID encoding (glsl/item_id.glsl) as the visibility shaders get it.
pub fn item_id_source(text: &str) -> String {
    if !active(Fault::SwapIdBytes) {
        return text.to_string();
    }
    let right = "vec4(float(n & 255), float((n >> 8) & 255), float((n >> 16) & 255), 255.0)";
    let swapped = "vec4(float((n >> 16) & 255), float((n >> 8) & 255), float(n & 255), 255.0)";
    assert!(
        text.contains(right),
        "item_id.glsl no longer has the encoding this fault swaps"
    );
    text.replace(right, swapped)
}
