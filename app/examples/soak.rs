//! Soak of the design state: 10 000 frames of brush strokes (brush-guided growth while a finger
//! paints), whole-tree grow and ungrow events and undos, fed as `sylva replay` feeds them; then
//! the memory the design holds against the final tree's own size. Issue 21 asks for at most 3×.
//!
//! `cargo run --release -p sylva-app --example soak [STEPS] [--mix design|sapling]`
//!
//! Two mixes of input:
//! - `design` (the default): a designer's session. The sapling is grown 20 years, then every
//!   five seconds a one-second stroke leads a tip of the crown outwards (about ten brush-guided
//!   iterations, at the default 10 a second); a third of the strokes are undone, a few whole-tree
//!   grows and undos follow, and when the tree has grown older than 40 years the designer scrubs
//!   the time back by 12 (each growth iteration is a year of the maple, so brushing without ever
//!   going back would age the design by centuries). The camera walks around the tree, framing it.
//! - `sapling`: the sapling brushed two thirds of the time, with few whole-tree grows (the
//!   soak of session 23): 1 900 iterations, in which the tree, all years old, sheds down to a few
//!   dozen internodes; a worst case for fixed costs.
//!
//! What is measured, from a baseline taken before the design exists (the growth's thread pool
//! started, the allocator's free pages returned):
//! - heap: the bytes the process holds, counted exactly by a counting allocator;
//! - resident: the process's resident anonymous memory (`RssAnon` in `/proc/self/status`: heap,
//!   stacks and the allocator's kept pages, leaving out the binary's code and data pages that
//!   running new code maps in), as the design leaves it (it hands free pages back to the
//!   system at most once a second) and at its peak (the high-water mark of the process's
//!   resident memory);
//! - the tree's own size: the heap of a whole copy of the final tree (its saved state and the
//!   shadow grid and pipe exponents derived from it: what a loaded tree holds).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::{Vec2, Vec3};
use sylva_app::render::{Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};

struct Counting;

static LIVE_BYTES: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE_BYTES.fetch_add(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE_BYTES.fetch_sub(layout.size(), Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE_BYTES.fetch_add(new_size, Ordering::Relaxed);
        LIVE_BYTES.fetch_sub(layout.size(), Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn live_bytes() -> usize {
    LIVE_BYTES.load(Ordering::Relaxed)
}

/// A field of `/proc/self/status` in bytes (0 where `/proc` is missing).
fn status_bytes(field: &str) -> usize {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with(field))?;
            line.split_whitespace().nth(1)?.parse::<usize>().ok()
        })
        .map_or(0, |kib| kib * 1024)
}

