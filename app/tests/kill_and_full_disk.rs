//! Faults while saving: the real `sylva` binary is killed (SIGKILL) at 20 staggered points
//! across `grow --glb --obj` and `replay`, and run against a full disk (`RLIMIT_FSIZE`, so a
//! write fails with EFBIG as on a full tmpfs, without root). Every file under an output name
//! must be the old whole file or the new whole file (compared byte for byte with an
//! uninterrupted run, and parsed), never a part; the only temporaries left are those of the
//! killed process, and the next run removes them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use sylva_core::Tree;
use sylva_core::safe_write::is_temp_name;

const GROW_NAMES: [&str; 6] = [
    "t.json",
    "t.glb",
    "t.obj",
    "t.mtl",
    "t_bark.png",
    "t_leaf.png",
];
const NUM_KILLS_PER_COMMAND: u32 = 10;
const REPLAY_FRAMES: usize = 24;

fn sylva() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sylva"));
    command.env("RUST_BACKTRACE", "0");
    command
}

fn grow_args(years: &str) -> Vec<String> {
    [
        "grow",
        "--species",
        "oak",
        "--years",
        years,
        "--out",
        "t.json",
        "--glb",
        "t.glb",
        "--obj",
        "t.obj",
    ]
    .map(String::from)
    .to_vec()
}

fn run_in(dir: &Path, args: &[String]) -> Output {
    let output = sylva()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sylva runs");
    assert!(
        output.status.success(),
        "sylva {args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// The files of `dir` that are not temporaries, by name.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry"))
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| !is_temp_name(name))
        .map(|name| {
            let bytes = std::fs::read(dir.join(&name)).expect("read");
            (name, bytes)
        })
        .collect()
}

/// The writer pids of the temporaries in `dir`.
fn temp_pids(dir: &Path) -> Vec<u32> {
    std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|name| is_temp_name(name))
        .map(|name| {
            let tail = name.rsplit_once('.').expect("suffix").0;
            let pid = tail.rsplit_once('.').expect("pid").1;
            pid.split_once('-').expect("n").0.parse().expect("pid")
        })
        .collect()
}

