//! Where a shell keeps its work: sessions, the camera frames recorded with them, and the
//! autosaved tree (app storage on a phone: Android's `filesDir`, iOS's Documents folder).

use std::path::{Path, PathBuf};

use anyhow::Context;

/// A folder the app may write; each run of the app records into a new `session-NNN` folder in
/// it (a TUM-layout recording of the frames shown with `session.json`, and the autosaved
/// `session.tree.json` beside it), which `sylva replay` opens on a desktop.
#[derive(Clone, Debug, PartialEq)]
pub struct StorageLocation {
    root: PathBuf,
}

impl StorageLocation {
    pub fn new(root: impl Into<PathBuf>) -> StorageLocation {
        StorageLocation { root: root.into() }
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    /// A new session folder (the first `session-NNN` not yet there), created.
    pub fn new_session_dir(&self) -> anyhow::Result<PathBuf> {
        std::fs::create_dir_all(&self.root)
            .with_context(|| format!("cannot create the app storage {}", self.root.display()))?;
        for n in 0..100_000u32 {
            let dir = self.root.join(format!("session-{n:03}"));
            match std::fs::create_dir(&dir) {
                Ok(()) => return Ok(dir),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => {
                    return Err(e).with_context(|| format!("cannot create {}", dir.display()));
                }
            }
        }
        anyhow::bail!("{} holds too many sessions", self.root.display())
    }

    /// The session file of a session folder.
    pub fn session_path(session_dir: &Path) -> PathBuf {
        session_dir.join("session.json")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_run_gets_a_new_session_folder() {
        let dir = tempfile::tempdir().expect("temp dir");
        let storage = StorageLocation::new(dir.path().join("files"));
        let first = storage.new_session_dir().expect("first");
        let second = storage.new_session_dir().expect("second");
        assert_eq!(first, dir.path().join("files/session-000"));
        assert_eq!(second, dir.path().join("files/session-001"));
        assert_eq!(
            StorageLocation::session_path(&first),
            first.join("session.json")
        );
        let blocked = StorageLocation::new(first.join("session.json/x"));
        std::fs::write(first.join("session.json"), "{}").expect("write");
        let error = blocked.new_session_dir().expect_err("a file in the way");
        assert!(
            format!("{error}").contains("cannot create the app storage"),
            "{error}"
        );
    }
}
