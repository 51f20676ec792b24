//! `solve`'s outputs as one set: the output folder holds either the complete old set or the
//! complete new one, whatever happens to the run (an error, a full disk, SIGINT/SIGTERM/SIGHUP, a
//! concurrent run into the same folder).
//!
//! - [`OutputSet::begin`], before the solve, creates a private staging folder
//!   `.radiosity-staging-XXXXXX` (mode 0700, `mkdir` is exclusive) in the output folder. That is
//!   also the check that the folder is writable, so a read-only `--out` fails at once.
//! - [`OutputSet::write`] creates each file in it exclusively (never through a symlink), encodes
//!   and syncs it. A full disk fails here, before anything is published.
//! - [`OutputSet::publish`], holding an exclusive `flock` on the output folder (so concurrent runs
//!   publish one after the other, never interleaved), renames the staging folder to
//!   `.radiosity-publishing-XXXXXX` (the set is complete), renames each file into the output
//!   folder (`stats.json` last), removes files of an older set that this one does not have
//!   (`convergence.png`, `shot-NNN-*`), and removes the empty folder.
//! - Signals are handled by [`exit_on_signals`]'s thread, which takes the same mutex as the publish:
//!   a signal during the solve or the writing removes the staging folder and exits 1 at once; one
//!   during the publish waits the milliseconds it takes.
//! - Each run holds an `flock` on its staging folder while it lives. A later run removes the
//!   staging folders no live run holds (a SIGKILL'd run's), and finishes a publish that a SIGKILL
//!   cut short (from the list of names in `.set`), so the set is whole again and nothing piles up.
//!
//! A plain directory swap (`renameat2(RENAME_EXCHANGE)`) would make the switch one system call,
//! but the output folder is the user's and may hold other files; it is not ours to swap.

use super::output::{fill, io_error, Payload};
use anyhow::{anyhow, bail, Context, Result};
use std::fs::{File, TryLockError};
use std::io::{self, Write};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

const STAGING: &str = ".radiosity-staging-";
const PUBLISHING: &str = ".radiosity-publishing-";
/// The names of the set, one a line, in the publishing folder: lets a later run finish the job.
const MANIFEST: &str = ".set";
/// Published last: a reader who finds it finds the rest of its set.
const LAST: &str = "stats.json";

/// What the signal thread must undo. Held by the publish, so a signal waits for it.
enum State {
    Idle,
    Staging { dir: PathBuf, staging: PathBuf },
    Published { dir: PathBuf },
}

static STATE: Mutex<State> = Mutex::new(State::Idle);

fn state() -> MutexGuard<'static, State> {
    // A panic elsewhere must not stop the cleanup.
    STATE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Is `name` a file `solve` writes? Only these are removed when a new set lacks them.
pub fn is_set_member(name: &str) -> bool {
    if matches!(
        name,
        "image.exr" | "image.png" | "lightmap.exr" | "stats.json" | "convergence.png"
    ) {
        return true;
    }
    let Some(rest) = name.strip_prefix("shot-") else {
        return false;
    };
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    digits >= 3
        && matches!(
            &rest[digits..],
            ".json" | "-itembuffer.png" | "-delta.png" | "-atlas-before.png" | "-atlas-after.png"
        )
}

/// How long to wait for another run's publish. It takes milliseconds; a run stopped (SIGSTOP) in
/// the middle of one must not hang this one.
const LOCK_PATIENCE: Duration = Duration::from_secs(60);

