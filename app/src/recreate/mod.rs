//! Recreating an existing tree in place (Longay 2014 §5.4.4 and §7): the user marks the real
//! tree in the footage (the trunk base, the crown's outline in one or more views), Sylva measures
//! it (height, crown width and axes, crown base, trunk position, each with how it was obtained)
//! from the visual hull of the outlines and the tracked points on the tree, then grows a species
//! from the trunk base into the hull. The result is an ordinary tree: every edit, the years and
//! the exports work on it. World: metres, Y up, origin on the ground plane (the tracker's).

pub mod fit;
pub mod footage;
pub mod grow;
pub mod hull;
pub mod marks;
pub mod measure;
pub mod overlay;
pub mod segment;
pub mod silhouette;
pub mod trunk;

use glam::{Affine3A, Vec3};

/// Views of the crown that score the growth and the foliage.
const GROWTH_VIEWS: usize = 10;
use sylva_core::geometry::{TreeMesh, TreeMeshes};

/// Moves every mesh of `meshes` (built in tree space) into the world by `world_from_tree`.
pub fn place_meshes(meshes: &mut TreeMeshes, world_from_tree: &Affine3A) {
    let place = |mesh: &mut TreeMesh| {
        for p in &mut mesh.positions {
            *p = world_from_tree.transform_point3(Vec3::from(*p)).to_array();
        }
        for n in &mut mesh.normals {
            *n = world_from_tree
                .transform_vector3(Vec3::from(*n))
                .normalize_or_zero()
                .to_array();
        }
    };
    for lod in &mut meshes.lods {
        place(&mut lod.branches);
        place(&mut lod.merged_leaves);
    }
    place(&mut meshes.leaves);
    place(&mut meshes.fruit);
}

/// Everything a recreation makes from tracked footage and the marks: the measures, the grown
/// tree placed in the world, how it grew, and the model's agreement with each traced outline.
pub struct Recreated {
    pub recreation: measure::Recreation,
    pub tree: sylva_core::Tree,
    pub world_from_tree: Affine3A,
    pub growth: grow::GrowthReport,
    /// Intersection over union of the model's silhouette (as drawn) and each traced outline,
    /// per marked frame.
    pub outline_iou: Vec<(usize, f64)>,
    /// The crown as segmented in the footage's frames (empty without its images).
    pub crown_masks: Vec<segment::CrownMask>,
}

impl Recreated {
    /// Mean of [`Self::outline_iou`] over the marked views.
    pub fn outline_iou_mean(&self) -> f64 {
        self.outline_iou.iter().map(|(_, v)| v).sum::<f64>() / self.outline_iou.len().max(1) as f64
    }

    /// The tree's meshes in the world (the finest level, its leaf cards).
    pub fn world_meshes(&self) -> TreeMeshes {
        let mut meshes = sylva_core::geometry::build_tree_meshes_in(
            &self.tree,
            sylva_core::geometry::Season::Summer,
        );
        place_meshes(&mut meshes, &self.world_from_tree);
        meshes
    }
}

