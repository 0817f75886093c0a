//! Where the tree stands and how the real scene shapes it.
//!
//! **Planting.** The tree is grown in its own space (metres, Y up, the trunk base at the origin);
//! `world_from_tree = T(base) · R(ground up) · S(1 / metres_per_unit)` places it in the tracked
//! world, whose unit is the tracker's, at the design's scale ([`crate::scale::TreeScale`]): the
//! camera seen from tree space is kept rigid (so depths there are metres), the ground's normal
//! is renormalised, and the scene's lowest voxel layer is converted to metres. A tap on the
//! ground plane plants it where
//! the ray from the tapped pixel through the frame's camera meets the plane, and dragging the
//! trunk base moves it. Everything that meets the world goes through that transform: the design
//! state sees the camera in tree space (so picking and the brush plane are in tree space), the
//! renderer draws the frame in tree space (camera, occluder and ground moved by
//! `tree_from_world`), and the scene answers core's [`Scene`] in tree space.
//!
//! **Scene modes** (Longay 2014 §5.4.3): free growth, growth in front of the scene (attraction
//! points in occupied space are dropped and no shoot may enter it) and pruning to the scene
//! (branches that entered it are cut). The scene is the occupancy map built from the depth
//! meshes of the keyframes' tracked points ([`crate::scene_tracking::SceneOccupancy`]).

use glam::{Affine3A, Mat4, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use sylva_core::environment::{Scene, SceneMode};
use sylva_tracking::depth_mesh::Observation;
use sylva_tracking::occupancy::OccupancyMap;

use crate::render::{GroundPlane, Intrinsics, OccluderMesh, ViewCamera};
use crate::scale::TreeScale;
use crate::scene_tracking::SceneOccupancy;
use crate::state::{DesignState, PICK_RADIUS_PX};

/// How growth reacts to the tracked scene (the UI's "scene" control; recorded with the
/// parameters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SceneChoice {
    /// The scene is ignored.
    #[default]
    Free,
    /// Grow in front of the scene: nothing grows into real objects.
    GrowInFront,
    /// Grow freely and cut what entered real objects (choosing it cuts at once).
    PruneToScene,
}

impl SceneChoice {
    pub const ALL: [SceneChoice; 3] = [
        SceneChoice::Free,
        SceneChoice::GrowInFront,
        SceneChoice::PruneToScene,
    ];

    /// Core's growth mode, `None` for free growth.
    pub fn mode(self) -> Option<SceneMode> {
        match self {
            SceneChoice::Free => None,
            SceneChoice::GrowInFront => Some(SceneMode::GrowInFront),
            SceneChoice::PruneToScene => Some(SceneMode::PruneToScene),
        }
    }

    /// The control's label.
    pub fn label(self) -> &'static str {
        match self {
            SceneChoice::Free => "Free",
            SceneChoice::GrowInFront => "Grow in front of the scene",
            SceneChoice::PruneToScene => "Prune to the scene",
        }
    }
}

/// Where the ray through `pixel` of `camera` meets `ground` (None when it looks away from it).
pub fn ground_point_at_pixel(
    camera: &ViewCamera,
    ground: &GroundPlane,
    pixel: Vec2,
) -> Option<Vec3> {
    let origin = camera.position();
    let direction = camera
        .world_from_camera
        .transform_vector3(camera.intrinsics.ray_from_pixel(pixel));
    let along = direction.dot(ground.normal);
    if along.abs() < 1e-6 {
        return None;
    }
    let t = (ground.point - origin).dot(ground.normal) / along;
    (t > 0.0 && t.is_finite()).then(|| origin + direction * t)
}

/// The tree planted at `point` on `ground`, its Y axis along the ground's normal, at
/// `metres_per_unit` metres per unit of the world (tree space is metres):
/// `world_from_tree = T(point) · R(ground up) · S(1 / metres_per_unit)`.
pub fn world_from_tree_at(point: Vec3, ground: &GroundPlane, metres_per_unit: f32) -> Affine3A {
    let up = ground.normal.try_normalize().unwrap_or(Vec3::Y);
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(1.0 / metres_per_unit),
        Quat::from_rotation_arc(Vec3::Y, up),
        point,
    )
}

/// Metres per world unit of a `world_from_tree` (its uniform scale's inverse; 1 for a rigid
/// placement).
pub fn metres_per_unit_of(world_from_tree: &Affine3A) -> f32 {
    1.0 / world_from_tree.matrix3.x_axis.length()
}

