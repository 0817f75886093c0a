//! Where the time of one edit in a garden goes (issue #24, Done when 5): for each edit of
//! `garden_edit_timing` (tree 4 of the 10-tree stand at 10 years, one thread, a tree edited
//! before), the CPU medians of the edit applied to the tree alone, of the same edit applied to
//! the tree as the garden readies it (its neighbours' nodes as occupied space and all their
//! shade in its grid, nothing handed on), of `Garden::edit_tree` with an empty edit (what the
//! garden adds around any edit), and of the whole `Garden::edit_tree`.
//!
//! `cargo run --release -p sylva-core --example garden_edit_parts [empty N]` (`empty N`: only N
//! empty edits of the tree, one after another, for `perf record`)

#[path = "../benches/common/garden_stands.rs"]
mod garden_stands;
use garden_stands::{EDITS, alone, stand};
#[path = "../benches/common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::{cpu_ms, median_ms};

const EDITED: usize = 4;
const RUNS: usize = 15;

fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut garden = stand(10, 10.0, 2014);
        garden.grow_years(10.0);
        // The selected tree of a design: edited before (an empty edit).
        garden.edit_tree(EDITED, |_| {});
        let args: Vec<String> = std::env::args().collect();
        if args.get(1).is_some_and(|a| a == "empty") {
            let n: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(10_000);
            let ms = cpu_ms(|| {
                for _ in 0..n {
                    garden.edit_tree(EDITED, |_| {});
                }
            });
            println!("{n} empty edits: {:.4} ms each", ms / n as f64);
            return;
        }
        for (name, edit) in EDITS {
            let (mut by_itself, mut readied, mut empty, mut whole) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for _ in 0..RUNS {
                let mut tree = alone(&garden, EDITED);
                by_itself.push(cpu_ms(|| edit(&mut tree)));
                let mut g = garden.clone();
                g.prepare_edit(EDITED);
                let mut tree = g.trees[EDITED].tree.clone();
                readied.push(cpu_ms(|| edit(&mut tree)));
                let mut g = garden.clone();
                empty.push(cpu_ms(|| {
                    g.edit_tree(EDITED, |_| {});
                }));
                let mut g = garden.clone();
                whole.push(cpu_ms(|| {
                    g.edit_tree(EDITED, edit);
                }));
            }
            let (a, r, e, w) = (
                median_ms(by_itself),
                median_ms(readied),
                median_ms(empty),
                median_ms(whole),
            );
            println!(
                "{name:>10}: alone {a:.3} ms, readied in the garden {r:.3} ms, empty edit_tree {e:.3} ms, edit_tree {w:.3} ms (ratio {:.3}; handing on and the rest {:.3} ms)",
                w / a,
                w - r - e
            );
        }
    });
}