/// Measures the tree the marks show in the tracked footage, chooses the species (`species`, or
/// the preset closest to the measured proportions), grows it into the hull (at most
/// `max_years`) and scores its silhouette against each outline. With the footage's images
/// (`images`) the crown is also segmented in its frames and the hull carved again by those
/// silhouettes ([`segment`]): growth fills the real crown's lobes, not the outlines' convex
/// hull. The `sylva recreate` command and the app's Recreate mode both come here. The marks
/// must already be checked against the footage's size ([`marks::Marks::validate`]).
///
/// `metres_per_unit` is the metres in one unit of the footage's world: 1 for
/// [`footage::track_footage`]'s (already metric), the design's scale for the tracker's world
/// in the app. The measures stay in the world's units; the tree grows in metres and
/// `world_from_tree` carries `S(1 / metres_per_unit)`.
pub fn recreate(
    footage: &footage::TrackedFootage,
    marks: &marks::Marks,
    species: Option<sylva_core::species::Species>,
    seed: u64,
    max_years: f32,
    images: Option<segment::FrameSource>,
    metres_per_unit: f64,
) -> Result<Recreated, marks::MarksError> {
    let mut recreation = measure::measure(footage, marks)?;
    let m = &recreation.measurements;
    let (species, choice) = match species {
        Some(s) => (s, "given".to_owned()),
        None => grow::closest_species(m.height_m, m.crown_width_m),
    };
    let marked: Vec<usize> = recreation.masks.iter().map(|mask| mask.frame).collect();
    let frames = segment::carve_frames(footage, &marked);
    let crown_masks = images
        .map(|load| segment::segment_frames(footage, &recreation.hull, &frames, load))
        .unwrap_or_default();
    // The real trunk in those frames: where it stands (the base moves onto it) and how thick.
    let trunk = images.and_then(|load| {
        trunk::find_trunk(
            footage,
            recreation.base,
            marks.base.frame,
            recreation.measurements.crown_base_m,
            &frames,
            load,
        )
    });
    if let Some(found) = &trunk {
        recreation.base = glam::DVec3::from_array(found.base);
        recreation.measurements.trunk_base = found.base;
        recreation.measurements.methods.trunk_base += &format!(
            ", moved {:.3} m onto the trunk seen in {} of {} views",
            found.shift_m, found.agreeing_views, found.views
        );
    }
    // The crown's volume: the hull carved again by the segmented silhouettes, else the hull.
    let segmented = !crown_masks.is_empty();
    let crown = if segmented {
        segment::carve_by_silhouettes(footage, &recreation.hull, &crown_masks)
    } else {
        recreation.hull.clone()
    };
    // The crown's views the tree should cover: its segmented silhouettes, else the outlines.
    let targets: Vec<fit::CrownTarget> = if crown_masks.is_empty() {
        let (w, h) = (footage.camera.width, footage.camera.height);
        (recreation.masks.iter())
            .map(|mask| fit::CrownTarget {
                frame: mask.frame,
                inside: (0..h)
                    .flat_map(|y| (0..w).map(move |x| (x, y)))
                    .map(|(x, y)| mask.contains(glam::DVec2::new(x as f64, y as f64)))
                    .collect(),
            })
            .collect()
    } else {
        (crown_masks.iter())
            .map(|mask| fit::CrownTarget {
                frame: mask.frame,
                inside: mask.inside.clone(),
            })
            .collect()
    };
    // Growth and the foliage are scored on a few of them (the marked ones first).
    let scored: Vec<&fit::CrownTarget> = fit::spread(&targets, &marked, GROWTH_VIEWS);
    let placed = grow::world_from_tree(recreation.base, footage.ground.normal, metres_per_unit);
    let score = |tree: &sylva_core::Tree| fit::foliage_iou(tree, &placed, footage, &scored);
    let coverage: grow::Coverage = &score;
    let (tree, world_from_tree, mut growth) = grow::grow_into_hull(
        species,
        choice,
        seed,
        &recreation,
        grow::Guide {
            crown: Some(&crown),
            coverage: Some(coverage),
        },
        placed,
        max_years,
    );
    let mut tree = tree;
    if let Some(found) = &trunk {
        // Tree space is in metres: the world's lengths scaled by the placement's.
        let metres = 1.0 / f64::from(world_from_tree.matrix3.x_axis.length());
        let at = (0.5 * recreation.measurements.crown_base_m * metres) as f32;
        let diameter_m = found.diameter_m * metres;
        growth.trunk_width_ratio = Some(trunk::fit_trunk_diameter(&mut tree, diameter_m, at));
    }
    growth.trunk = trunk;
    growth.segmented_views = crown_masks.len();
    growth.crown_voxels = segmented.then(|| crown.num_voxels());
    let mut recreated = Recreated {
        recreation,
        tree,
        world_from_tree,
        growth,
        outline_iou: Vec::new(),
        crown_masks,
    };
    let model =
        silhouette::WorldTriangles::of_meshes(&recreated.world_meshes(), &Affine3A::IDENTITY);
    recreated.outline_iou = recreated
        .recreation
        .masks
        .iter()
        .map(|mask| {
            let seen = silhouette::Silhouette::render(footage, mask.frame, &model);
            (mask.frame, seen.iou_with_outline(mask))
        })
        .collect();
    Ok(recreated)
}