/// A uniform scale of the world by `factor` about `centre` (what a new design scale does to
/// where trees stand: the centre stays, the rest moves).
pub fn world_scaled_about(centre: Vec3, factor: f32) -> Affine3A {
    Affine3A::from_translation(centre)
        * Affine3A::from_scale(Vec3::splat(factor))
        * Affine3A::from_translation(-centre)
}

/// `camera` (in the world) seen from tree space: a rigid camera (rotation as in the world,
/// position moved by `tree_from_world`), so it projects every tree point to the pixel where
/// the world camera projects the point's place in the world, and its depths are metres. Near and
/// far are scaled with the world.
pub fn camera_in_tree(camera: &ViewCamera, tree_from_world: &Affine3A) -> ViewCamera {
    if *tree_from_world == Affine3A::IDENTITY {
        return *camera;
    }
    let metres_per_unit = tree_from_world.matrix3.x_axis.length();
    let rotation = Mat4::from(*tree_from_world) * camera.world_from_camera;
    let position = tree_from_world.transform_point3(camera.position());
    let column = |c: glam::Vec4| (c.truncate() / metres_per_unit).extend(0.0);
    ViewCamera {
        world_from_camera: Mat4::from_cols(
            column(rotation.x_axis),
            column(rotation.y_axis),
            column(rotation.z_axis),
            position.extend(1.0),
        ),
        near: camera.near * metres_per_unit,
        far: camera.far * metres_per_unit,
        ..*camera
    }
}

/// The occluder (in the world) moved into tree space.
pub fn occluder_in_tree(occluder: &OccluderMesh, tree_from_world: &Affine3A) -> OccluderMesh {
    if *tree_from_world == Affine3A::IDENTITY {
        return occluder.clone();
    }
    OccluderMesh {
        positions: occluder
            .positions
            .iter()
            .map(|&p| tree_from_world.transform_point3(p))
            .collect(),
        indices: occluder.indices.clone(),
    }
}

/// The ground plane (in the world) in tree space (its normal of unit length: the placement
/// carries a scale).
pub fn ground_in_tree(ground: &GroundPlane, tree_from_world: &Affine3A) -> GroundPlane {
    if *tree_from_world == Affine3A::IDENTITY {
        return *ground;
    }
    let normal = tree_from_world.transform_vector3(ground.normal);
    GroundPlane {
        point: tree_from_world.transform_point3(ground.point),
        normal: normal.try_normalize().unwrap_or(normal),
    }
}

/// The tracked scene as core sees it: points in tree space, answered by the occupancy map in
/// the world. The lowest voxel layer above the ground is left to core's own ground rule (the
/// plane through the base): the ground's tracked points occupy it, and the trunk starts there.
pub struct TreeScene<'a> {
    pub map: &'a OccupancyMap,
    pub world_from_tree: Affine3A,
    /// Points of tree space lower than this (m) are judged by the ground rule alone.
    pub ground_clearance_m: f32,
}

impl Scene for TreeScene<'_> {
    fn is_free(&self, point_in_tree: Vec3) -> bool {
        point_in_tree.y < self.ground_clearance_m
            || self
                .map
                .is_free(self.world_from_tree.transform_point3(point_in_tree))
    }
}

/// The scene growth reacts to in `choice`, in tree space (None for free growth or without a
/// map).
pub(crate) fn growth_scene(
    choice: SceneChoice,
    occupancy: &Option<SceneOccupancy>,
    world_from_tree: Option<Affine3A>,
) -> Option<(TreeScene<'_>, SceneMode)> {
    Some((tree_scene(occupancy, world_from_tree)?, choice.mode()?))
}

/// The tracked scene in tree space, when the tree is planted and a map exists.
pub(crate) fn tree_scene(
    occupancy: &Option<SceneOccupancy>,
    world_from_tree: Option<Affine3A>,
) -> Option<TreeScene<'_>> {
    let map = occupancy.as_ref()?.map();
    let world_from_tree = world_from_tree?;
    // The voxel is sized in the tracker's unit; the clearance is in tree space (metres).
    let voxel_size = sylva_tracking::occupancy::OccupancyConfig::default().voxel_size_m;
    (map.num_keyframes() > 0).then_some(TreeScene {
        map,
        world_from_tree,
        ground_clearance_m: voxel_size * metres_per_unit_of(&world_from_tree),
    })
}

