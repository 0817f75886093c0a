//! Plantings: where the trees of a garden stand. An explicit list of trees, a row (start, end,
//! spacing), a group (centre, radius, count) or a stand over a plot, random (uniform) or
//! clustered (a Thomas process: cluster centres uniform over the plot, trees scattered about
//! them by a Gaussian kernel, Longay 2014 §6.4's kernel distributions).
//!
//! Every planting is checked before anything is allocated for it: counts are bounded
//! ([`MAX_GARDEN_TREES`]), positions finite and within [`MAX_PLANTING_EXTENT_M`], and no two
//! trunks closer than [`MIN_TREE_SPACING_M`]; errors name the entry.

use glam::Vec2;
use serde::{Deserialize, Serialize};

use super::{GardenError, MAX_GARDEN_YEARS};
use crate::rng::Rng;
use crate::species::Species;

/// The most trees a garden may hold.
pub const MAX_GARDEN_TREES: usize = 2000;
/// No trunk may stand further than this from the garden's origin along x or z, metres.
pub const MAX_PLANTING_EXTENT_M: f32 = 500.0;
/// Two trunks closer than this stand on the same spot, metres.
pub const MIN_TREE_SPACING_M: f32 = 0.3;
/// Standard deviation of the clustered stand's kernel, metres.
const CLUSTER_SIGMA_M: f32 = 2.0;
/// Trees per cluster of a clustered stand, on average.
const TREES_PER_CLUSTER: usize = 8;
/// Draws a stand may make per tree before it gives up on the spacing.
const DRAWS_PER_TREE: usize = 200;

/// A tree to plant, resolved: species, trunk position (garden metres), age and seed. `entry`
/// names the planting it came from in errors.
#[derive(Clone, Debug)]
pub struct PlantedTree {
    pub species: Species,
    pub x_m: f32,
    pub z_m: f32,
    pub age_years: f32,
    pub seed: u64,
    pub entry: String,
}

/// How a stand's trees are spread over its plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    #[default]
    Random,
    Clustered,
}

/// One entry of a planting file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Planting {
    /// One tree.
    Tree {
        x: f32,
        z: f32,
        species: String,
        #[serde(default)]
        age_years: f32,
        #[serde(default)]
        seed: u64,
    },
    /// Trees from `start` to `end` (x, z), `spacing_m` apart; seeds `seed`, `seed + 1`, ...
    Row {
        species: String,
        start: [f32; 2],
        end: [f32; 2],
        spacing_m: f32,
        #[serde(default)]
        age_years: f32,
        #[serde(default)]
        seed: u64,
    },
    /// `count` trees evenly round a circle of `radius_m` about `centre` (one in the centre when
    /// the count is 1).
    Group {
        species: String,
        centre: [f32; 2],
        radius_m: f32,
        count: usize,
        #[serde(default)]
        age_years: f32,
        #[serde(default)]
        seed: u64,
    },
    /// `count` trees over a `width_m` × `depth_m` plot centred on the origin, species taken in
    /// turn from `species`.
    Stand {
        species: Vec<String>,
        width_m: f32,
        depth_m: f32,
        count: usize,
        #[serde(default)]
        layout: Layout,
        #[serde(default)]
        age_years: f32,
        #[serde(default)]
        seed: u64,
    },
}

/// A planting file: `{"plantings": [...]}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantingFile {
    pub plantings: Vec<Planting>,
}

fn bad(entry: &str, reason: impl Into<String>) -> GardenError {
    GardenError::Planting {
        entry: entry.to_string(),
        reason: reason.into(),
    }
}

fn check_length(entry: &str, what: &str, value: f32, max: f32) -> Result<(), GardenError> {
    if value.is_finite() && value > 0.0 && value <= max {
        Ok(())
    } else {
        Err(bad(
            entry,
            format!("{what} is {value}, expected a length in (0, {max}] m"),
        ))
    }
}

fn check_count(entry: &str, count: usize, room: usize) -> Result<(), GardenError> {
    if count == 0 || count > room {
        return Err(bad(
            entry,
            format!(
                "{count} trees (a garden holds 1 to {MAX_GARDEN_TREES}; {room} places are left)"
            ),
        ));
    }
    Ok(())
}

impl PlantingFile {
    /// Every tree of every planting, species resolved by `species_by_name` (a preset name or a
    /// file). Nothing is grown; the trees are checked as [`check_trees`] does.
    pub fn trees(
        &self,
        species_by_name: &dyn Fn(&str) -> Result<Species, String>,
    ) -> Result<Vec<PlantedTree>, GardenError> {
        let mut trees = Vec::new();
        for (i, planting) in self.plantings.iter().enumerate() {
            let room = MAX_GARDEN_TREES.saturating_sub(trees.len());
            planting.expand(i, room, species_by_name, &mut trees)?;
        }
        check_trees(&trees)?;
        Ok(trees)
    }
}

