//! Autosave: a few seconds after the tree changes, the tree (and, for recorded footage, the
//! session that replays to it) is written next to the session file, atomically (a temporary
//! file renamed over the old one). A crash, a killed app or a dead battery loses at most the
//! last few seconds of design, never the tree.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;

use crate::session::Session;
use crate::state::DesignState;

/// Time between autosaves while the tree keeps changing.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(5);

/// Writes the design when it changed and the interval has passed.
pub struct Autosaver {
    tree_path: PathBuf,
    session_path: Option<PathBuf>,
    interval: Duration,
    saved_revision: Option<u64>,
    last_save: Option<Instant>,
}

impl Autosaver {
    /// Autosaves the tree as `<session stem>.tree.json` beside `session_path`, and the session
    /// itself when `save_session` (a live stream's session waits for its recording to finish).
    pub fn new(session_path: &Path, save_session: bool, interval: Duration) -> Autosaver {
        Autosaver {
            tree_path: session_path.with_extension("tree.json"),
            session_path: save_session.then(|| session_path.to_owned()),
            interval,
            saved_revision: None,
            last_save: None,
        }
    }

    pub fn tree_path(&self) -> &Path {
        &self.tree_path
    }

    /// Saves when the tree changed since the last save and `interval` has passed since then.
    /// Returns whether it saved.
    pub fn poll(
        &mut self,
        now: Instant,
        design: &DesignState,
        session: &Session,
    ) -> anyhow::Result<bool> {
        let changed = self.saved_revision != Some(design.revision);
        let due = self
            .last_save
            .is_none_or(|t| now.duration_since(t) >= self.interval);
        if !changed || !due {
            return Ok(false);
        }
        self.save(design, session)?;
        self.saved_revision = Some(design.revision);
        self.last_save = Some(now);
        Ok(true)
    }

    /// Saves now if anything changed since the last save (on closing).
    pub fn flush(&mut self, design: &DesignState, session: &Session) -> anyhow::Result<()> {
        if self.saved_revision != Some(design.revision) {
            self.save(design, session)?;
            self.saved_revision = Some(design.revision);
        }
        Ok(())
    }

    fn save(&self, design: &DesignState, session: &Session) -> anyhow::Result<()> {
        if let Some(parent) = self
            .tree_path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
        {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create {}", parent.display()))?;
        }
        design
            .tree
            .save(&self.tree_path)
            .with_context(|| format!("cannot autosave the tree to {}", self.tree_path.display()))?;
        // The tree file is in tree space; where it stands goes beside it.
        crate::player::write_placement(design, &self.tree_path.with_extension("placement.json"))?;
        if let Some(path) = &self.session_path {
            session.save(path)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::Parameters;
    use sylva_core::Tree;

    fn design() -> (DesignState, Session) {
        let design = DesignState::new(7, Parameters::default());
        let session = Session::new(PathBuf::from("footage"), 7, Parameters::default());
        (design, session)
    }

    #[test]
    fn a_changed_tree_is_saved_once_per_interval_and_reloads_identically() {
        let dir = tempfile::tempdir().expect("temp dir");
        let session_path = dir.path().join("work.json");
        let mut saver = Autosaver::new(&session_path, true, Duration::from_secs(5));
        let (mut design, session) = design();
        let t0 = Instant::now();
        assert!(
            saver.poll(t0, &design, &session).expect("save"),
            "first change saves"
        );
        assert_eq!(saver.tree_path(), dir.path().join("work.tree.json"));
        let saved = Tree::load(saver.tree_path()).expect("autosaved tree loads");
        assert_eq!(
            serde_json::to_string(&saved).expect("json"),
            serde_json::to_string(&design.tree).expect("json")
        );
        assert!(
            Session::load(&session_path).is_ok(),
            "the session is saved too"
        );

        design.revision += 1;
        assert!(
            !saver
                .poll(t0 + Duration::from_secs(1), &design, &session)
                .expect("poll"),
            "not before the interval"
        );
        assert!(
            saver
                .poll(t0 + Duration::from_secs(6), &design, &session)
                .expect("save")
        );
        assert!(
            !saver
                .poll(t0 + Duration::from_secs(20), &design, &session)
                .expect("poll"),
            "nothing changed"
        );
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .expect("dir")
            .filter_map(|e| e.ok())
            .filter(|e| sylva_core::safe_write::is_temp_name(&e.file_name().to_string_lossy()))
            .collect();
        assert!(leftovers.is_empty(), "no temporary files left");
    }

    #[test]
    fn closing_saves_what_the_interval_held_back_and_a_live_session_is_not_written() {
        let dir = tempfile::tempdir().expect("temp dir");
        let session_path = dir.path().join("live.json");
        let mut saver = Autosaver::new(&session_path, false, Duration::from_secs(5));
        let (mut design, session) = design();
        let t0 = Instant::now();
        saver.poll(t0, &design, &session).expect("save");
        design.revision += 1;
        saver
            .poll(t0 + Duration::from_millis(10), &design, &session)
            .expect("poll");
        let before = std::fs::metadata(saver.tree_path())
            .expect("tree")
            .modified()
            .ok();
        saver.flush(&design, &session).expect("flush");
        assert_eq!(saver.saved_revision, Some(design.revision));
        assert!(before.is_some());
        assert!(
            !session_path.exists(),
            "a live session waits for its recording"
        );
    }

    #[test]
    fn an_unwritable_place_is_an_error_naming_it() {
        let dir = tempfile::tempdir().expect("temp dir");
        let blocker = dir.path().join("file");
        std::fs::write(&blocker, b"x").expect("write");
        let mut saver = Autosaver::new(&blocker.join("s.json"), false, Duration::ZERO);
        let (design, session) = design();
        let error = saver
            .poll(Instant::now(), &design, &session)
            .expect_err("cannot write under a file");
        assert!(format!("{error:#}").contains("file"), "{error:#}");
    }
}