/// Planting and the scene, for the design state.
impl DesignState {
    /// Takes the scene of the frame about to be shown: its ground plane and, once the ground is
    /// found, its tracked points for the occupancy of the scene (call before
    /// [`Self::advance_frame`]).
    pub fn observe_scene(
        &mut self,
        intrinsics: &Intrinsics,
        world_from_camera: Option<Mat4>,
        ground: Option<GroundPlane>,
        observations: &[Observation],
    ) {
        self.ground = ground;
        self.scale
            .observe(intrinsics, world_from_camera, ground, observations);
        if self.tree_scale == TreeScale::Awaiting
            && self.is_planted()
            && let Some(scale) = self.scale.state.current()
        {
            // Planted before there was a scale: the first one is taken (once).
            self.set_tree_scale(TreeScale::Metric(scale));
        }
        self.occupancy
            .get_or_insert_with(|| SceneOccupancy::new(intrinsics))
            .observe(observations, world_from_camera, ground.is_some());
        self.recreate
            .observe(intrinsics, world_from_camera, ground, observations);
    }

    /// Builds the scene's occupancy on a worker thread (the window; replays build the same map
    /// inline, at the same frames).
    pub fn with_scene_worker(mut self, intrinsics: &Intrinsics) -> DesignState {
        self.occupancy = Some(SceneOccupancy::with_worker(intrinsics));
        self
    }

    /// The camera in the world (the tracked pose of the frame shown).
    pub fn world_camera(&self) -> Option<ViewCamera> {
        self.world_camera
    }

    /// Tree space from the world (identity before planting).
    pub fn tree_from_world(&self) -> Affine3A {
        self.world_from_tree.unwrap_or(Affine3A::IDENTITY).inverse()
    }

    /// Whether the tree is planted (shown and editable).
    pub fn is_planted(&self) -> bool {
        self.world_from_tree.is_some()
    }

    /// Number of keyframes in the occupancy of the scene.
    pub fn num_scene_keyframes(&self) -> usize {
        self.occupancy
            .as_ref()
            .map_or(0, |o| o.map().num_keyframes())
    }

    pub(crate) fn update_tree_camera(&mut self) {
        let tree_from_world = self.tree_from_world();
        self.camera = self
            .world_camera
            .filter(|_| self.is_planted())
            .map(|c| camera_in_tree(&c, &tree_from_world));
    }

    /// Plants (or moves) the tree where the ray through `pixel` meets the ground plane; false
    /// when there is no camera or ground yet, or the ray misses the ground.
    pub(crate) fn plant_at(&mut self, pixel: Vec2) -> bool {
        let (Some(camera), Some(ground)) = (self.world_camera, self.ground) else {
            return false;
        };
        let Some(point) = ground_point_at_pixel(&camera, &ground, pixel) else {
            return false;
        };
        if !self.is_planted() {
            // The design's scale is taken when its first tree is planted.
            self.tree_scale = self
                .scale
                .state
                .current()
                .map_or(TreeScale::Awaiting, TreeScale::Metric);
        }
        let metres_per_unit = self.tree_scale.metres_per_unit() as f32;
        self.world_from_tree = Some(world_from_tree_at(point, &ground, metres_per_unit));
        self.update_tree_camera();
        self.changed();
        true
    }

    /// An explicit scale event (a holding height entered, a known length marked): the design
    /// takes the current scale (nothing before planting, or while there is no scale).
    pub(crate) fn adopt_current_scale(&mut self) {
        if let (true, Some(scale)) = (self.is_planted(), self.scale.state.current()) {
            self.set_tree_scale(TreeScale::Metric(scale));
        }
    }

    /// Places every tree at `scale`: each keeps its size in metres (tree space does not change)
    /// and is scaled in the world about its trunk base, so it changes size in the image. A
    /// garden is scaled as one about its first tree's base (the garden's layout is metres in
    /// garden space), so the other trees' bases move with it.
    pub(crate) fn set_tree_scale(&mut self, scale: TreeScale) {
        let factor = (self.tree_scale.metres_per_unit() / scale.metres_per_unit()) as f32;
        self.tree_scale = scale;
        let Some(world_from_tree) = self.world_from_tree else {
            return;
        };
        if !(factor.is_finite() && factor > 0.0) || (factor - 1.0).abs() < 1e-7 {
            return;
        }
        let centre = self
            .garden_origin_in_world()
            .unwrap_or(Vec3::from(world_from_tree.translation));
        let world_from_old = world_scaled_about(centre, factor);
        self.world_from_tree = Some(world_from_old * world_from_tree);
        self.rescale_garden(&world_from_old);
        self.update_tree_camera();
        self.changed();
    }

