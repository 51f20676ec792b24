//! The golden check on each of Mesa's software drivers, each in a process of its own: the
//! driver is chosen by environment variables that Mesa reads once, when it first loads, so one
//! process cannot try several. The parent runs `radiosity check` again as a child with the
//! driver's environment and reads the child's JSON.
//!
//! Variables the child gets (any inherited value is replaced; everything else, such as
//! `LD_LIBRARY_PATH` or `LIBGL_DRIVERS_PATH` pointing at a Mesa build under test, is passed on):
//! - llvmpipe: `GALLIUM_DRIVER=llvmpipe` on the EGL device platform (Mesa's default software
//!   rasteriser, named so that an inherited `GALLIUM_DRIVER` cannot swap it).
//! - softpipe: `GALLIUM_DRIVER=softpipe` on the EGL device platform (the reference rasteriser).
//! - osmesa: the OSMesa library (`libOSMesa.so.8`, gallium's OSMesa front end) with
//!   `GALLIUM_DRIVER=llvmpipe`: another window-system layer over the same rasteriser.
//! - zink: `MESA_LOADER_DRIVER_OVERRIDE=zink` and `LIBGL_ALWAYS_SOFTWARE=1` on the EGL device
//!   platform: GL on Vulkan, here on lavapipe (package mesa-vulkan-drivers). With
//!   `GALLIUM_DRIVER=zink` alone, Mesa 22.3.6 fails in eglInitialize ("egl: failed to create dri2
//!   screen", EGL_NOT_INITIALIZED) on both the device and the surfaceless platform.
//!
//! A child whose context turns out to be another driver than the one asked for (Mesa falls back
//! silently) counts as that driver being unavailable, never as a pass.

use super::Outcome;
use crate::gl::BackendChoice;
use anyhow::{Context, Result};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A Mesa driver of the driver matrix (`check --drivers`).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Driver {
    /// llvmpipe through EGL: the CI's driver.
    Llvmpipe,
    /// softpipe through EGL: Gallium's reference rasteriser.
    Softpipe,
    /// OSMesa (llvmpipe behind it).
    Osmesa,
    /// zink through EGL: GL on Vulkan (lavapipe).
    Zink,
}

/// Variables a child gets removed before its driver's own are set.
const SELECTING: [&str; 3] = [
    "GALLIUM_DRIVER",
    "MESA_LOADER_DRIVER_OVERRIDE",
    "LIBGL_ALWAYS_SOFTWARE",
];

impl Driver {
    /// Every driver, in the order the matrix runs them.
    pub const ALL: [Driver; 4] = [
        Driver::Llvmpipe,
        Driver::Softpipe,
        Driver::Osmesa,
        Driver::Zink,
    ];

    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Driver::Llvmpipe => "llvmpipe",
            Driver::Softpipe => "softpipe",
            Driver::Osmesa => "osmesa",
            Driver::Zink => "zink",
        }
    }

    /// The environment that selects it (see the module's notes for why).
    pub fn environment(self) -> &'static [(&'static str, &'static str)] {
        match self {
            Driver::Llvmpipe | Driver::Osmesa => &[("GALLIUM_DRIVER", "llvmpipe")],
            Driver::Softpipe => &[("GALLIUM_DRIVER", "softpipe")],
            Driver::Zink => &[
                ("MESA_LOADER_DRIVER_OVERRIDE", "zink"),
                ("LIBGL_ALWAYS_SOFTWARE", "1"),
            ],
        }
    }

    /// The backend that opens it.
    pub fn backend(self) -> BackendChoice {
        match self {
            Driver::Osmesa => BackendChoice::Osmesa,
            _ => BackendChoice::Egl,
        }
    }

    /// Make `command` (a `radiosity` subcommand that takes `--backend`) run on this driver: its
    /// backend, and its environment in place of any inherited driver-selecting variable.
    pub fn select(self, command: &mut Command) -> &mut Command {
        for var in SELECTING {
            command.env_remove(var);
        }
        let backend = match self.backend() {
            BackendChoice::Osmesa => "osmesa",
            _ => "egl",
        };
        command
            .envs(self.environment().iter().copied())
            .arg("--backend")
            .arg(backend)
    }

    /// Whether a context whose GL_RENDERER is `renderer` is this driver.
    pub fn recognises(self, renderer: &str) -> bool {
        match self {
            Driver::Llvmpipe | Driver::Osmesa => renderer.starts_with("llvmpipe"),
            Driver::Softpipe => renderer.starts_with("softpipe"),
            Driver::Zink => renderer.starts_with("zink"),
        }
    }
}

/// Parse `--drivers`: names separated by commas, or `all`.
pub fn parse_list(text: &str) -> Result<(Vec<Driver>, bool), String> {
    if text.trim() == "all" {
        return Ok((Driver::ALL.to_vec(), true));
    }
    let mut drivers = Vec::new();
    for name in text.split(',').map(str::trim) {
        let driver = Driver::ALL
            .into_iter()
            .find(|d| d.name() == name)
            .ok_or_else(|| {
                format!("unknown driver '{name}' (llvmpipe, softpipe, osmesa, zink or all)")
            })?;
        if !drivers.contains(&driver) {
            drivers.push(driver);
        }
    }
    Ok((drivers, false))
}