/// Resident anonymous memory (heap, stacks, the allocator's kept pages), bytes.
fn resident_anonymous_bytes() -> usize {
    status_bytes("RssAnon:")
}

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn touch(design: &mut DesignState, phase: TouchPhase, at: Vec2) {
    design.apply(&InputEvent::Touch {
        phase,
        id: 0,
        x: at.x,
        y: at.y,
    });
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mix {
    Design,
    Sapling,
}

/// The figures of one moment of the soak.
#[derive(Default)]
struct Figures {
    internodes: usize,
    tree_bytes: usize,
    heap: usize,
    resident: usize,
}

impl Figures {
    fn heap_ratio(&self) -> f64 {
        self.heap as f64 / self.tree_bytes.max(1) as f64
    }
    fn resident_ratio(&self) -> f64 {
        self.resident as f64 / self.tree_bytes.max(1) as f64
    }
}

struct Baseline {
    live: usize,
    anonymous: usize,
}

fn figures(design: &DesignState, baseline: &Baseline) -> Figures {
    Figures {
        internodes: design.tree.skeleton.len(),
        tree_bytes: tree_own_bytes(design),
        heap: live_bytes() - baseline.live,
        resident: resident_anonymous_bytes().saturating_sub(baseline.anonymous),
    }
}

fn main() {
    let mut steps = 10_000;
    let mut mix = Mix::Design;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--mix" => match args.next().as_deref() {
                Some("design") => mix = Mix::Design,
                Some("sapling") => mix = Mix::Sapling,
                other => {
                    eprintln!("soak: --mix takes design or sapling, not {other:?}");
                    std::process::exit(2);
                }
            },
            n => match n.parse() {
                Ok(n) => steps = n,
                Err(_) => {
                    eprintln!("soak: usage: soak [STEPS] [--mix design|sapling]");
                    std::process::exit(2);
                }
            },
        }
    }
    // The process's fixed costs before the design exists: the growth's thread pool and each
    // thread's allocator arena, warmed by a tree grown and dropped.
    let mut warm = sylva_core::Tree::new(
        sylva_core::species::Species::by_name("maple").expect("the maple preset"),
        1,
    );
    warm.grow(6, None);
    drop(warm);
    sylva_app::memory::release_free_memory();
    let baseline = Baseline {
        live: live_bytes(),
        anonymous: resident_anonymous_bytes(),
    };
    let started = Instant::now();
    let mut design = DesignState::new(21, Parameters::default());
    let mut walk = Walk::new(&design);
    design.advance_frame(Some(walk.camera(0)), 0.0, 1.0 / 30.0);
    if mix == Mix::Design {
        design.apply(&InputEvent::Grow { iterations: 20 });
        walk = Walk::new(&design);
    }
    let mut peak = Figures::default();
    let mut stroke = Vec::new();
    let mut num_strokes = 0;
    for step in 0..steps {
        let time_s = step as f64 / 30.0;
        match mix {
            Mix::Design => design_step(&mut design, &mut walk, step, &mut stroke, &mut num_strokes),
            Mix::Sapling => sapling_step(&mut design, &walk, step, &mut stroke),
        }
        design.advance_frame(Some(walk.camera(step)), time_s, 1.0 / 30.0);
        if step % 100 == 99 {
            let now = figures(&design, &baseline);
            if now.heap_ratio() > peak.heap_ratio() {
                peak.heap = now.heap;
                peak.tree_bytes = now.tree_bytes;
                peak.internodes = now.internodes;
            }
            if now.resident_ratio() > peak.resident_ratio() {
                peak.resident = now.resident;
            }
            if step % 1000 == 999 {
                let (undo, timeline) = design.snapshot_bytes();
                println!(
                    "step {:>6}: {:>6} internodes, {:>5} attraction points, iteration {:>4}; tree {:>6.2} MiB; heap {:>6.2} MiB ({:.2}x; undo {:.2}, timeline {:.2}), resident {:>6.2} MiB ({:.2}x)",
                    step + 1,
                    now.internodes,
                    design.tree.environment.attraction.points.len(),
                    design.tree.iteration,
                    mib(now.tree_bytes),
                    mib(now.heap),
                    now.heap_ratio(),
                    mib(undo),
                    mib(timeline),
                    mib(now.resident),
                    now.resident_ratio(),
                );
            }
        }
    }
    let elapsed_s = started.elapsed().as_secs_f64();
    let end = figures(&design, &baseline);
    let peak_resident = status_bytes("VmHWM:");
    let (undo, timeline) = design.snapshot_bytes();
    println!(
        "soak_steps={steps} mix={} strokes={num_strokes} elapsed_s={elapsed_s:.1} internodes={} iteration={} undo_steps={} tree_mib={:.2} design_heap_mib={:.2} design_resident_mib={:.2} heap_ratio={:.2} resident_ratio={:.2}",
        if mix == Mix::Design {
            "design"
        } else {
            "sapling"
        },
        end.internodes,
        design.tree.iteration,
        design.undo_depth(),
        mib(end.tree_bytes),
        mib(end.heap),
        mib(end.resident),
        end.heap_ratio(),
        end.resident_ratio(),
    );
    println!(
        "peak_heap_ratio={:.2} (at {} internodes) peak_resident_ratio={:.2} process_peak_resident_mib={:.2}",
        peak.heap_ratio(),
        peak.internodes,
        peak.resident_ratio(),
        mib(peak_resident),
    );
    // What the design holds once the allocator has handed its free pages back (as the design
    // does at most once a second after a change).
    sylva_app::memory::release_free_memory();
    let released = resident_anonymous_bytes().saturating_sub(baseline.anonymous);
    println!(
        "design_resident_after_release_mib={:.2} resident_ratio_after_release={:.2}",
        mib(released),
        released as f64 / end.tree_bytes.max(1) as f64
    );
    // Where the heap is: the live tree (with its growth working memory), the undo steps and
    // the timeline (as they count themselves), and the rest of the design.
    let seedling = sylva_core::Tree::new(design.tree.species.clone(), 0);
    let tree = std::mem::replace(&mut design.tree, seedling);
    let with_tree = live_bytes();
    drop(tree);
    let tree_live = with_tree - live_bytes();
    let attraction_points = design.tree.environment.attraction.points.len();
    println!(
        "tree_live_mib={:.2} ({:.2}x: the tree {:.2} and its growth working memory {:.2}) undo_mib={:.2} ({:.2}x) timeline_mib={:.2} ({:.2}x) rest_mib={:.2} ({:.2}x) attraction_points_after_seedling={attraction_points}",
        mib(tree_live),
        tree_live as f64 / end.tree_bytes.max(1) as f64,
        end.tree_bytes as f64 / end.tree_bytes.max(1) as f64,
        tree_live.saturating_sub(end.tree_bytes) as f64 / end.tree_bytes.max(1) as f64,
        mib(undo),
        undo as f64 / end.tree_bytes.max(1) as f64,
        mib(timeline),
        timeline as f64 / end.tree_bytes.max(1) as f64,
        mib(end.heap.saturating_sub(tree_live + undo + timeline)),
        end.heap.saturating_sub(tree_live + undo + timeline) as f64 / end.tree_bytes.max(1) as f64,
    );
}