/// An exclusive `flock` on a folder, released when the file is dropped (or the process dies).
fn lock_folder(dir: &Path) -> Result<File> {
    let f = File::open(dir)
        .with_context(|| format!("cannot open the output directory {}", dir.display()))?;
    let start = Instant::now();
    loop {
        match f.try_lock() {
            Ok(()) => return Ok(f),
            Err(TryLockError::WouldBlock) if start.elapsed() < LOCK_PATIENCE => {
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(TryLockError::WouldBlock) => bail!(
                "another run has held the output directory {} for {} s (its lock); \
                 the earlier outputs are kept",
                dir.display(),
                LOCK_PATIENCE.as_secs()
            ),
            Err(TryLockError::Error(e)) => {
                // A file system without flock: the run still works, alone.
                say(format_args!(
                    "warning: cannot lock the output directory {} ({e}): runs into it at the \
                     same time are not kept apart",
                    dir.display()
                ));
                return Ok(f);
            }
        }
    }
}

/// The files of one run, staged in the output folder until [`OutputSet::publish`].
pub struct OutputSet {
    dir: PathBuf,
    staging: PathBuf,
    /// Held while this run lives: tells other runs the staging folder is not stale.
    _alive: File,
    names: Mutex<Vec<String>>,
    published: bool,
}

impl OutputSet {
    /// Create the staging folder in `dir` (which must exist), after clearing what killed runs
    /// left there. Fails, naming `dir`, when it is not writable.
    pub fn begin(dir: &Path) -> Result<OutputSet> {
        let folder_lock = lock_folder(dir)?;
        recover(dir);
        let mut state = state();
        let staging = tempfile::Builder::new()
            .prefix(STAGING)
            .permissions(std::fs::Permissions::from_mode(0o700))
            .tempdir_in(dir)
            .map_err(|e| {
                // The kind, not tempfile's message, which names the random staging name.
                anyhow!(
                    "cannot write into the output directory {}: {}",
                    dir.display(),
                    e.kind()
                )
            })?
            .keep();
        let alive = match File::open(&staging) {
            Ok(f) => f,
            Err(e) => {
                let _ = std::fs::remove_dir_all(&staging);
                bail!("cannot open {}: {e}", staging.display());
            }
        };
        // Never blocks (the folder is new). Where flock fails, other runs' try_lock fails too, so
        // they leave this folder alone all the same.
        let _ = alive.lock();
        *state = State::Staging {
            dir: dir.to_path_buf(),
            staging: staging.clone(),
        };
        drop(state);
        drop(folder_lock);
        Ok(OutputSet {
            dir: dir.to_path_buf(),
            staging,
            _alive: alive,
            names: Mutex::new(Vec::new()),
            published: false,
        })
    }

    /// The staging folder the set's files go into before `publish`.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Stage `name` (a plain file name) with its contents.
    pub fn write(&self, name: &str, payload: Payload) -> Result<()> {
        let target = self.dir.join(name);
        if name.contains('/') || name.starts_with('.') || name.is_empty() {
            bail!("{} is not a plain output file name", target.display());
        }
        let mut file = self.create(name, &target)?;
        fill(&mut file, &payload, &target)?;
        self.names
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(name.to_string());
        Ok(())
    }

    /// Create `name` in the staging folder, exclusively; `target` names it in messages.
    fn create(&self, name: &str, target: &Path) -> Result<File> {
        // Under the mutex: the signal thread never removes the folder while a file is being
        // created in it, and after it has, nothing more is created.
        let _state = state();
        File::options()
            .write(true)
            .create_new(true)
            .open(self.staging.join(name))
            .map_err(|e| io_error(e.kind(), &e.to_string(), target))
    }

    /// Replace the set in the output folder with the staged files.
    pub fn publish(mut self) -> Result<()> {
        let names = std::mem::take(&mut *self.names.lock().unwrap_or_else(|e| e.into_inner()));
        let manifest = names.join("\n") + "\n";
        let manifest_path = self.staging.join(MANIFEST);
        let mut file = self.create(MANIFEST, &manifest_path)?;
        fill(&mut file, &Payload::Text(manifest), &manifest_path)?;
        sync_folder(&self.staging);

        let _folder_lock = lock_folder(&self.dir)?;
        let mut state = state();
        // What would stop a rename half-way is checked before the first one.
        for name in &names {
            let target = self.dir.join(name);
            if std::fs::symlink_metadata(&target).is_ok_and(|m| m.is_dir()) {
                bail!(
                    "cannot write {}: a directory is in the way (the earlier outputs are kept)",
                    target.display()
                );
            }
        }
        let suffix = self
            .staging
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_prefix(STAGING))
            .unwrap_or("x")
            .to_string();
        let publishing = self.dir.join(format!("{PUBLISHING}{suffix}"));
        std::fs::rename(&self.staging, &publishing)
            .map_err(|e| io_error(e.kind(), &e.to_string(), &publishing))?;
        self.staging = publishing.clone();
        let result = finish(&self.dir, &publishing, &names);
        if result.is_ok() {
            self.published = true;
            *state = State::Published {
                dir: self.dir.clone(),
            };
        }
        result
    }
}

impl Drop for OutputSet {
    /// A run that does not publish leaves nothing behind.
    fn drop(&mut self) {
        if self.published {
            return;
        }
        let mut state = state();
        // After a failed publish, rolling forward is the way to a whole set (the next run does it).
        if self
            .staging
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with(STAGING))
        {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
        *state = State::Idle;
    }
}

