//! Times editing one tree of a 10-tree garden (issue #24, Done when 5): a brush dab, a prune and
//! a parameter change (and a regrowth from a seedling with the changed parameter) of tree 4 of the mixed-preset stand of `garden_timing` (10 × 10 m, grown
//! 10 years), each by `Garden::edit_tree` against its neighbours and, as the reference, applied
//! to the same tree standing alone (its own shade only); the garden edit is timed as the tree's
//! first edit (which casts all its neighbours' shade into its grid) and as an edit of a tree
//! edited before (the selected tree of a design). One thread; the CPU time of each is the
//! median of 7 runs on fresh copies. Target: the garden edit at most 20% above the tree alone.
//! Also checks that the other nine trees' files stay byte-identical.
//!
//! `cargo run --release -p sylva-core --example garden_edit_timing`

#[path = "../benches/common/garden_stands.rs"]
mod garden_stands;
use garden_stands::{EDITS, alone, stand};
#[path = "../benches/common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::{cpu_ms, median_ms};

const EDITED: usize = 4;
const RUNS: usize = 7;

fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut garden = stand(10, 10.0, 2014);
        garden.grow_years(10.0);
        let files = |g: &sylva_core::garden::Garden| -> Vec<Vec<u8>> {
            g.trees
                .iter()
                .map(|t| t.tree.to_json_bytes().expect("saves"))
                .collect()
        };
        let before = files(&garden);
        println!(
            "10 trees on 10 x 10 m, 10 years, {} internodes; tree {EDITED} ({}, {} internodes) edited",
            garden.num_internodes(),
            garden.trees[EDITED].tree.species.name,
            garden.trees[EDITED].tree.skeleton.len()
        );
        for (name, edit) in EDITS {
            let mut first = Vec::new();
            let mut later = Vec::new();
            let mut by_itself = Vec::new();
            let mut others_kept = true;
            for _ in 0..RUNS {
                let mut g = garden.clone();
                first.push(cpu_ms(|| {
                    g.edit_tree(EDITED, edit);
                }));
                let after = files(&g);
                others_kept &= (0..10).all(|i| i == EDITED || after[i] == before[i]);
                // A tree edited before (the selected one in a design): an empty edit, untimed.
                let mut g = garden.clone();
                g.edit_tree(EDITED, |_| {});
                later.push(cpu_ms(|| {
                    g.edit_tree(EDITED, edit);
                }));
                let mut tree = alone(&garden, EDITED);
                by_itself.push(cpu_ms(|| edit(&mut tree)));
            }
            let (f, l, a) = (median_ms(first), median_ms(later), median_ms(by_itself));
            println!(
                "{name:>10}: the tree alone {a:.2} ms; in the garden, first edit {f:.2} ms (ratio {:.3}), an edit after others {l:.2} ms (ratio {:.3}; target <= 1.20); the other nine byte-identical: {others_kept}",
                f / a,
                l / a
            );
        }
    });
}
