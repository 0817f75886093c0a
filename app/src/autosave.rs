//! Autosave: a few seconds after the tree changes, the tree (and, for recorded footage, the
//! session that replays to it) is written next to the session file, atomically and durably
//! ([`sylva_core::safe_write`]). A crash, a killed app or a dead battery loses at most the
//! last few seconds of design, never the tree.
//!
//! Starting the window never erases an earlier autosave: [`Autosaver::keep_previous`] rotates
//! it to `<stem>.1.tree.json` (and `.1.tree.placement.json`, `.1.json`), the one before to
//! `.2`, up to [`NUM_KEPT_AUTOSAVES`], and the window offers to restore `.1` ([`restore_prompt_ui`], or
//! `sylva view --restore`). Nothing is written before the design changes, so opening and
//! closing the window leaves the earlier autosaves as they were. SIGTERM, SIGINT and SIGHUP
//! close the window as its close button does ([`exit_on_signals`]), which flushes the autosave.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use sylva_core::Tree;

use crate::player::Placement;
use crate::session::Session;
use crate::state::{DesignState, InputEvent};

/// Time between autosaves while the tree keeps changing.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(5);

/// Earlier autosaves kept (`.1` the latest).
pub const NUM_KEPT_AUTOSAVES: usize = 3;

/// Largest tree file restored, bytes (a 300 000-internode tree is about 130 MB).
const MAX_TREE_FILE_BYTES: u64 = 1 << 30;

/// Writes the design when it changed and the interval has passed.
pub struct Autosaver {
    tree_path: PathBuf,
    session_path: Option<PathBuf>,
    /// Where the session file lies (saved by the window on closing even when not autosaved).
    session_file: PathBuf,
    interval: Duration,
    saved_revision: Option<u64>,
    last_save: Option<Instant>,
}

/// An earlier autosave the window offers back.
#[derive(Clone, Debug, PartialEq)]
pub struct PreviousAutosave {
    pub tree_path: PathBuf,
    /// Internodes and age of its tree, for the prompt.
    pub num_internodes: usize,
    pub age_years: f32,
}

impl Autosaver {
    /// Autosaves the tree as `<session stem>.tree.json` beside `session_path`, and the session
    /// itself when `save_session` (a live stream's session waits for its recording to finish).
    pub fn new(session_path: &Path, save_session: bool, interval: Duration) -> Autosaver {
        Autosaver {
            tree_path: session_path.with_extension("tree.json"),
            session_path: save_session.then(|| session_path.to_owned()),
            session_file: session_path.to_owned(),
            interval,
            saved_revision: None,
            last_save: None,
        }
    }

    pub fn tree_path(&self) -> &Path {
        &self.tree_path
    }

    /// The files of autosave `generation` (0 the current one, 1 the latest earlier one):
    /// tree, placement, session.
    pub fn files(&self, generation: usize) -> [PathBuf; 3] {
        let stem = self.session_file.with_extension("");
        let name = |suffix: &str| {
            let mut s = stem.as_os_str().to_owned();
            if generation > 0 {
                s.push(format!(".{generation}"));
            }
            s.push(suffix);
            PathBuf::from(s)
        };
        [
            name(".tree.json"),
            name(".tree.placement.json"),
            name(".json"),
        ]
    }

    /// Call once on start, before anything is saved: moves the current autosave to `.1` (and
    /// `.1` to `.2`, …, the oldest beyond [`NUM_KEPT_AUTOSAVES`] dropped), and treats `design`
    /// as saved (nothing is written until it changes). Returns the latest earlier autosave, if
    /// one loads.
    pub fn keep_previous(
        &mut self,
        design: &DesignState,
    ) -> anyhow::Result<Option<PreviousAutosave>> {
        self.saved_revision = Some(design.revision);
        if self.files(0)[0].exists() {
            for generation in (0..NUM_KEPT_AUTOSAVES).rev() {
                let from = self.files(generation);
                let to = self.files(generation + 1);
                // The oldest kept is replaced by the one after it.
                for (from, to) in from.iter().zip(&to) {
                    if from.exists() {
                        std::fs::rename(from, to).with_context(|| {
                            format!("cannot keep {} as {}", from.display(), to.display())
                        })?;
                    }
                }
            }
        }
        let tree_path = self.files(1)[0].clone();
        if !tree_path.exists() {
            return Ok(None);
        }
        match load_tree_file(&tree_path) {
            Ok(tree) => Ok(Some(PreviousAutosave {
                tree_path,
                num_internodes: tree.skeleton.len(),
                age_years: tree.age_years(),
            })),
            Err(e) => {
                eprintln!("warning: the earlier autosave cannot be restored: {e:#}");
                Ok(None)
            }
        }
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
        // A garden goes beside it, whole (the tree file is its selected tree).
        let garden_path = self.session_file.with_extension("garden.json");
        crate::garden_view::write_garden(design, &garden_path)?;
        if let Some(path) = &self.session_path {
            session.save(path)?;
        }
        Ok(())
    }
}