/// Move the files named in `names` from `from` into `dir` (`stats.json` last), remove the older
/// set's files this set lacks, then `from` itself. Files already moved (by a run killed half-way)
/// are skipped, so it can be run again.
fn finish(dir: &Path, from: &Path, names: &[String]) -> Result<()> {
    let order = names
        .iter()
        .filter(|n| *n != LAST)
        .chain(names.iter().filter(|n| *n == LAST));
    for name in order {
        let (src, dst) = (from.join(name), dir.join(name));
        match std::fs::rename(&src, &dst) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_error(e.kind(), &e.to_string(), &dst)),
        }
    }
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let is_file = entry.file_type().is_ok_and(|t| !t.is_dir());
            if is_file && is_set_member(&name) && !names.contains(&name) {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
    let _ = std::fs::remove_file(from.join(MANIFEST));
    let _ = std::fs::remove_dir(from);
    sync_folder(dir);
    Ok(())
}

/// Make renames and new names durable; some file systems refuse, which costs only durability.
fn sync_folder(dir: &Path) {
    if let Ok(f) = File::open(dir) {
        let _ = f.sync_all();
    }
}

/// Clear what runs that died left in `dir` (the caller holds the folder's lock): staging folders
/// are removed, interrupted publishes finished. Folders a live run holds are left alone.
/// Best effort: what cannot be cleared now is tried again by the next run.
fn recover(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let staging = name.starts_with(STAGING);
        if !(staging || name.starts_with(PUBLISHING)) {
            continue;
        }
        // A symlink planted at such a name is neither followed nor locked.
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let path = entry.path();
        let Ok(folder) = File::open(&path) else {
            continue;
        };
        if folder.try_lock().is_err() {
            continue; // a live run's
        }
        if staging {
            let _ = std::fs::remove_dir_all(&path);
        } else if let Ok(list) = std::fs::read_to_string(path.join(MANIFEST)) {
            // Only our own names: a planted list must not move anything else (`../x`).
            let names: Vec<String> = list
                .lines()
                .filter(|n| is_set_member(n))
                .map(str::to_string)
                .collect();
            let _ = finish(dir, &path, &names);
        }
    }
}

/// To stderr, if it is still open: `eprintln!` would panic, and the exit must happen.
fn say(message: std::fmt::Arguments) {
    let _ = writeln!(io::stderr(), "{message}");
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        signal_hook::consts::SIGHUP => "SIGHUP",
        _ => "a signal",
    }
}

/// Whether the first signal asks the solve to stop instead of ending the process.
static DEFER: AtomicBool = AtomicBool::new(false);
/// The signal that asked it (0: none yet).
static REQUESTED: AtomicI32 = AtomicI32::new(0);

/// While `on` (a solve's loop), the first SIGINT, SIGTERM or SIGHUP does not end the process:
/// it is kept for [`stop_requested`], so that the solve stops after its current shot and its
/// solution so far is written as a whole set. A second one ends the process as before. Turning
/// it on forgets an earlier solve's signal (a program may run several).
pub fn defer_first_signal(on: bool) {
    if on {
        REQUESTED.store(0, Ordering::SeqCst);
    }
    DEFER.store(on, Ordering::SeqCst);
}

/// The name of the signal that asked the solve to stop, if one did.
pub fn stop_requested() -> Option<&'static str> {
    match REQUESTED.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(signal_name(signal)),
    }
}

