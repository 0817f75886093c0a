//! The app's files on disk: every file it writes goes through [`sylva_core::safe_write`]
//! (a temporary beside the target, fsynced, renamed over it, the folder fsynced), and a
//! command's outputs are checked against its inputs and each other before it runs.

use std::path::Path;

use anyhow::{Context, bail};
use sylva_core::safe_write;

/// Writes `bytes` to `path` atomically and durably; the error names the file.
pub fn write_file(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    safe_write::write_file(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Encodes `image` as PNG (the bytes `image.save` writes) and writes it atomically.
pub fn write_png<P>(
    image: &image::ImageBuffer<P, Vec<P::Subpixel>>,
    path: &Path,
) -> anyhow::Result<()>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
{
    let bytes = sylva_core::geometry::textures::png_bytes(image)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    write_file(path, &bytes)
}

/// Refuses, before a command runs, an output that is one of its inputs, two outputs naming one
/// file, and outputs that are not regular writable files.
pub fn check_outputs(inputs: &[&Path], outputs: &[&Path]) -> anyhow::Result<()> {
    safe_write::check_distinct(inputs, outputs)?;
    Ok(())
}

/// Whether `name` is a file `sylva replay` writes into its `--out` folder.
pub fn is_replay_output(name: &str) -> bool {
    let frame = name
        .strip_prefix("frame_")
        .and_then(|rest| rest.strip_suffix(".png"))
        .is_some_and(|digits| digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit()));
    frame
        || matches!(
            name,
            "tree.json" | "tree.glb" | "placement.json" | "garden.json" | "garden.placement.json"
        )
        || safe_write::is_temp_name(name)
}

/// Readies `out` for a replay: created when missing; a folder holding anything is refused
/// unless `force`, and then only the files a replay writes (frames, tree, placement, stale
/// temporaries) are removed, so no frame of an earlier replay is left beside the new ones.
pub fn prepare_replay_folder(out: &Path, force: bool) -> anyhow::Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("--out {} is not a folder", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let entries: Vec<_> = std::fs::read_dir(out)
        .with_context(|| format!("cannot read {}", out.display()))?
        .collect::<Result<_, _>>()
        .with_context(|| format!("cannot read {}", out.display()))?;
    if entries.is_empty() {
        return Ok(());
    }
    if !force {
        bail!(
            "--out {} is not empty ({} entries): replay into an empty folder, or pass --force to remove the frames, tree and placement an earlier replay left there",
            out.display(),
            entries.len()
        );
    }
    for entry in entries {
        let name = entry.file_name();
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && name.to_str().is_some_and(is_replay_output) {
            let path = entry.path();
            std::fs::remove_file(&path)
                .with_context(|| format!("cannot remove {}", path.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_non_empty_folder_is_refused_and_forced_clears_only_replay_files() {
        let dir = tempfile::tempdir().expect("dir");
        let out = dir.path().join("out");
        prepare_replay_folder(&out, false).expect("a new folder");
        for name in ["frame_0000.png", "frame_0059.png", "tree.json", "notes.txt"] {
            std::fs::write(out.join(name), b"x").expect("write");
        }
        let error = prepare_replay_folder(&out, false).expect_err("not empty");
        assert!(format!("{error:#}").contains("--force"), "{error:#}");
        assert!(out.join("frame_0059.png").exists(), "nothing removed");
        prepare_replay_folder(&out, true).expect("forced");
        let left: Vec<String> = std::fs::read_dir(&out)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(left, ["notes.txt"], "the user's file stays");
    }

    #[test]
    fn replay_outputs_are_recognised_by_name() {
        assert!(is_replay_output("frame_0012.png"));
        assert!(is_replay_output("frame_12345.png"));
        assert!(!is_replay_output("frame_12.png"));
        assert!(!is_replay_output("frame_abcd.png"));
        assert!(!is_replay_output("session.json"));
        assert!(is_replay_output(".tree.glb.77-0.sylva-tmp"));
    }
}
