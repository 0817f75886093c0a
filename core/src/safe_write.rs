//! Safe writes: every file Sylva writes for the user (trees, gardens, sessions, GLB, OBJ, MTL,
//! PNG, reports, autosaves) goes through [`write_file`] or [`write_file_with`].
//!
//! A write goes to a new, uniquely named temporary file in the target's folder
//! (`.<name>.<pid>-<n>.sylva-tmp`), which is flushed and fsynced, renamed over the target, and
//! then the folder is fsynced so the rename survives a power loss. A reader, a kill or a full
//! disk therefore leaves either the old whole file or the new whole file under the target's
//! name, never a part; the temporary is removed on any error. A temporary left by a killed
//! process is removed by the next write into that folder (on Linux, once its process is gone).
//!
//! Before anything is written, [`check_output`] refuses targets that are not regular files
//! (directories, devices, FIFOs, sockets) and read-only files, and [`check_distinct`] refuses a
//! command whose output is one of its inputs or whose outputs name one file twice. Both work on
//! the file itself (same device and inode on Unix, canonical path elsewhere), so `./a.json`,
//! `dir/../a.json`, hard and symbolic links are recognised.
//!
//! Standard library only: the core stays pure Rust and the app uses the same helper.

use std::collections::HashSet;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The suffix of Sylva's temporary files.
pub const TEMP_SUFFIX: &str = ".sylva-tmp";

/// Writes `bytes` to `path` atomically and durably (see the module doc).
pub fn write_file(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_file_with(path, |out| out.write_all(bytes))
}

/// Streams a file to `path` atomically and durably: `write` fills a buffered temporary file that
/// replaces `path` only once `write` returned `Ok` and the data is on disk.
pub fn write_file_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let target = resolve_target(path)?;
    check_output(&target)?;
    let dir = folder_of(&target);
    sweep_stale_temps_once(&dir);
    let name = target
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?
        .to_string_lossy()
        .into_owned();
    let (temp_path, file) = create_temp(&dir, &name)?;
    let temp = TempGuard(Some(temp_path));
    if let Ok(meta) = std::fs::metadata(&target) {
        // A replaced file keeps its permissions.
        file.set_permissions(meta.permissions())?;
    }
    let mut out = BufWriter::with_capacity(1 << 16, file);
    write(&mut out)?;
    let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
    file.sync_all()?;
    drop(file);
    let temp_path = temp.path().to_path_buf();
    std::fs::rename(&temp_path, &target)?;
    temp.disarm();
    sync_folder(&dir)
}

/// Refuses an output that exists and is not a regular file, or is read-only: Sylva replaces
/// only regular, writable files (a missing file is fine).
pub fn check_output(path: &Path) -> io::Result<()> {
    let meta = match std::fs::metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a regular file: refusing to replace it",
                path.display(),
                kind_of(&meta)
            ),
        ));
    }
    if meta.permissions().readonly() {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "{} is read-only: refusing to replace it (make it writable or choose another name)",
                path.display()
            ),
        ));
    }
    Ok(())
}

/// Why a command's files cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputConflict {
    #[error(
        "the output {output} is the input {input}: refusing to overwrite an input (choose another output name)"
    )]
    OutputIsInput { output: PathBuf, input: PathBuf },
    #[error("the outputs {first} and {second} name one file: choose two names")]
    SameOutputTwice { first: PathBuf, second: PathBuf },
    /// The reason names the file.
    #[error("{reason}")]
    Unwritable { path: PathBuf, reason: io::Error },
}