/// Frames of a stroke in the design mix (one second) and of the design mix's cycle.
const STROKE_FRAMES: usize = 30;
const CYCLE_FRAMES: usize = 150;
/// The design mix keeps the tree between these ages (years of the maple).
const OLDEST_YEARS: u32 = 40;
const SCRUB_BACK_YEARS: i32 = 12;

/// One frame of a designer's session (see the module's doc).
fn design_step(
    design: &mut DesignState,
    walk: &mut Walk,
    step: usize,
    stroke: &mut Vec<Vec2>,
    num_strokes: &mut usize,
) {
    let cycle = step / CYCLE_FRAMES;
    let frame = step % CYCLE_FRAMES;
    if frame == 0 {
        *walk = Walk::new(design);
        *stroke = outward_stroke(design, &walk.camera(step), cycle);
    }
    if let Some(&at) = stroke.get(frame) {
        let phase = match frame {
            0 => TouchPhase::Start,
            f if f + 1 == stroke.len() => TouchPhase::End,
            _ => TouchPhase::Move,
        };
        touch(design, phase, at);
        if phase == TouchPhase::End {
            *num_strokes += 1;
        }
    }
    match frame {
        // The designer dislikes a third of the strokes.
        60 if cycle % 3 == 2 => design.apply(&InputEvent::Undo),
        90 if design.tree.iteration > OLDEST_YEARS => {
            let asked = design.tree.iteration - SCRUB_BACK_YEARS as u32;
            design.apply(&InputEvent::Grow {
                iterations: -SCRUB_BACK_YEARS,
            });
            // Where the timeline had thinned the years asked for, the scrub lands on an
            // earlier kept one; landing more than a scrub farther back, the designer takes it
            // back.
            if design.tree.iteration + (SCRUB_BACK_YEARS as u32) < asked {
                design.apply(&InputEvent::Undo);
            }
        }
        90 if cycle.is_multiple_of(4) => design.apply(&InputEvent::Grow { iterations: 2 }),
        120 if cycle % 7 == 3 => design.apply(&InputEvent::Undo),
        _ => {}
    }
}