impl Planting {
    fn kind(&self) -> &'static str {
        match self {
            Planting::Tree { .. } => "tree",
            Planting::Row { .. } => "row",
            Planting::Group { .. } => "group",
            Planting::Stand { .. } => "stand",
        }
    }

    /// Appends this planting's trees (at most `room`) to `out`; `index` names it in errors.
    pub fn expand(
        &self,
        index: usize,
        room: usize,
        species_by_name: &dyn Fn(&str) -> Result<Species, String>,
        out: &mut Vec<PlantedTree>,
    ) -> Result<(), GardenError> {
        let entry = format!("{index} ({})", self.kind());
        let resolve =
            |name: &str| species_by_name(name).map_err(|e| bad(&entry, format!("species: {e}")));
        let mut push = |species: &Species, p: Vec2, age_years: f32, seed: u64| {
            out.push(PlantedTree {
                species: species.clone(),
                x_m: p.x,
                z_m: p.y,
                age_years,
                seed,
                entry: entry.clone(),
            });
        };
        match self {
            Planting::Tree {
                x,
                z,
                species,
                age_years,
                seed,
            } => {
                check_count(&entry, 1, room)?;
                push(&resolve(species)?, Vec2::new(*x, *z), *age_years, *seed);
            }
            Planting::Row {
                species,
                start,
                end,
                spacing_m,
                age_years,
                seed,
            } => {
                let (a, b) = (Vec2::from(*start), Vec2::from(*end));
                check_point(&entry, a)?;
                check_point(&entry, b)?;
                check_length(&entry, "spacing_m", *spacing_m, 2.0 * MAX_PLANTING_EXTENT_M)?;
                let length = a.distance(b);
                // Counted in f64 before anything is allocated: a tiny spacing is an error.
                let count = (f64::from(length) / f64::from(*spacing_m)).floor() + 1.0;
                if count > room as f64 {
                    return Err(bad(
                        &entry,
                        format!(
                            "{count} trees (a garden holds 1 to {MAX_GARDEN_TREES}; {room} places are left)"
                        ),
                    ));
                }
                let count = count as usize;
                let species = resolve(species)?;
                let step = (b - a).normalize_or_zero() * *spacing_m;
                for k in 0..count {
                    push(&species, a + step * k as f32, *age_years, seed + k as u64);
                }
            }
            Planting::Group {
                species,
                centre,
                radius_m,
                count,
                age_years,
                seed,
            } => {
                let c = Vec2::from(*centre);
                check_point(&entry, c)?;
                check_count(&entry, *count, room)?;
                if !(radius_m.is_finite() && (0.0..=MAX_PLANTING_EXTENT_M).contains(radius_m)) {
                    return Err(bad(&entry, format!("radius_m is {radius_m}")));
                }
                let species = resolve(species)?;
                for k in 0..*count {
                    let p = if *count == 1 {
                        c
                    } else {
                        let angle = std::f32::consts::TAU * k as f32 / *count as f32;
                        c + Vec2::from_angle(angle) * *radius_m
                    };
                    push(&species, p, *age_years, seed + k as u64);
                }
            }
            Planting::Stand {
                species,
                width_m,
                depth_m,
                count,
                layout,
                age_years,
                seed,
            } => {
                check_length(&entry, "width_m", *width_m, 2.0 * MAX_PLANTING_EXTENT_M)?;
                check_length(&entry, "depth_m", *depth_m, 2.0 * MAX_PLANTING_EXTENT_M)?;
                check_count(&entry, *count, room)?;
                if species.is_empty() {
                    return Err(bad(&entry, "no species"));
                }
                let resolved = species
                    .iter()
                    .map(|s| resolve(s))
                    .collect::<Result<Vec<_>, _>>()?;
                let plot = Vec2::new(*width_m, *depth_m);
                let positions = stand_positions(plot, *count, *layout, *seed)
                    .ok_or_else(|| {
                        bad(
                            &entry,
                            format!(
                                "cannot place {count} trees {MIN_TREE_SPACING_M} m apart on {width_m} × {depth_m} m"
                            ),
                        )
                    })?;
                for (k, p) in positions.into_iter().enumerate() {
                    let s = &resolved[k % resolved.len()];
                    push(s, p, *age_years, seed.wrapping_add(1 + k as u64));
                }
            }
        }
        Ok(())
    }
}