/// Checks a command's files before it runs: every output passes [`check_output`], no output is
/// one of `inputs`, and no two outputs are one file.
pub fn check_distinct(inputs: &[&Path], outputs: &[&Path]) -> Result<(), OutputConflict> {
    let inputs: Vec<(&Path, FileIdentity)> =
        inputs.iter().map(|p| (*p, FileIdentity::of(p))).collect();
    let mut seen: Vec<(&Path, FileIdentity)> = Vec::new();
    for &output in outputs {
        check_output(output).map_err(|reason| OutputConflict::Unwritable {
            path: output.to_path_buf(),
            reason,
        })?;
        let identity = FileIdentity::of(output);
        if let Some((input, _)) = inputs.iter().find(|(_, i)| i.same_file(&identity)) {
            return Err(OutputConflict::OutputIsInput {
                output: output.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
        if let Some((first, _)) = seen.iter().find(|(_, i)| i.same_file(&identity)) {
            return Err(OutputConflict::SameOutputTwice {
                first: first.to_path_buf(),
                second: output.to_path_buf(),
            });
        }
        seen.push((output, identity));
    }
    Ok(())
}

/// Whether `name` is one of Sylva's temporary files.
pub fn is_temp_name(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(TEMP_SUFFIX)
}

/// A file as the file system knows it: its canonical path (of the folder, for a file not there
/// yet) and, on Unix, its device and inode.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FileIdentity {
    path: PathBuf,
    device_inode: Option<(u64, u64)>,
}

impl FileIdentity {
    fn of(path: &Path) -> FileIdentity {
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| {
            let dir = folder_of(path);
            let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
            match path.file_name() {
                Some(name) => dir.join(name),
                None => dir,
            }
        });
        FileIdentity {
            path: canonical,
            device_inode: device_inode(path),
        }
    }

    fn same_file(&self, other: &FileIdentity) -> bool {
        match (self.device_inode, other.device_inode) {
            (Some(a), Some(b)) => a == b,
            _ => self.path == other.path,
        }
    }
}

#[cfg(unix)]
fn device_inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn device_inode(_path: &Path) -> Option<(u64, u64)> {
    None
}

fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// The folder holding `path` (`.` for a bare name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A symbolic link to an existing file is written through (the link stays a link).
fn resolve_target(path: &Path) -> io::Result<PathBuf> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => {
            Ok(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()))
        }
        _ => Ok(path.to_path_buf()),
    }
}

