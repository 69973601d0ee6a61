//! Files as a demanding user expects them: every output is written whole or not at all
//! (temporary file beside it, then one rename), every input a user names is a regular file
//! read within a stated bound (no `/dev/zero`, no FIFO that blocks forever), and an output
//! folder is held by one process at a time. Every error names the file.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// A file operation that failed, with the file it failed on.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", .path.display())]
pub struct FileError {
    pub path: PathBuf,
    pub message: String,
    /// True when the file itself is not acceptable (not a regular file, too large, in use):
    /// the user's input, not the machine, is at fault.
    pub refused: bool,
}

impl FileError {
    fn io(path: &Path, message: impl ToString) -> Self {
        FileError {
            path: path.to_path_buf(),
            message: message.to_string(),
            refused: false,
        }
    }

    fn refused(path: &Path, message: impl ToString) -> Self {
        FileError {
            refused: true,
            ..FileError::io(path, message)
        }
    }
}

/// The temporary name of `path` while it is written: `.NAME.HOST.PID.N.tmp` beside it (same
/// folder, so the final rename is atomic). Host, process and a per-process count make it
/// unique among every writer of a folder shared by several machines (shards filling one truth
/// cache, issue 20): two writers of the same file never share a temporary.
fn temporary_path(path: &Path) -> Result<PathBuf, FileError> {
    static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let file_name = path
        .file_name()
        .ok_or_else(|| FileError::refused(path, "not a file path"))?;
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| {
            h.trim()
                .chars()
                .filter(|c| c.is_ascii_alphanumeric() || *c == '-')
                .take(64)
                .collect::<String>()
        })
        .unwrap_or_default();
    let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(".{host}.{}.{n}.tmp", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

/// Runs `write` on `tmp` and flushes it to disk (data before name: a power cut leaves the
/// old file or the new one, never an empty one). Removes `tmp` on failure.
fn write_temporary(
    path: &Path,
    tmp: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), FileError> {
    let result = write(tmp).and_then(|()| {
        File::open(tmp)
            .and_then(|f| f.sync_all())
            .map_err(|e| e.to_string())
    });
    result.map_err(|message| {
        let _ = std::fs::remove_file(tmp);
        FileError::io(path, message)
    })
}

/// Runs `write` on a temporary path beside `path`, then renames it into place. On any error
/// the temporary file is removed and `path` is left as it was; a crash leaves at most a
/// `.NAME.PID.tmp` file, never a truncated `NAME`.
pub fn write_atomically_with(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), FileError> {
    let tmp = temporary_path(path)?;
    write_temporary(path, &tmp, write)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        FileError::io(path, e)
    })
}

/// Several outputs of one command, written all or none: each is staged under its temporary
/// name, and only when every one is written are they renamed into place. Dropped before
/// [`StagedFiles::commit`], it removes what it staged.
#[derive(Debug, Default)]
pub struct StagedFiles {
    staged: Vec<(PathBuf, PathBuf)>,
}

impl StagedFiles {
    pub fn new() -> Self {
        StagedFiles::default()
    }

    /// Writes `path`'s content (through `write`, given the temporary path) without showing it
    /// under its name yet.
    pub fn stage_with(
        &mut self,
        path: &Path,
        write: impl FnOnce(&Path) -> Result<(), String>,
    ) -> Result<(), FileError> {
        let tmp = temporary_path(path)?;
        write_temporary(path, &tmp, write)?;
        self.staged.push((tmp, path.to_path_buf()));
        Ok(())
    }