fn load_tree_file(path: &Path) -> anyhow::Result<Tree> {
    let bytes = sylva_tracking::input_file::read_regular_file(path, MAX_TREE_FILE_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok(Tree::from_json_bytes_named(
        &bytes,
        &path.display().to_string(),
    )?)
}

/// The tree of a [`InputEvent::RestoreTree`] (a tree file's JSON), validated.
pub fn parse_restored_tree(tree_file: &str) -> Result<Tree, String> {
    Tree::from_json_bytes_named(tree_file.as_bytes(), "the restored tree")
        .map_err(|e| e.to_string())
}

/// The event restoring the autosaved tree at `tree_path` and its placement beside it.
pub fn restore_event(tree_path: &Path) -> anyhow::Result<InputEvent> {
    let tree = load_tree_file(tree_path)?;
    let placement_path = tree_path.with_extension("placement.json");
    let world_from_tree = match std::fs::read_to_string(&placement_path) {
        Ok(text) => {
            serde_json::from_str::<Placement>(&text)
                .with_context(|| format!("{} is not a placement file", placement_path.display()))?
                .world_from_tree
        }
        Err(_) => None,
    };
    Ok(InputEvent::RestoreTree {
        tree_file: String::from_utf8(tree.to_json_bytes()?)?,
        world_from_tree,
    })
}

/// The prompt offering an earlier autosave back: "Restore" sends the restore event, "Dismiss"
/// (or restoring) closes it.
pub fn restore_prompt_ui(
    ui: &mut egui::Ui,
    offer: &mut Option<PreviousAutosave>,
    events: &mut Vec<InputEvent>,
) {
    let Some(previous) = offer.as_ref() else {
        return;
    };
    let mut close = false;
    egui::Window::new("Earlier design")
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_TOP, [0.0, 60.0])
        .show(ui.ctx(), |ui| {
            ui.label(format!(
                "An earlier design was autosaved: {} internodes, {:.0} years ({}).",
                previous.num_internodes,
                previous.age_years,
                previous.tree_path.display()
            ));
            ui.horizontal(|ui| {
                if ui.button("Restore").clicked() {
                    match restore_event(&previous.tree_path) {
                        Ok(event) => events.push(event),
                        Err(e) => eprintln!("warning: {e:#}"),
                    }
                    close = true;
                }
                if ui.button("Dismiss").clicked() {
                    close = true;
                }
            });
        });
    if close {
        *offer = None;
    }
}

static EXIT_REQUESTED: AtomicBool = AtomicBool::new(false);

/// From now on SIGTERM, SIGINT and SIGHUP only ask the window to close ([`exit_requested`]),
/// which then flushes the autosave and saves the session as closing it does.
pub fn exit_on_signals() {
    #[cfg(unix)]
    {
        extern "C" fn on_signal(_: libc::c_int) {
            EXIT_REQUESTED.store(true, Ordering::SeqCst);
        }
        let handler = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
        for signal in [libc::SIGTERM, libc::SIGINT, libc::SIGHUP] {
            // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
            unsafe {
                libc::signal(signal, handler);
            }
        }
    }
}

/// Whether a signal asked the app to close.
pub fn exit_requested() -> bool {
    EXIT_REQUESTED.load(Ordering::SeqCst)
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
    fn each_start_keeps_the_earlier_autosaves_rotated_and_offers_the_latest() {
        let dir = tempfile::tempdir().expect("temp dir");
        let session_path = dir.path().join("last-session.json");
        let (mut design, session) = design();
        let mut revisions = Vec::new();
        for start in 0..5u64 {
            let mut saver = Autosaver::new(&session_path, true, Duration::ZERO);
            let offer = saver.keep_previous(&design).expect("rotate");
            assert_eq!(offer.is_some(), start > 0, "start {start}: {offer:?}");
            assert!(
                !saver.poll(Instant::now(), &design, &session).expect("poll"),
                "nothing is written before the design changes"
            );
            design.revision += 1;
            design.tree.grow(1, None);
            saver.flush(&design, &session).expect("flush");
            revisions.push(design.tree.iteration);
        }
        // The current autosave, then the three before it, newest first.
        let saver = Autosaver::new(&session_path, true, Duration::ZERO);
        for generation in 0..=NUM_KEPT_AUTOSAVES {
            let [tree, placement, session] = saver.files(generation);
            let kept = Tree::load(&tree).expect("kept tree");
            assert_eq!(
                kept.iteration,
                revisions[4 - generation],
                "generation {generation}"
            );
            assert!(
                placement.exists() && session.exists(),
                "generation {generation}"
            );
        }
        assert!(
            !saver.files(NUM_KEPT_AUTOSAVES + 1)[0].exists(),
            "the oldest dropped"
        );
        let event = restore_event(&saver.files(1)[0]).expect("restorable");
        let mut restored = DesignState::new(7, Parameters::default());
        restored.apply(&event);
        assert_eq!(restored.tree.iteration, revisions[3]);
        restored.apply(&InputEvent::Undo);
        assert_eq!(restored.tree.iteration, 1, "restoring is undoable");
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
