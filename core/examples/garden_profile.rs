//! One garden of the mixed presets to profile (`perf record`) or check: `garden_profile COUNT
//! SIDE_M YEARS [alone]` grows COUNT seedlings at random on SIDE_M × SIDE_M m for YEARS years
//! (`alone`: without competition) and prints the time, internodes, mean links and digest.
//! `CHECK=1` then compares every tree's shadow grid at each of its nodes with a grid holding
//! all its linked neighbours' nodes (the shade covers must make them equal); `DUMP=PATH`
//! writes the garden file.
use std::time::Instant;

#[path = "../benches/common/garden_stands.rs"]
mod garden_stands;
use garden_stands::stand;
#[path = "../benches/common/digest.rs"]
mod digest;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(300);
    let side_m: f32 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(30.0);
    let years: f32 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(20.0);
    let alone = args.get(4).is_some_and(|a| a == "alone");
    let started = Instant::now();
    let mut garden = stand(count, side_m, 2014);
    garden.competition = !alone;
    garden.grow_years(years);
    if let Ok(path) = std::env::var("DUMP") {
        std::fs::write(path, garden.to_json_bytes()).expect("dump");
    }
    if std::env::var("CHECK").is_ok() {
        let mut bad = 0;
        let mut total = 0;
        for t in &garden.trees {
            let mut full = t.tree.clone();
            full.rebuild_shadow();
            let base = t.base();
            for &j in &t.neighbours {
                let n = &garden.trees[j as usize];
                full.environment.shadow.apply_nodes(
                    n.tree
                        .skeleton
                        .internodes
                        .iter()
                        .map(|m| (n.base() + m.end) - base),
                    1,
                );
            }
            for m in &t.tree.skeleton.internodes {
                total += 1;
                if full.environment.shadow.shadow_at(m.end)
                    != t.tree.environment.shadow.shadow_at(m.end)
                {
                    bad += 1;
                }
            }
        }
        println!("shade differs at {bad} of {total} nodes");
    }
    let links: usize = garden.trees.iter().map(|t| t.neighbours.len()).sum();
    println!("mean links {:.1}", links as f64 / count as f64);
    println!(
        "{count} trees {side_m} m {years} y alone={alone}: {:.3} s, {} internodes, digest {}",
        started.elapsed().as_secs_f64(),
        garden.num_internodes(),
        digest::fnv1a_hex(&garden.to_json_bytes())
    );
}