/// How a driver's run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Its cases ran (each passed or failed).
    Ran,
    /// It could not give a GL 3.0 context here, or gave another driver's.
    Unavailable,
    /// The child died or stopped without a report (a crash in the driver, a timeout).
    Crashed,
}

/// One driver's run, as the child reports it (and the parent completes it).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct DriverRun {
    /// The driver.
    pub driver: Driver,
    /// Whether it ran, was unavailable or crashed.
    pub status: Status,
    /// Why it is unavailable or crashed.
    pub reason: String,
    /// GL_VENDOR as it reported it.
    pub vendor: String,
    /// GL_RENDERER as it reported it.
    pub renderer: String,
    /// GL_VERSION as it reported it.
    pub version: String,
    /// The variables that selected it.
    pub environment: Vec<(String, String)>,
    /// Each case's outcome.
    pub outcomes: Vec<Outcome>,
    /// Wall-clock seconds of the child.
    pub seconds: f64,
}

impl DriverRun {
    /// A run of `driver` with nothing done yet.
    pub fn new(driver: Driver) -> DriverRun {
        DriverRun {
            driver,
            status: Status::Ran,
            reason: String::new(),
            vendor: String::new(),
            renderer: String::new(),
            version: String::new(),
            environment: driver
                .environment()
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            outcomes: Vec::new(),
            seconds: 0.0,
        }
    }

    /// How many cases failed.
    pub fn failed(&self) -> usize {
        self.outcomes.iter().filter(|o| !o.comparison.pass).count()
    }
}

/// What the children are told besides their driver.
pub struct ChildArgs<'a> {
    /// `radiosity` itself.
    pub exe: &'a Path,
    /// `--against`, when given.
    pub against: Option<&'a Path>,
    /// The cases to run (all when empty).
    pub cases: &'a [String],
    /// Difference pictures go to `<diff_dir>/<driver>/`.
    pub diff_dir: &'a Path,
    /// A driver that has not finished by then is stopped and reported as crashed.
    pub timeout: Duration,
}

/// Run the check on `driver` in a child process.
pub fn run(driver: Driver, args: &ChildArgs) -> Result<DriverRun> {
    let report = tempfile::Builder::new()
        .prefix("radiosity-check-")
        .suffix(".json")
        .tempfile()
        .context("cannot create a temporary file for a driver's report")?;
    let mut command = Command::new(args.exe);
    command
        .arg("check")
        .arg("--as-driver")
        .arg(driver.name())
        .arg("--report")
        .arg(report.path())
        .arg("--diff-dir")
        .arg(args.diff_dir.join(driver.name()));
    if let Some(dir) = args.against {
        command.arg("--against").arg(dir);
    }
    if !args.cases.is_empty() {
        command.arg("--cases").arg(args.cases.join(","));
    }
    driver
        .select(&mut command)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = command
        .spawn()
        .with_context(|| format!("cannot start {}", args.exe.display()))?;
    // Read stderr on a thread so that a chatty driver cannot fill the pipe and stall the child.
    let mut stderr = child.stderr.take().expect("stderr is piped");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut text);
        text
    });
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if start.elapsed() > args.timeout {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = reader.join().unwrap_or_default();
    let seconds = start.elapsed().as_secs_f64();
    let written = std::fs::read(report.path()).unwrap_or_default();
    let mut run = match serde_json::from_slice::<DriverRun>(&written) {
        Ok(run) => run,
        Err(_) => {
            let mut run = DriverRun::new(driver);
            run.status = Status::Crashed;
            run.reason = match status {
                None => format!("no report after {} s; stopped", args.timeout.as_secs()),
                Some(s) => format!(
                    "the check ended ({s}) without a report; {}",
                    last_lines(&stderr)
                ),
            };
            run
        }
    };
    run.seconds = seconds;
    if run.status == Status::Ran && status.is_some_and(|s| !s.success()) && run.outcomes.is_empty()
    {
        run.status = Status::Crashed;
        run.reason = last_lines(&stderr);
    }
    if run.status == Status::Ran && !driver.recognises(&run.renderer) {
        run.status = Status::Unavailable;
        run.reason = format!(
            "asked for {} ({}), the context is '{}'",
            driver.name(),
            env_text(driver),
            run.renderer
        );
        run.outcomes.clear();
    }
    Ok(run)
}

fn env_text(driver: Driver) -> String {
    driver
        .environment()
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The last few lines of a child's stderr, for a reason.
fn last_lines(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = &lines[lines.len().saturating_sub(3)..];
    if tail.is_empty() {
        "no message".into()
    } else {
        tail.join(" | ")
    }
}

/// Where `--report` writes, for a child.
pub fn write_report(path: &Path, run: &DriverRun) -> Result<()> {
    let text = serde_json::to_vec_pretty(run)?;
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}