    /// Renames every staged file into place; returns their paths. A destination that is a
    /// folder is refused before any file is renamed (the files renamed before it had stayed,
    /// an export's meshes without its XML).
    pub fn commit(mut self) -> Result<Vec<PathBuf>, FileError> {
        if let Some((_, path)) = self.staged.iter().find(|(_, path)| path.is_dir()) {
            return Err(FileError::refused(
                path,
                "would be written as a file, but it is a folder",
            ));
        }
        let staged = std::mem::take(&mut self.staged);
        let mut done = Vec::with_capacity(staged.len());
        let mut pending = staged.into_iter();
        while let Some((tmp, path)) = pending.next() {
            if let Err(e) = std::fs::rename(&tmp, &path) {
                let _ = std::fs::remove_file(&tmp);
                for (tmp, _) in pending {
                    let _ = std::fs::remove_file(tmp);
                }
                return Err(FileError::io(&path, e));
            }
            done.push(path);
        }
        Ok(done)
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        for (tmp, _) in &self.staged {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Refuses, before anything is computed or written, a set of outputs of which one is a
/// folder or two name the same file (`-o a.exr --bounces a.exr`, or a PNG written beside an
/// EXR that another output names). With [`StagedFiles`], the outputs then appear together.
pub fn check_outputs(outputs: &[(&str, PathBuf)]) -> Result<(), FileError> {
    for (flag, path) in outputs {
        if path.is_dir() {
            return Err(FileError::refused(
                path,
                format!("{flag} would write this file, but it is a folder"),
            ));
        }
    }
    check_distinct(outputs)
}

/// The folder a file `path` is in: its parent, or `.` for a bare file name (whose parent is
/// the empty path).
pub fn folder_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `p` with its folder resolved (`..` and links), for telling whether two names write one
/// file; made absolute as it is where its folder does not exist.
pub fn in_resolved_folder(p: &Path) -> PathBuf {
    match (folder_of(p).canonicalize(), p.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()),
    }
}

/// The file `path` resolves to, for telling whether two names are one file: wholly
/// canonicalized (links and `..` resolved) where it exists, else [`in_resolved_folder`].
pub fn resolved(path: &Path) -> PathBuf {
    path.canonicalize()
        .unwrap_or_else(|_| in_resolved_folder(path))
}

/// Refuses a set of paths in which two name the same file.
pub fn check_distinct(outputs: &[(&str, PathBuf)]) -> Result<(), FileError> {
    // The folders exist (outputs are checked first).
    for (i, (flag_a, a)) in outputs.iter().enumerate() {
        for (flag_b, b) in &outputs[..i] {
            if in_resolved_folder(a) == in_resolved_folder(b) {
                return Err(FileError::refused(
                    a,
                    format!(
                        "{flag_a} and {flag_b} would both write this file; give them different names"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Removes `path` if it exists: a file an earlier run wrote that this one does not (a stale
/// figure, a screenshot's companion), which must not pass for a current one.
pub fn remove_stale(path: &Path) -> Result<(), FileError> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(FileError::io(
            path,
            format!("could not remove the stale file: {e}"),
        )),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` atomically ([`write_atomically_with`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomically_with(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|e| e.to_string())
    })
}

/// Reads the regular file at `path`, refusing anything else (a device such as `/dev/zero`, a
/// FIFO, a folder) and any file larger than `max_bytes` — before reading a byte of it.
/// `what` names the file's role in messages ("scene file", "OBJ file").
pub fn read_bounded(path: &Path, max_bytes: u64, what: &str) -> Result<Vec<u8>, FileError> {
    let file = open_regular(path, max_bytes, what)?;
    let cannot = |e: std::io::Error| FileError::io(path, format!("cannot read {what}: {e}"));
    // The file may grow after the check: never read past the bound.
    let len = file.metadata().map_err(cannot)?.len();
    let mut bytes = Vec::with_capacity(len.min(max_bytes) as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(path, bytes.len() as u64, max_bytes, what));
    }
    Ok(bytes)
}

/// Opens `path` for reading if it is a regular file of at most `max_bytes`; refuses anything
/// else (a device such as `/dev/zero`, a FIFO, a folder) before reading a byte. The file is
/// opened non-blocking and checked *as opened*, so a FIFO swapped in after a check can
/// neither block nor slip through.
pub fn open_regular(path: &Path, max_bytes: u64, what: &str) -> Result<File, FileError> {
    use std::os::unix::fs::OpenOptionsExt;
    const O_NONBLOCK: i32 = 0o4000; // Linux, every architecture Rust targets there
    let cannot = |e: std::io::Error| FileError::io(path, format!("cannot read {what}: {e}"));
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(O_NONBLOCK)
        .open(path)
        .map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    if !meta.is_file() {
        return Err(FileError::refused(
            path,
            format!("{what} must be a regular file, not {}", kind_of(&meta)),
        ));
    }
    if meta.len() > max_bytes {
        return Err(too_large(path, meta.len(), max_bytes, what));
    }
    Ok(file)
}

fn too_large(path: &Path, size: u64, max_bytes: u64, what: &str) -> FileError {
    FileError::refused(
        path,
        format!(
            "{what} is {}, more than the {} accepted",
            human_bytes(size),
            human_bytes(max_bytes)
        ),
    )
}

/// [`read_bounded`] for text: the file must be UTF-8.
pub fn read_bounded_text(path: &Path, max_bytes: u64, what: &str) -> Result<String, FileError> {
    String::from_utf8(read_bounded(path, max_bytes, what)?).map_err(|e| {
        FileError::refused(
            path,
            format!(
                "{what} is not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

/// `out/x.exr` → `out/x_left.exr`: `suffix` joined to the file's stem with `_`, the extension
/// kept (a stereo eye's name, `sbs`, `anaglyph`).
pub fn with_stem_suffix(path: &Path, suffix: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!("{stem}_{suffix}.{}", ext.to_string_lossy()),
        None => format!("{stem}_{suffix}"),
    };
    path.with_file_name(name)
}

/// `n` bytes in the largest binary unit it reaches (KiB, MiB, GiB, TiB) and that unit; `None`
/// below 1 KiB. The one table of [`human_bytes`] and the memory plans' `format_bytes`.
pub fn binary_unit(n: u64) -> Option<(f64, &'static str)> {
    const UNITS: [(&str, u64); 4] = [
        ("TiB", 1 << 40),
        ("GiB", 1 << 30),
        ("MiB", 1 << 20),
        ("KiB", 1 << 10),
    ];
    UNITS
        .iter()
        .find(|(_, size)| n >= *size)
        .map(|&(unit, size)| (n as f64 / size as f64, unit))
}

/// `1.5 GiB`, `35.2 KiB`, `12 bytes`: binary units, as `--memory-budget` reads them
/// (`2G` is 2 GiB) and the plans' estimates and the reports' memory columns print them, so
/// that one output never mixes the two kinds.
pub fn human_bytes(n: u64) -> String {
    match binary_unit(n) {
        Some((v, unit)) => format!("{v:.1} {unit}"),
        None => format!("{n} bytes"),
    }
}

/// An output folder held by this process: the advisory lock on `DIR/.mirrorbox.lock`
/// (`flock`), released when this value is dropped or the process dies — a killed sweep never
/// leaves a stale lock behind.
#[derive(Debug)]
pub struct FolderLock {
    file: File,
    path: PathBuf,
}

/// Unlocks explicitly before the file closes: a `flock` belongs to the open file description,
/// which a child forked at that moment shares until its `exec` closes it — closing our copy
/// alone could leave the folder locked for that instant (seen in the hardening tests, whose
/// other tests spawn processes all the time).
impl Drop for FolderLock {
    fn drop(&mut self) {
        let _ = self.file.unlock();
    }
}

/// The lock file's name inside a locked folder.
pub const LOCK_FILE: &str = ".mirrorbox.lock";

impl FolderLock {
    /// Takes the folder's lock, or refuses at once (naming the process that holds it) when
    /// another process has it. The folder must exist.
    pub fn try_acquire(dir: &Path) -> Result<FolderLock, FileError> {
        let path = dir.join(LOCK_FILE);
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| FileError::io(&path, format!("cannot create the lock file: {e}")))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                let who = if holder.is_empty() {
                    "another process".to_string()
                } else {
                    format!("another process ({holder})")
                };
                return Err(FileError::refused(
                    dir,
                    format!(
                        "this folder is in use by {who}; wait for it to finish or choose another output folder"
                    ),
                ));
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(FileError::io(&path, format!("cannot lock: {e}")));
            }
        }
        use std::io::{Seek, Write};
        let _ = file.set_len(0);
        let _ = file.seek(std::io::SeekFrom::Start(0));
        let _ = writeln!(file, "pid {}", std::process::id());
        Ok(FolderLock { file, path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writers racing on one file (shards filling one truth cache): the file ends as one
    /// writer's bytes, whole, and no temporary is left.
    #[test]
    fn concurrent_writers_of_one_file_never_mix() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.exr");
        std::thread::scope(|s| {
            for k in 0u8..8 {
                let path = &path;
                s.spawn(move || {
                    for _ in 0..20 {
                        write_atomically(path, &vec![k; 64 * 1024]).unwrap();
                    }
                });
            }
        });
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 64 * 1024);
        assert!(bytes.iter().all(|&b| b == bytes[0]), "mixed writers");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "a temporary was left");
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.md");
        write_atomically(&path, b"old").unwrap();
        let err = write_atomically_with(&path, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err("disk full".into())
        })
        .unwrap_err();
        assert!(err.to_string().contains("report.md") && err.to_string().contains("disk full"));
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "the temporary file must be gone");
    }

    #[test]
    fn special_files_and_large_files_are_refused_before_reading() {
        for (path, kind) in [("/dev/zero", "character device"), ("/", "folder")] {
            let e = read_bounded(Path::new(path), 1 << 20, "OBJ file").unwrap_err();
            assert!(e.refused && e.message.contains(kind), "{e}");
        }
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            // Would block forever if opened.
            let e = read_bounded(&fifo, 1 << 20, "OBJ file").unwrap_err();
            assert!(e.message.contains("FIFO"), "{e}");
        }
        let big = dir.path().join("big.obj");
        std::fs::write(&big, vec![b'#'; 101]).unwrap();
        let e = read_bounded(&big, 100, "OBJ file").unwrap_err();
        assert!(e.refused && e.message.contains("101 bytes"), "{e}");
        assert_eq!(read_bounded(&big, 101, "OBJ file").unwrap().len(), 101);
    }

    #[test]
    fn a_folder_is_held_by_one_lock_at_a_time() {
        let dir = tempfile::tempdir().unwrap();
        let first = FolderLock::try_acquire(dir.path()).unwrap();
        let second = FolderLock::try_acquire(dir.path()).unwrap_err();
        assert!(second.refused, "{second}");
        assert!(
            second
                .message
                .contains(&format!("pid {}", std::process::id())),
            "{second}"
        );
        drop(first);
        FolderLock::try_acquire(dir.path()).expect("free again once released");
    }

    #[test]
    fn staged_files_appear_together_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        let mut staged = StagedFiles::new();
        staged
            .stage_with(&a, |t| std::fs::write(t, "a").map_err(|e| e.to_string()))
            .unwrap();
        assert!(!a.exists(), "not visible before commit");
        let e = staged
            .stage_with(&b, |_| Err("disk full".into()))
            .unwrap_err();
        assert!(e.to_string().contains("b.exr"));
        drop(staged);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "nothing left"
        );

        let mut staged = StagedFiles::new();
        for p in [&a, &b] {
            staged
                .stage_with(p, |t| std::fs::write(t, "x").map_err(|e| e.to_string()))
                .unwrap();
        }
        assert_eq!(staged.commit().unwrap(), vec![a.clone(), b.clone()]);
        assert!(a.is_file() && b.is_file());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);

        // A destination that is a folder: refused before any file is renamed.
        let (c, d) = (dir.path().join("c.obj"), dir.path().join("d.json"));
        std::fs::create_dir(&d).unwrap();
        let mut staged = StagedFiles::new();
        for p in [&c, &d] {
            staged
                .stage_with(p, |t| std::fs::write(t, "x").map_err(|e| e.to_string()))
                .unwrap();
        }
        let e = staged.commit().unwrap_err();
        assert!(e.refused && e.to_string().contains("d.json"), "{e}");
        assert!(!c.exists(), "renamed before the refusal");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            3,
            "a, b, d/"
        );
    }

    #[test]
    fn colliding_outputs_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("sub")).unwrap();
        let distinct = [
            ("-o", d.join("a.exr")),
            ("-o (its PNG)", d.join("a.png")),
            ("--bounces", d.join("sub/a.exr")),
        ];
        assert!(check_outputs(&distinct).is_ok());
        let folder = [("-o (its PNG)", d.join("sub"))];
        let e = check_outputs(&folder).unwrap_err();
        assert!(e.refused && e.message.contains("is a folder"), "{e}");
        let same = [
            ("-o", d.join("a.exr")),
            ("--bounces", d.join("sub/../a.exr")),
        ];
        let e = check_distinct(&same).unwrap_err();
        assert!(e.refused && e.message.contains("--bounces and -o"), "{e}");
    }

    #[test]
    fn sizes_read_as_people_say_them() {
        assert_eq!(human_bytes(12), "12 bytes");
        assert_eq!(human_bytes(36_000), "35.2 KiB");
        assert_eq!(human_bytes(34_359_738_368), "32.0 GiB");
        assert_eq!(human_bytes(1023), "1023 bytes");
        assert_eq!(human_bytes(1024), "1.0 KiB");
    }
}