pub(super) fn check_point(entry: &str, p: Vec2) -> Result<(), GardenError> {
    if p.is_finite() && p.abs().max_element() <= MAX_PLANTING_EXTENT_M {
        Ok(())
    } else {
        Err(bad(
            entry,
            format!(
                "position ({}, {}) is not a point within {MAX_PLANTING_EXTENT_M} m of the origin",
                p.x, p.y
            ),
        ))
    }
}

/// Positions of a stand over a plot of `plot` (x, z) metres centred on the origin, no two closer
/// than [`MIN_TREE_SPACING_M`]; None when the draws run out.
pub fn stand_positions(plot: Vec2, count: usize, layout: Layout, seed: u64) -> Option<Vec<Vec2>> {
    let mut rng = Rng::new(seed);
    let half = plot * 0.5;
    let uniform = |rng: &mut Rng| {
        Vec2::new(
            rng.range_f32(-half.x, half.x),
            rng.range_f32(-half.y, half.y),
        )
    };
    let centres: Vec<Vec2> = match layout {
        Layout::Random => Vec::new(),
        Layout::Clustered => (0..count.div_ceil(TREES_PER_CLUSTER))
            .map(|_| uniform(&mut rng))
            .collect(),
    };
    let mut placed: Vec<Vec2> = Vec::with_capacity(count);
    let mut draws = 0;
    while placed.len() < count {
        draws += 1;
        if draws > DRAWS_PER_TREE * count {
            return None;
        }
        let p = if centres.is_empty() {
            uniform(&mut rng)
        } else {
            let c = centres[rng.next_u32() as usize % centres.len()];
            // Box–Muller: a Gaussian offset of σ about the cluster centre.
            let (u1, u2) = (rng.next_f32().max(1e-7), rng.next_f32());
            let radius = CLUSTER_SIGMA_M * (-2.0 * u1.ln()).sqrt();
            c + Vec2::from_angle(std::f32::consts::TAU * u2) * radius
        };
        let inside = p.abs().cmple(half).all();
        if inside && placed.iter().all(|q| q.distance(p) >= MIN_TREE_SPACING_M) {
            placed.push(p);
        }
    }
    Some(placed)
}

/// Checks a list of trees: at most [`MAX_GARDEN_TREES`], finite positions within
/// [`MAX_PLANTING_EXTENT_M`], ages in [0, [`MAX_GARDEN_YEARS`]], valid species and no two trunks
/// closer than [`MIN_TREE_SPACING_M`]. Errors name the tree (by index and entry).
pub fn check_trees(trees: &[PlantedTree]) -> Result<(), GardenError> {
    if trees.is_empty() || trees.len() > MAX_GARDEN_TREES {
        return Err(bad(
            "all",
            format!(
                "{} trees (a garden holds 1 to {MAX_GARDEN_TREES})",
                trees.len()
            ),
        ));
    }
    let name = |i: usize| {
        let t: &PlantedTree = &trees[i];
        if t.entry.is_empty() {
            format!("tree {i}")
        } else {
            format!("{}, tree {i}", t.entry)
        }
    };
    for (i, t) in trees.iter().enumerate() {
        check_point(&name(i), Vec2::new(t.x_m, t.z_m))?;
        if !(t.age_years.is_finite() && (0.0..=MAX_GARDEN_YEARS).contains(&t.age_years)) {
            return Err(bad(
                &name(i),
                format!(
                    "age_years is {}, expected 0 to {MAX_GARDEN_YEARS}",
                    t.age_years
                ),
            ));
        }
        t.species
            .validate()
            .map_err(|e| bad(&name(i), format!("species {}: {e}", t.species.name)))?;
    }
    // Same spot: sorted along x, each tree compared with those within the spacing along x.
    let mut order: Vec<usize> = (0..trees.len()).collect();
    order.sort_by(|&a, &b| trees[a].x_m.total_cmp(&trees[b].x_m));
    for (k, &i) in order.iter().enumerate() {
        let p = Vec2::new(trees[i].x_m, trees[i].z_m);
        for &j in &order[k + 1..] {
            let q = Vec2::new(trees[j].x_m, trees[j].z_m);
            if q.x - p.x >= MIN_TREE_SPACING_M {
                break;
            }
            if p.distance(q) < MIN_TREE_SPACING_M {
                let (a, b) = (i.min(j), i.max(j));
                return Err(bad(
                    &name(b),
                    format!(
                        "stands {:.3} m from {} (trunks must be at least {MIN_TREE_SPACING_M} m apart)",
                        p.distance(q),
                        name(a)
                    ),
                ));
            }
        }
    }
    Ok(())
}
