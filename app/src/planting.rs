//! Where the tree stands and how the real scene shapes it.
//!
//! **Planting.** The tree is grown in its own space (metres, Y up, the trunk base at the origin);
//! `world_from_tree` places it in the tracked world. A tap on the ground plane plants it where
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

/// The tree planted at `point` on `ground`, its Y axis along the ground's normal.
pub fn world_from_tree_at(point: Vec3, ground: &GroundPlane) -> Affine3A {
    let up = ground.normal.try_normalize().unwrap_or(Vec3::Y);
    Affine3A::from_rotation_translation(Quat::from_rotation_arc(Vec3::Y, up), point)
}

/// `camera` (in the world) seen from tree space.
pub fn camera_in_tree(camera: &ViewCamera, tree_from_world: &Affine3A) -> ViewCamera {
    if *tree_from_world == Affine3A::IDENTITY {
        return *camera;
    }
    ViewCamera {
        world_from_camera: Mat4::from(*tree_from_world) * camera.world_from_camera,
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

/// The ground plane (in the world) in tree space.
pub fn ground_in_tree(ground: &GroundPlane, tree_from_world: &Affine3A) -> GroundPlane {
    if *tree_from_world == Affine3A::IDENTITY {
        return *ground;
    }
    // A rigid motion keeps the normal's length.
    GroundPlane {
        point: tree_from_world.transform_point3(ground.point),
        normal: tree_from_world.transform_vector3(ground.normal),
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
    (map.num_keyframes() > 0).then_some(TreeScene {
        map,
        world_from_tree: world_from_tree?,
        ground_clearance_m: sylva_tracking::occupancy::OccupancyConfig::default().voxel_size_m,
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
        self.world_from_tree = Some(world_from_tree_at(point, &ground));
        self.update_tree_camera();
        self.changed();
        true
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
        let ground = GroundPlane::default();
        let world_from_tree = world_from_tree_at(Vec3::new(0.5, 0.0, -0.3), &ground);
        let tree_camera = camera_in_tree(&camera, &world_from_tree.inverse());
        let top_in_tree = Vec3::new(0.0, 1.0, 0.0);
        let a = tree_camera.pixel_from_world(top_in_tree).unwrap();
        let b = camera
            .pixel_from_world(world_from_tree.transform_point3(top_in_tree))
            .unwrap();
        assert!(a.distance(b) < 1e-3, "{a} vs {b}");
    }
}
