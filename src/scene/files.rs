//! Reading scene files safely: only regular files under a size limit, material libraries only
//! inside the scene's folder (unless allowed), and names echoed with control characters escaped.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Largest OBJ file read (bytes): beyond it a file is refused rather than read until memory
/// runs out (`/dev/zero` was read until the allocator aborted).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;
/// Largest MTL file read (bytes): a material library is a few lines per material.
pub const MAX_MTL_BYTES: u64 = 16 << 20;

static ALLOW_OUTSIDE_MATERIALS: AtomicBool = AtomicBool::new(false);

/// Let `mtllib` name files outside the scene's folder (absolute paths, `../`); off by default,
/// so that a scene file cannot make the program read any file it can reach.
pub fn allow_outside_materials(allow: bool) {
    ALLOW_OUTSIDE_MATERIALS.store(allow, Ordering::Relaxed);
}

/// Where the material libraries of a scene come from: its folder on disk, or the copies built
/// into the binary. Both go through the same checks of what they return.
pub(super) trait MaterialFiles {
    /// The bytes of the library `file` (the scene's folder joined with the `mtllib` name).
    fn read(&self, file: &Path) -> std::io::Result<Vec<u8>>;
    /// The `.mtl` files in the scene's folder (at most [`BESIDE`]), for the message that says
    /// which of them defines the materials when the library an `mtllib` names is missing. They
    /// are fetched with `read`, under its rules.
    fn beside(&self) -> Vec<PathBuf>;
    /// Scenes built into the binary: their notes (statements skipped) are known and not
    /// repeated on every run; their warnings still are.
    fn built_in(&self) -> bool {
        false
    }
}

/// Most `.mtl` files of a folder looked into for a missing library: a folder of many is not
/// read whole.
pub(super) const BESIDE: usize = 64;

/// A scene's folder on disk.
pub(super) struct Folder<'a>(pub &'a Path);

impl MaterialFiles for Folder<'_> {
    fn read(&self, file: &Path) -> std::io::Result<Vec<u8>> {
        if !ALLOW_OUTSIDE_MATERIALS.load(Ordering::Relaxed) {
            confined(self.0, file)?;
        }
        read_regular(file, MAX_MTL_BYTES)
    }

    fn beside(&self) -> Vec<PathBuf> {
        let Ok(entries) = std::fs::read_dir(self.0) else {
            return Vec::new();
        };
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mtl")))
            .collect();
        files.sort();
        files.truncate(BESIDE);
        files
    }
}

/// The rule of [`Folder::read`] for any other file a scene names (a glTF file's buffers and
/// images): inside `dir` unless `--allow-outside-materials` is given.
pub(super) fn confined_file(dir: &Path, file: &Path) -> std::io::Result<()> {
    if ALLOW_OUTSIDE_MATERIALS.load(Ordering::Relaxed) {
        return Ok(());
    }
    confined(dir, file)
}

/// Refuse `file` unless it resolves (symbolic links followed) inside `dir`.
fn confined(dir: &Path, file: &Path) -> std::io::Result<()> {
    let (d, f) = (dir.canonicalize()?, file.canonicalize()?);
    if f.starts_with(&d) {
        Ok(())
    } else {
        Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            format!(
                "it is outside the scene's folder {}; pass --allow-outside-materials to read it",
                shown_path(&d)
            ),
        ))
    }
}

/// The bytes of `path` if it is a regular file of at most `limit` bytes: a FIFO would block
/// forever and a device (`/dev/zero`) never ends.
pub(super) fn read_regular(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "it is a directory",
        ));
    }
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, FIFO or socket)",
        ));
    }
    if meta.len() > limit {
        return Err(too_large(limit));
    }
    let mut bytes = Vec::new();
    // The file may grow between the check and the read: read at most one byte past the limit.
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

fn too_large(limit: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidData,
        format!("larger than the limit of {} MiB", limit >> 20),
    )
}

/// The text of a scene file. Bytes that are not UTF-8 (a Latin-1 object name from an older
/// exporter) become U+FFFD rather than refusing the file: they can only be in names, and a
/// number they spoil fails its own check with its line. A byte-order mark is dropped.
pub(super) fn decode(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    String::from_utf8_lossy(bytes)
}

/// `s` with control characters escaped (`\u{1b}`, `\n`), for echoing names read from a file:
/// a raw escape sequence in an object name would drive the user's terminal.
pub fn shown(s: &str) -> String {
    if !s.chars().any(char::is_control) {
        return s.to_string();
    }
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Longest part of a line echoed in a message, characters.
const EXCERPT: usize = 80;

/// `s` for a message quoting a line of a file: escaped, and cut after [`EXCERPT`] characters
/// (a line may be a gigabyte long).
pub(super) fn excerpt(s: &str) -> String {
    match s.char_indices().nth(EXCERPT) {
        Some((i, _)) => format!("{}…", shown(&s[..i])),
        None => shown(s),
    }
}

/// A path for messages, control characters escaped.
pub fn shown_path(path: &Path) -> String {
    shown(&path.display().to_string())
}

/// The file name of `path` for short messages (`scene.mtl`), escaped.
pub(super) fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| shown(&n.to_string_lossy()))
        .unwrap_or_else(|| shown_path(path))
}