/// One frame of the sapling mix: a stroke of 40 frames every 60 from a tip of the crown (each
/// stroke from another), whole-tree grows, an ungrow and an undo every 500.
fn sapling_step(design: &mut DesignState, walk: &Walk, step: usize, stroke: &mut Vec<Vec2>) {
    let phase_in_stroke = step % 60;
    if phase_in_stroke == 0 {
        let camera = walk.camera(step);
        let tips = tip_pixels(design, &camera);
        let start = tips
            .get((step / 60 * 7919) % tips.len().max(1))
            .map_or(Vec2::new(320.0, 240.0), |t| t.0);
        let heading = Vec2::new(((step / 60) as f32 * 2.4).sin(), -1.0).normalize();
        *stroke = (0..=40).map(|k| start + heading * k as f32 * 2.0).collect();
    }
    if let Some(&at) = stroke.get(phase_in_stroke) {
        let phase = match phase_in_stroke {
            0 => TouchPhase::Start,
            40 => TouchPhase::End,
            _ => TouchPhase::Move,
        };
        touch(design, phase, at);
    }
    match step % 500 {
        100 | 200 | 300 | 400 => design.apply(&InputEvent::Grow { iterations: 2 }),
        250 => design.apply(&InputEvent::Grow { iterations: -1 }),
        450 => design.apply(&InputEvent::Undo),
        _ => {}
    }
}

/// The camera walking slowly around the tree at a distance that frames it.
struct Walk {
    intrinsics: Intrinsics,
    target: Vec3,
    distance_m: f32,
}

impl Walk {
    /// Framing the design's tree as it is now (its height, or 3 m at least).
    fn new(design: &DesignState) -> Walk {
        let intrinsics = Intrinsics::from_fov(640, 480, 1.0);
        let height_m = tree_height_m(design).max(3.0);
        Walk {
            intrinsics,
            target: Vec3::new(0.0, 0.5 * height_m, 0.0),
            // The whole height in the 480-pixel height of the view, with a margin.
            distance_m: 1.3 * height_m,
        }
    }

    fn camera(&self, step: usize) -> ViewCamera {
        let angle = step as f32 * 0.002;
        let eye = self.target + Vec3::new(angle.sin(), 0.1, angle.cos()) * self.distance_m;
        ViewCamera::looking_at(self.intrinsics, eye, self.target)
    }
}

/// The height of the tree's highest internode end above its base, metres.
fn tree_height_m(design: &DesignState) -> f32 {
    design
        .tree
        .skeleton
        .internodes
        .iter()
        .map(|i| i.end.y)
        .fold(0.0_f32, f32::max)
}

/// Pixels and world positions of the tree's tips (by arena order) that `camera` sees.
fn tip_pixels(design: &DesignState, camera: &ViewCamera) -> Vec<(Vec2, Vec3)> {
    design
        .tree
        .skeleton
        .internodes
        .iter()
        .filter(|i| i.main_child.is_none())
        .filter_map(|i| Some((camera.pixel_from_world(i.end)?, i.end)))
        .filter(|(p, _)| p.x > 0.0 && p.y > 0.0 && p.x < 640.0 && p.y < 480.0)
        .collect()
}

/// A stroke of [`STROKE_FRAMES`] finger positions from the `n`-th visible tip of the crown's
/// upper half (cycling) one metre outwards, away from the trunk's axis and up.
fn outward_stroke(design: &DesignState, camera: &ViewCamera, n: usize) -> Vec<Vec2> {
    let height_m = tree_height_m(design);
    let tips: Vec<(Vec2, Vec3)> = tip_pixels(design, camera)
        .into_iter()
        .filter(|(_, w)| w.y > 0.5 * height_m)
        .collect();
    let Some(&(_, tip)) = tips.get((n * 7919) % tips.len().max(1)) else {
        return Vec::new();
    };
    let outwards =
        (Vec3::new(tip.x, 0.0, tip.z).normalize_or_zero() + Vec3::Y * 0.5).normalize_or(Vec3::Y);
    (0..STROKE_FRAMES)
        .filter_map(|k| {
            let t = k as f32 / (STROKE_FRAMES - 1) as f32;
            camera.pixel_from_world(tip + outwards * t)
        })
        .collect()
}

/// The final tree's own size: the heap of a whole copy of it (shadow grid included).
fn tree_own_bytes(design: &DesignState) -> usize {
    let before = live_bytes();
    let mut copy = design.tree.clone();
    copy.rebuild_shadow();
    let bytes = live_bytes() - before;
    drop(copy);
    bytes
}