/// From now on SIGINT, SIGTERM and SIGHUP end the process with status 1 and one message, after
/// removing the staged files of an unpublished set; during a publish they wait for it to end.
/// While [`defer_first_signal`] is on, the first one only asks the solve to stop.
pub fn exit_on_signals() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    static INSTALLED: AtomicBool = AtomicBool::new(false);
    if INSTALLED.swap(true, Ordering::SeqCst) {
        return Ok(());
    }
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .context("cannot install the signal handlers")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for signal in signals.forever() {
                let name = signal_name(signal);
                if DEFER.load(Ordering::SeqCst)
                    && (REQUESTED.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst))
                        .is_ok()
                {
                    say(format_args!(
                        "{name}: stopping after the current shot to write the solution so far; \
                         a second signal stops at once and keeps the earlier outputs"
                    ));
                    continue;
                }
                // Kept locked until the exit: nothing is staged or published after this.
                let state = state();
                match &*state {
                    State::Staging { dir, staging } => {
                        let _ = std::fs::remove_dir_all(staging);
                        say(format_args!(
                            "error: interrupted by {name}; {} keeps its earlier outputs",
                            dir.display()
                        ));
                    }
                    State::Published { dir } => {
                        say(format_args!(
                            "error: interrupted by {name} after the outputs were written to {}",
                            dir.display()
                        ));
                    }
                    State::Idle => say(format_args!("error: interrupted by {name}")),
                }
                // _exit: no atexit handlers, which could run into the GL driver's threads.
                signal_hook::low_level::exit(1);
            }
        })
        .context("cannot start the signal thread")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    fn text(s: &str) -> Payload<'static> {
        Payload::Text(s.to_string())
    }

    // One test: the state is process-wide, and the test harness runs tests in parallel.
    #[test]
    fn sets_replace_each_other_whole() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        std::fs::write(dir.join("notes.txt"), "the user's").unwrap();

        let a = OutputSet::begin(dir).unwrap();
        a.write("image.png", text("a")).unwrap();
        a.write("convergence.png", text("a")).unwrap();
        a.write("stats.json", text("a")).unwrap();
        assert_eq!(names(dir).len(), 2, "only the staging folder is new");
        a.publish().unwrap();
        assert_eq!(
            names(dir),
            ["convergence.png", "image.png", "notes.txt", "stats.json"]
        );

        // A set without convergence.png removes the old one; other files stay.
        let b = OutputSet::begin(dir).unwrap();
        b.write("image.png", text("b")).unwrap();
        b.write("stats.json", text("b")).unwrap();
        assert!(b.write("../escape", text("b")).is_err());
        b.publish().unwrap();
        assert_eq!(names(dir), ["image.png", "notes.txt", "stats.json"]);

        // Dropped unpublished: nothing changes, nothing is left.
        let c = OutputSet::begin(dir).unwrap();
        c.write("image.png", text("c")).unwrap();
        drop(c);
        assert_eq!(names(dir), ["image.png", "notes.txt", "stats.json"]);
        assert_eq!(std::fs::read_to_string(dir.join("image.png")).unwrap(), "b");

        // What a SIGKILL leaves: a staging folder, and a publish cut short after one rename.
        let dead = dir.join(format!("{STAGING}dead"));
        std::fs::create_dir(&dead).unwrap();
        std::fs::write(dead.join("image.png"), "dead").unwrap();
        let cut = dir.join(format!("{PUBLISHING}cut"));
        std::fs::create_dir(&cut).unwrap();
        std::fs::write(cut.join(MANIFEST), "image.png\nstats.json\n../escape\n").unwrap();
        std::fs::write(cut.join("../escape"), "stays").unwrap();
        std::fs::write(dir.join("image.png"), "cut").unwrap();
        std::fs::write(cut.join("stats.json"), "cut").unwrap();
        let d2 = OutputSet::begin(dir).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.join("stats.json")).unwrap(),
            "cut"
        );
        assert!(!dead.exists() && !cut.exists());
        assert!(dir.join("escape").exists() && !d.path().parent().unwrap().join("escape").exists());
        std::fs::remove_file(dir.join("escape")).unwrap();
        drop(d2);
        assert_eq!(names(dir), ["image.png", "notes.txt", "stats.json"]);

        // A directory in the way fails before anything is renamed.
        std::fs::create_dir(dir.join("lightmap.exr")).unwrap();
        let e = OutputSet::begin(dir).unwrap();
        e.write("image.png", text("e")).unwrap();
        e.write("lightmap.exr", text("e")).unwrap();
        let err = format!("{:#}", e.publish().unwrap_err());
        assert!(err.contains("lightmap.exr"), "{err}");
        assert_eq!(
            std::fs::read_to_string(dir.join("image.png")).unwrap(),
            "cut"
        );
        assert_eq!(
            names(dir),
            ["image.png", "lightmap.exr", "notes.txt", "stats.json"]
        );
    }

    #[test]
    fn set_members() {
        for n in [
            "image.exr",
            "stats.json",
            "shot-001.json",
            "shot-1234-delta.png",
        ] {
            assert!(is_set_member(n), "{n}");
        }
        for n in [
            "notes.txt",
            "shot-01.json",
            "shot-001-x.png",
            "image.jpg",
            "shot-.json",
        ] {
            assert!(!is_set_member(n), "{n}");
        }
    }
}