fn create_temp(dir: &Path, name: &str) -> io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let pid = std::process::id();
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = dir.join(format!(".{name}.{pid}-{n}{TEMP_SUFFIX}"));
        match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(file) => return Ok((path, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Removes its temporary file unless disarmed (after the rename).
struct TempGuard(Option<PathBuf>);

impl TempGuard {
    fn path(&self) -> &Path {
        self.0.as_deref().unwrap_or(Path::new(""))
    }

    fn disarm(mut self) {
        self.0 = None;
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(path) = self.0.take() {
            let _ = std::fs::remove_file(path);
        }
    }
}

#[cfg(unix)]
fn sync_folder(dir: &Path) -> io::Result<()> {
    File::open(dir)?.sync_all()
}

#[cfg(not(unix))]
fn sync_folder(_dir: &Path) -> io::Result<()> {
    // Windows cannot open a folder as a file; NTFS journals the rename.
    Ok(())
}

/// Once per folder and process: removes temporaries whose writing process is gone (killed
/// mid-write). Only where that can be told (Linux's `/proc`); elsewhere they are left, and
/// ignored, being hidden and never read.
fn sweep_stale_temps_once(dir: &Path) {
    static SWEPT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);
    let proc = Path::new("/proc/self");
    if !proc.exists() {
        return;
    }
    {
        let Ok(mut swept) = SWEPT.lock() else {
            return;
        };
        let key = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
        if !swept.get_or_insert_with(HashSet::new).insert(key) {
            return;
        }
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            continue;
        };
        if let Some(pid) = temp_writer_pid(name)
            && pid != std::process::id()
            && !Path::new("/proc").join(pid.to_string()).exists()
        {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The process id in a temporary's name `.<name>.<pid>-<n>.sylva-tmp`.
fn temp_writer_pid(name: &str) -> Option<u32> {
    if !is_temp_name(name) {
        return None;
    }
    let stem = &name[..name.len() - TEMP_SUFFIX.len()];
    let (_, tail) = stem.rsplit_once('.')?;
    let (pid, n) = tail.split_once('-')?;
    n.parse::<u64>().ok()?;
    pid.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temps_in(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .expect("dir")
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| is_temp_name(n))
            .collect()
    }

    #[test]
    fn a_write_replaces_the_file_whole_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("tree.json");
        write_file(&path, b"old").expect("write");
        write_file(&path, b"new contents").expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), b"new contents");
        assert!(temps_in(dir.path()).is_empty());
    }

    #[test]
    fn a_failing_writer_keeps_the_old_file_and_removes_its_temporary() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("t.glb");
        write_file(&path, b"old whole file").expect("write");
        let error = write_file_with(&path, |out| {
            out.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        })
        .expect_err("fails");
        assert!(error.to_string().contains("disk full"));
        assert_eq!(std::fs::read(&path).expect("read"), b"old whole file");
        assert!(
            temps_in(dir.path()).is_empty(),
            "{:?}",
            temps_in(dir.path())
        );
    }

    #[test]
    fn folders_fifos_devices_and_read_only_files_are_refused_by_name() {
        let dir = tempfile::tempdir().expect("dir");
        let error = write_file(dir.path(), b"x").expect_err("a folder");
        assert!(error.to_string().contains("a folder"), "{error}");
        let error = write_file(Path::new("/dev/null"), b"x").expect_err("a device");
        assert!(
            error.to_string().contains("/dev/null is a device"),
            "{error}"
        );
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let error = write_file(&fifo, b"x").expect_err("a FIFO");
            assert!(error.to_string().contains("a FIFO"), "{error}");
        }
        let locked = dir.path().join("locked.json");
        std::fs::write(&locked, b"keep").expect("write");
        let mut perms = std::fs::metadata(&locked).expect("meta").permissions();
        perms.set_readonly(true);
        std::fs::set_permissions(&locked, perms).expect("chmod");
        let error = write_file(&locked, b"x").expect_err("read-only");
        assert!(error.to_string().contains("read-only"), "{error}");
        assert_eq!(std::fs::read(&locked).expect("read"), b"keep");
        assert!(temps_in(dir.path()).is_empty());
    }

    #[test]
    fn an_output_naming_an_input_or_another_output_is_refused() {
        let dir = tempfile::tempdir().expect("dir");
        let species = dir.path().join("my.json");
        std::fs::write(&species, b"{}").expect("write");
        let via_dots = dir.path().join(".").join("sub/../my.json");
        std::fs::create_dir(dir.path().join("sub")).expect("mkdir");
        let error = check_distinct(&[&species], &[&via_dots]).expect_err("same file");
        assert!(
            matches!(error, OutputConflict::OutputIsInput { .. }),
            "{error}"
        );
        let link = dir.path().join("hard.json");
        std::fs::hard_link(&species, &link).expect("link");
        assert!(
            check_distinct(&[&species], &[&link]).is_err(),
            "a hard link"
        );

        let t = dir.path().join("t.json");
        let error = check_distinct(&[], &[&t, &dir.path().join("./t.json")]).expect_err("twice");
        assert!(error.to_string().contains("name one file"), "{error}");
        let other = dir.path().join("t.glb");
        check_distinct(&[&species], &[&t, &other]).expect("distinct files pass");
    }

    #[test]
    fn a_symbolic_link_is_written_through_and_stays_a_link() {
        let dir = tempfile::tempdir().expect("dir");
        let real = dir.path().join("real.json");
        std::fs::write(&real, b"old").expect("write");
        let link = dir.path().join("link.json");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&real, &link).expect("symlink");
            write_file(&link, b"new").expect("write");
            assert!(
                std::fs::symlink_metadata(&link)
                    .expect("meta")
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(std::fs::read(&real).expect("read"), b"new");
        }
    }

    #[test]
    fn a_temporary_of_a_dead_process_is_swept_and_a_live_ones_kept() {
        let dir = tempfile::tempdir().expect("dir");
        // Pid 2^31 - 2 exceeds any Linux pid_max: that process is gone.
        let dead = dir.path().join(format!(".t.glb.2147483646-0{TEMP_SUFFIX}"));
        let live = dir
            .path()
            .join(format!(".t.glb.{}-999{TEMP_SUFFIX}", std::process::id()));
        std::fs::write(&dead, b"part").expect("write");
        std::fs::write(&live, b"part").expect("write");
        assert_eq!(
            temp_writer_pid(&dead.file_name().unwrap().to_string_lossy()),
            Some(2147483646)
        );
        write_file(&dir.path().join("t.glb"), b"whole").expect("write");
        if Path::new("/proc/self").exists() {
            assert!(!dead.exists(), "the killed writer's temporary is removed");
        }
        assert!(live.exists(), "a running writer's temporary is left alone");
    }
}
