//! Soak of the design state: 10 000 frames of brush strokes (brush-guided growth while a finger
//! paints), whole-tree grow and ungrow events and undos, fed as `sylva replay` feeds them; then
//! the memory the design holds against the final tree's own size. Issue 21 asks for at most 3×.
//!
//! `cargo run --release -p sylva-app --example soak [STEPS]`
//!
//! Heap bytes are counted by a counting allocator (exact); resident memory is read from
//! `/proc/self/statm` (Linux) and includes what the allocator keeps after frees.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::Vec3;
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

/// Resident memory, bytes (0 where `/proc` is missing).
fn resident_bytes() -> usize {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<usize>().ok())
        .map_or(0, |pages| pages * 4096)
}

/// Resident anonymous memory (heap, stacks: what the process allocated, not the pages of its
/// binary that running new code paths maps in), bytes (0 where `/proc` is missing).
fn resident_anonymous_bytes() -> usize {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("RssAnon:"))?;
            line.split_whitespace().nth(1)?.parse::<usize>().ok()
        })
        .map_or(0, |kib| kib * 1024)
}

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn touch(design: &mut DesignState, phase: TouchPhase, x: f32, y: f32) {
    design.apply(&InputEvent::Touch { phase, id: 0, x, y });
}

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let k = Intrinsics::from_fov(640, 480, 1.0);
    let camera_at = |step: usize| {
        // Walking slowly around the tree.
        let angle = step as f32 * 0.002;
        let eye = Vec3::new(4.0 * angle.sin(), 1.5, 4.0 * angle.cos());
        ViewCamera::looking_at(k, eye, Vec3::new(0.0, 1.5, 0.0))
    };
    let live_before = live_bytes();
    let started = Instant::now();
    let mut design = DesignState::new(21, Parameters::default());
    // Resident memory from after the first frame: the growth's thread pool and the allocator's
    // arenas are then in place (a fixed cost of the process, not of the design).
    design.advance_frame(Some(camera_at(0)), 0.0, 1.0 / 30.0);
    design.apply(&InputEvent::Grow { iterations: 1 });
    let resident_before = resident_bytes();
    let anonymous_before = resident_anonymous_bytes();
    let mut peak_ratio: f64 = 0.0;
    let mut stroke_start = glam::Vec2::ZERO;
    for step in 0..steps {
        let time_s = step as f64 / 30.0;
        // A stroke of 40 frames every 60 from a tip of the crown outwards (each stroke from
        // another tip), so the tree keeps growing where it is brushed.
        let phase_in_stroke = step % 60;
        if phase_in_stroke == 0 {
            stroke_start = tip_pixel(&design, step / 60).unwrap_or(glam::Vec2::new(320.0, 240.0));
        }
        let heading = glam::Vec2::new(((step / 60) as f32 * 2.4).sin(), -1.0).normalize();
        let finger = stroke_start + heading * phase_in_stroke as f32 * 2.0;
        match phase_in_stroke {
            0 => touch(&mut design, TouchPhase::Start, finger.x, finger.y),
            1..=39 => touch(&mut design, TouchPhase::Move, finger.x, finger.y),
            40 => touch(&mut design, TouchPhase::End, finger.x, finger.y),
            _ => {}
        }
        // Whole-tree growth (the tree reaches hundreds of iterations), an ungrow and an undo.
        match step % 500 {
            100 | 200 | 300 | 400 => design.apply(&InputEvent::Grow { iterations: 2 }),
            250 => design.apply(&InputEvent::Grow { iterations: -1 }),
            450 => design.apply(&InputEvent::Undo),
            _ => {}
        }
        design.advance_frame(Some(camera_at(step)), time_s, 1.0 / 30.0);
        if step % 1000 == 999 {
            let tree = tree_own_bytes(&design);
            let held = live_bytes() - live_before;
            let ratio = held as f64 / tree.max(1) as f64;
            peak_ratio = peak_ratio.max(ratio);
            let (undo, timeline) = design.snapshot_bytes();
            println!(
                "step {:>6}: {:>6} internodes, {:>6} attraction points, iteration {:>4}; design holds {:>7.2} MiB (undo {:.2}, timeline {:.2}), {:.2}x the tree's own size",
                step + 1,
                design.tree.skeleton.len(),
                design.tree.environment.attraction.points.len(),
                design.tree.iteration,
                mib(held),
                mib(undo),
                mib(timeline),
                ratio
            );
        }
    }
    let elapsed_s = started.elapsed().as_secs_f64();
    let held = live_bytes() - live_before;
    let resident = resident_bytes().saturating_sub(resident_before);
    let anonymous = resident_anonymous_bytes().saturating_sub(anonymous_before);
    let tree_bytes = tree_own_bytes(&design);
    let (undo, timeline) = design.snapshot_bytes();
    println!(
        "soak_steps={steps} elapsed_s={elapsed_s:.1} internodes={} undo_steps={} tree_mib={:.2} design_heap_mib={:.2} design_resident_mib={:.2} undo_mib={:.2} timeline_mib={:.2} heap_ratio={:.2} resident_ratio={:.2}",
        design.tree.skeleton.len(),
        design.undo_depth(),
        mib(tree_bytes),
        mib(held),
        mib(resident),
        mib(undo),
        mib(timeline),
        held as f64 / tree_bytes.max(1) as f64,
        resident as f64 / tree_bytes.max(1) as f64,
    );
    println!(
        "design_resident_anonymous_mib={:.2} resident_anonymous_ratio={:.2}",
        mib(anonymous),
        anonymous as f64 / tree_bytes.max(1) as f64,
    );
    let attraction = &design.tree.environment.attraction;
    println!(
        "peak_heap_ratio={peak_ratio:.2} tree_model_own_mib={:.2} tree_saved_state_mib={:.2} persistent_points={} point_groups={}",
        mib(design.tree.own_bytes()),
        mib(design.tree.saved_state_bytes()),
        attraction.num_persistent(),
        attraction.groups.len()
    );
    // The heap of the design's tree as it lives, its growth working memory included: what
    // taking it out of the design (for a seedling) frees.
    let seedling = sylva_core::Tree::new(design.tree.species.clone(), 0);
    let tree = std::mem::replace(&mut design.tree, seedling);
    let with_both = live_bytes();
    drop(tree);
    println!(
        "tree_live_mib={:.2} (the design's tree with its growth working memory)",
        mib(with_both - live_bytes())
    );
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

/// The pixel of the `n`-th tip (by arena order, cycling) as the design's camera sees it.
fn tip_pixel(design: &DesignState, n: usize) -> Option<glam::Vec2> {
    let camera = design.camera?;
    let tips: Vec<Vec3> = design
        .tree
        .skeleton
        .internodes
        .iter()
        .filter(|i| i.main_child.is_none())
        .map(|i| i.end)
        .collect();
    let tip = tips.get((n * 7919) % tips.len().max(1))?;
    camera.pixel_from_world(*tip)
}