/// Runs `args` in `dir` and SIGKILLs it after `after`; returns its pid (None if it ended first).
fn run_and_kill(dir: &Path, args: &[String], after: Duration) -> Option<u32> {
    let mut child = sylva()
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("sylva starts");
    let pid = child.id();
    let started = Instant::now();
    while started.elapsed() < after {
        if child.try_wait().expect("poll").is_some() {
            return None;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
    Some(pid)
}

/// Checks each file under a known name against its allowed whole versions, and parses it.
fn check_whole(dir: &Path, allowed: &BTreeMap<String, Vec<&Vec<u8>>>, point: &str) {
    for (name, bytes) in files(dir) {
        let Some(versions) = allowed.get(&name) else {
            continue;
        };
        assert!(
            versions.iter().any(|v| **v == bytes),
            "{point}: {name} ({} bytes) is neither the old nor the new whole file",
            bytes.len()
        );
        let path = dir.join(&name);
        if name.ends_with(".png") {
            image::load_from_memory(&bytes).unwrap_or_else(|e| panic!("{point}: {name}: {e}"));
        } else if name == "t.json" || name == "tree.json" {
            Tree::load(&path).unwrap_or_else(|e| panic!("{point}: {name}: {e}"));
        } else if name.ends_with(".glb") {
            let declared = u32::from_le_bytes(bytes[8..12].try_into().expect("header"));
            assert_eq!(declared as usize, bytes.len(), "{point}: {name} header");
        }
    }
}

#[test]
fn killed_grow_and_replay_leave_only_whole_old_or_new_files() {
    let root = tempfile::tempdir().expect("temp dir");
    // Grow: old outputs, then the new ones a full run writes (in another folder).
    let (old_dir, new_dir, work) = (
        root.path().join("old"),
        root.path().join("new"),
        root.path().join("work"),
    );
    for d in [&old_dir, &new_dir, &work] {
        std::fs::create_dir(d).expect("mkdir");
    }
    run_in(&old_dir, &grow_args("10"));
    let started = Instant::now();
    run_in(&new_dir, &grow_args("40"));
    let full_run = started.elapsed();
    // The kill points are spread over the run after the process start-up (measured on a
    // command that does nothing else), where the growing and writing happen.
    let started = Instant::now();
    run_in(&new_dir, &["species".to_string()]);
    let start_up = started.elapsed().min(full_run);
    let (old, new) = (files(&old_dir), files(&new_dir));
    for name in GROW_NAMES {
        assert!(old.contains_key(name) && new.contains_key(name), "{name}");
    }
    // The tree and its meshes change with its age (the MTL and textures may not).
    let changing: Vec<&str> = GROW_NAMES
        .into_iter()
        .filter(|n| old[*n] != new[*n])
        .collect();
    assert!(changing.len() >= 3, "{changing:?}");
    let allowed: BTreeMap<String, Vec<&Vec<u8>>> = GROW_NAMES
        .iter()
        .map(|n| (n.to_string(), vec![&old[*n], &new[*n]]))
        .collect();
    let mut killed = Vec::new();
    let mut kinds = Vec::new();
    for i in 0..NUM_KILLS_PER_COMMAND {
        // The old files back, then a kill part-way through the run.
        for name in GROW_NAMES {
            std::fs::write(work.join(name), &old[name]).expect("old file");
        }
        let after = start_up
            + (full_run - start_up)
                .mul_f64((f64::from(i) + 0.5) / f64::from(NUM_KILLS_PER_COMMAND));
        let point = format!("grow killed after {after:?}");
        let pid = run_and_kill(&work, &grow_args("40"), after);
        check_whole(&work, &allowed, &point);
        let now = files(&work);
        kinds.push(changing.iter().filter(|n| now[**n] == new[**n]).count());
        killed.extend(pid);
        let pids = temp_pids(&work);
        assert!(
            pids.iter().all(|p| killed.contains(p)),
            "{point}: a temporary of a process that was not killed: {pids:?}"
        );
        assert!(pids.len() <= killed.len(), "{point}: {pids:?}");
    }
    println!(
        "grow: {full_run:?} a run ({start_up:?} start-up); of {changing:?}, new at each kill point: {kinds:?}"
    );
    assert!(
        kinds.iter().any(|&k| k > 0 && k < changing.len()),
        "some kill lands between outputs: {kinds:?}"
    );
    run_in(&work, &grow_args("40"));
    assert!(temp_pids(&work).is_empty(), "the next run removes them");
    assert_eq!(files(&work), new, "and writes the new files whole");

    // Replay: a short session into the same folder with --force at each kill point.
    let session = short_session(root.path());
    let (reference, out) = (root.path().join("reference"), root.path().join("out"));
    let replay_args = |dir: &Path| -> Vec<String> {
        vec![
            "replay".into(),
            session.display().to_string(),
            "--out".into(),
            dir.display().to_string(),
            "--force".into(),
        ]
    };
    let started = Instant::now();
    run_in(root.path(), &replay_args(&reference));
    let full_run = started.elapsed();
    let new = files(&reference);
    assert_eq!(new.len(), REPLAY_FRAMES + 3, "frames, tree, glb, placement");
    let allowed: BTreeMap<String, Vec<&Vec<u8>>> =
        new.iter().map(|(n, b)| (n.clone(), vec![b])).collect();
    run_in(root.path(), &replay_args(&out));
    let mut killed = Vec::new();
    let mut counts = Vec::new();
    for i in 0..NUM_KILLS_PER_COMMAND {
        let after = full_run.mul_f64((f64::from(i) + 0.5) / f64::from(NUM_KILLS_PER_COMMAND));
        let point = format!("replay killed after {after:?}");
        killed.extend(run_and_kill(root.path(), &replay_args(&out), after));
        check_whole(&out, &allowed, &point);
        let names = files(&out);
        assert!(
            names.keys().all(|n| new.contains_key(n)),
            "{point}: stray files {names:?}"
        );
        counts.push(names.len());
        let pids = temp_pids(&out);
        assert!(pids.iter().all(|p| killed.contains(p)), "{point}: {pids:?}");
    }
    println!("replay: {full_run:?} a run; files present at each kill point: {counts:?}");
    run_in(root.path(), &replay_args(&out));
    assert!(temp_pids(&out).is_empty(), "the next replay removes them");
    assert_eq!(files(&out), new);
}

/// The demo session cut to its first frames, footage referenced absolutely.
fn short_session(dir: &Path) -> PathBuf {
    let committed =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions/demo_garden.session.json");
    let text = std::fs::read_to_string(committed).expect("session");
    let mut session: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let footage = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden");
    session["footage"] = serde_json::json!(footage);
    session["frames"]
        .as_array_mut()
        .expect("frames")
        .truncate(REPLAY_FRAMES);
    session["events"]
        .as_array_mut()
        .expect("events")
        .retain(|e| {
            e["frame"]
                .as_u64()
                .is_some_and(|f| (f as usize) < REPLAY_FRAMES)
        });
    let path = dir.join("short.session.json");
    std::fs::write(&path, session.to_string()).expect("write");
    path
}

#[test]
fn a_full_disk_leaves_the_previous_files_whole_and_no_temporary() {
    let dir = tempfile::tempdir().expect("temp dir");
    run_in(dir.path(), &grow_args("10"));
    let before = files(dir.path());
    // RLIMIT_FSIZE of 16 KiB: every new output is larger, so its write fails with EFBIG
    // (SIGXFSZ ignored, as a full disk's ENOSPC fails a write).
    let output = Command::new("bash")
        .arg("-c")
        .arg("ulimit -f 16 && trap '' XFSZ && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_sylva"))
        .args(grow_args("40"))
        .current_dir(dir.path())
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("bash runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "a full disk is an error");
    assert!(
        stderr.contains("t.json") && stderr.contains("too large"),
        "the error names the file and the reason: {stderr}"
    );
    assert_eq!(files(dir.path()), before, "the previous files stay whole");
    assert!(temp_pids(dir.path()).is_empty(), "no temporary remains");
}