    /// The status line: the scale's source and uncertainty, and what the tree is drawn at.
    pub fn scale_status(&self) -> String {
        match self.is_planted() {
            true => format!(
                "{} · {}",
                self.scale.state.status(),
                self.tree_scale.status()
            ),
            false => self.scale.state.status(),
        }
    }

    /// A touch starting on the trunk base drags the tree.
    pub(crate) fn begin_move(&mut self, id: u64, pixel: Vec2) -> bool {
        let on_base = self
            .camera
            .and_then(|c| c.pixel_from_world(Vec3::ZERO))
            .is_some_and(|base| base.distance(pixel) <= PICK_RADIUS_PX);
        if on_base {
            self.moving_base = Some(id);
        }
        on_base
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Intrinsics;

    #[test]
    fn a_tap_below_the_horizon_lands_on_the_ground_under_the_ray() {
        let intrinsics = Intrinsics::from_fov(640, 480, 60f32.to_radians());
        let camera = ViewCamera::looking_at(intrinsics, Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO);
        let ground = GroundPlane::default();
        let centre = camera.pixel_from_world(Vec3::new(0.4, 0.0, -0.2)).unwrap();
        let hit = ground_point_at_pixel(&camera, &ground, centre).expect("on the ground");
        assert!(hit.distance(Vec3::new(0.4, 0.0, -0.2)) < 1e-4, "hit {hit}");
        // Above the horizon the ray never meets the ground.
        let level = ViewCamera::looking_at(intrinsics, Vec3::new(0.0, 1.5, 3.0), Vec3::Y);
        assert!(ground_point_at_pixel(&level, &ground, Vec2::new(320.0, 0.0)).is_none());
    }

    #[test]
    fn the_camera_seen_from_tree_space_projects_tree_points_where_the_world_ones_were() {
        let intrinsics = Intrinsics::from_fov(640, 480, 60f32.to_radians());
        let camera = ViewCamera::looking_at(intrinsics, Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO);
        let ground = GroundPlane {
            point: Vec3::ZERO,
            normal: Vec3::new(0.05, 1.0, -0.03).normalize(),
        };
        // Rigid, and with a world whose unit is 0.63 m (a tracker 1.59× too large).
        for metres_per_unit in [1.0, 0.63] {
            // A base on the tilted ground.
            let base = Vec3::new(0.5, -0.034, -0.3);
            let world_from_tree = world_from_tree_at(base, &ground, metres_per_unit);
            assert!((metres_per_unit_of(&world_from_tree) - metres_per_unit).abs() < 1e-6);
            let tree_camera = camera_in_tree(&camera, &world_from_tree.inverse());
            let rotation = glam::Mat3::from_mat4(tree_camera.world_from_camera);
            assert!(
                (rotation.transpose() * rotation).abs_diff_eq(glam::Mat3::IDENTITY, 1e-5),
                "the tree camera is rigid"
            );
            for point_in_tree in [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.4, 2.5, -0.7)] {
                let point_in_world = world_from_tree.transform_point3(point_in_tree);
                let a = tree_camera.pixel_from_world(point_in_tree).unwrap();
                let b = camera.pixel_from_world(point_in_world).unwrap();
                assert!(
                    a.distance(b) < 1e-3,
                    "{a} vs {b} at {metres_per_unit} m/unit"
                );
                // Depths in tree space are metres: the world's depth times the scale.
                let depth_m = tree_camera.depth_of(point_in_tree);
                let depth_units = camera.depth_of(point_in_world);
                assert!(
                    (depth_m - depth_units * metres_per_unit).abs() < 1e-4,
                    "{depth_m} m vs {depth_units} units"
                );
            }
            let ground_in_tree = ground_in_tree(&ground, &world_from_tree.inverse());
            assert!(ground_in_tree.normal.distance(Vec3::Y) < 1e-5);
            // The trunk base (tree space's origin) is on it.
            assert!(ground_in_tree.point.dot(ground_in_tree.normal).abs() < 1e-5);
        }
    }

    #[test]
    fn a_world_scale_about_the_base_keeps_the_base_and_sizes_the_tree() {
        let ground = GroundPlane::default();
        let base = Vec3::new(0.5, 0.0, -0.3);
        let before = world_from_tree_at(base, &ground, 1.0);
        let after = world_scaled_about(base, 1.0 / 0.63) * before;
        assert!(after.abs_diff_eq(world_from_tree_at(base, &ground, 0.63), 1e-6));
    }
}
