//! Depth-mesh tests: analytic scenes with exact answers, incremental updates, bad input.

use glam::{Affine3A, Mat3, Vec2, Vec3};

use super::*;

/// Fixed seed for every random test input.
const SEED: u64 = 0x5eed_de97;

pub(crate) struct SplitMix(pub(crate) u64);

impl SplitMix {
    pub(crate) fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
}

pub(crate) fn camera() -> PinholeIntrinsics {
    PinholeIntrinsics {
        width: 640,
        height: 480,
        fx: 525.0,
        fy: 525.0,
        cx: 319.5,
        cy: 239.5,
    }
}

/// Camera at `position` looking along −Z, pitched down by `pitch_deg` (world Y up).
fn looking_down(position: Vec3, pitch_deg: f32) -> Affine3A {
    let pitch = pitch_deg.to_radians();
    let forward = Vec3::new(0.0, -pitch.sin(), -pitch.cos());
    let right = forward.cross(Vec3::Y).normalize();
    let down = forward.cross(right);
    Affine3A::from_mat3_translation(Mat3::from_cols(right, down, forward), position)
}

/// An analytic scene: optional ground (y = 0) and axis-aligned boxes, seen by one camera.
struct Scene {
    name: &'static str,
    ground: bool,
    boxes: Vec<(Vec3, Vec3)>,
    world_from_camera: Affine3A,
}

impl Scene {
    /// Camera Z of the first surface behind `pixel`, if any.
    fn depth(&self, pixel: Vec2) -> Option<f32> {
        let cam = camera();
        let ray_in_camera = Vec3::new(
            (pixel.x - cam.cx) / cam.fx,
            (pixel.y - cam.cy) / cam.fy,
            1.0,
        );
        let origin = Vec3::from(self.world_from_camera.translation);
        let direction = self.world_from_camera.transform_vector3(ray_in_camera);
        let mut best = f32::INFINITY;
        if self.ground && direction.y < -1e-9 {
            best = -origin.y / direction.y;
        }
        for &(min, max) in &self.boxes {
            let (mut near, mut far) = (0.0_f32, best);
            for axis in 0..3 {
                let (t0, t1) = (
                    (min[axis] - origin[axis]) / direction[axis],
                    (max[axis] - origin[axis]) / direction[axis],
                );
                near = near.max(t0.min(t1));
                far = far.min(t0.max(t1));
            }
            if near <= far && near < best {
                best = near;
            }
        }
        // `direction` has camera Z = 1, so the ray parameter is the depth.
        (best.is_finite() && best < 50.0).then_some(best)
    }

    /// Feature-like points: a jittered grid, plus points along every visible box edge and just
    /// beside it on both sides (where a corner detector fires: silhouettes and creases).
    fn sample_points(&self, rng: &mut SplitMix) -> Vec<Observation> {
        let cam = camera();
        let mut points = Vec::new();
        let push = |pixel: Vec2, points: &mut Vec<Observation>| {
            if cam.contains(pixel)
                && let Some(depth_m) = self.depth(pixel)
            {
                points.push(Observation {
                    id: points.len() as u64,
                    pixel,
                    depth_m,
                });
            }
        };
        for row in 0..=30 {
            for column in 0..=40 {
                let jitter = Vec2::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 10.0;
                let pixel = (Vec2::new(column as f32, row as f32) * 16.0 + jitter)
                    .clamp(Vec2::ZERO, Vec2::new(639.0, 479.0));
                push(pixel, &mut points);
            }
        }
        let camera_from_world = self.world_from_camera.inverse();
        for &(min, max) in &self.boxes {
            for (a, b) in box_edges(min, max) {
                let (pa, pb) = (
                    camera_from_world.transform_point3(a),
                    camera_from_world.transform_point3(b),
                );
                let num_steps = 200;
                for i in 0..=num_steps {
                    let p = pa.lerp(pb, i as f32 / num_steps as f32);
                    let Some(pixel) = cam.pixel_from_camera(p) else {
                        continue;
                    };
                    let visible = self
                        .depth(pixel)
                        .is_some_and(|z| (z - p.z).abs() < 2e-3 * p.z);
                    if !visible || !cam.contains(pixel) || i % 2 == 1 {
                        continue;
                    }
                    let along =
                        (cam.pixel_from_camera(pb).unwrap_or(pixel) - pixel).normalize_or(Vec2::X);
                    let across = along.perp() * 2.5;
                    push(pixel, &mut points);
                    push(pixel + across, &mut points);
                    push(pixel - across, &mut points);
                }
            }
        }
        points
    }
}

fn box_edges(min: Vec3, max: Vec3) -> Vec<(Vec3, Vec3)> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    let mut edges = Vec::new();
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                edges.push((corner(i), corner(i | bit)));
            }
        }
    }
    edges
}

fn scenes() -> Vec<Scene> {
    let standing = looking_down(Vec3::new(0.0, 1.5, 3.0), 30.0);
    vec![
        Scene {
            name: "plane",
            ground: true,
            boxes: vec![],
            world_from_camera: standing,
        },
        Scene {
            name: "plane + box",
            ground: true,
            boxes: vec![(Vec3::new(-0.3, 0.0, -0.3), Vec3::new(0.3, 0.6, 0.3))],
            world_from_camera: standing,
        },
        Scene {
            name: "plane + wall",
            ground: true,
            boxes: vec![(Vec3::new(-3.0, 0.0, -1.2), Vec3::new(3.0, 2.0, -1.0))],
            world_from_camera: standing,
        },
        Scene {
            name: "thin pole in front of a wall",
            ground: true,
            boxes: vec![
                (Vec3::new(-5.0, 0.0, -0.2), Vec3::new(5.0, 2.5, 0.0)),
                (Vec3::new(-0.04, 0.0, 1.16), Vec3::new(0.04, 2.0, 1.24)),
            ],
            world_from_camera: looking_down(Vec3::new(0.0, 1.2, 3.0), 10.0),
        },
    ]
}

/// Pixels within `band_px` of a silhouette (a jump of more than 5 % in true depth, or
/// surface next to nothing).
fn silhouette_band(scene: &Scene, band_px: i32) -> Vec<bool> {
    let (w, h) = (640i32, 480i32);
    let depth: Vec<Option<f32>> = (0..w * h)
        .map(|i| scene.depth(Vec2::new((i % w) as f32, (i / w) as f32)))
        .collect();
    let edge = |a: Option<f32>, b: Option<f32>| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() > 0.05 * a.min(b),
        (None, None) => false,
        _ => true,
    };
    let mut band = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let here = depth[(y * w + x) as usize];
            let jump = (x + 1 < w && edge(here, depth[(y * w + x + 1) as usize]))
                || (y + 1 < h && edge(here, depth[((y + 1) * w + x) as usize]));
            if jump {
                for dy in -band_px..=band_px + 1 {
                    for dx in -band_px..=band_px + 1 {
                        let (bx, by) = (x + dx, y + dy);
                        if bx >= 0 && by >= 0 && bx < w && by < h {
                            band[(by * w + bx) as usize] = true;
                        }
                    }
                }
            }
        }
    }
    band
}

/// Fraction of queries (every other pixel outside the band, a point 5 cm in front of and
/// 5 cm behind the true surface, or at 5 m where there is none) answered like the scene.
fn accuracy(scene: &Scene, mesh: &DepthMesh) -> (f64, f64) {
    let band = silhouette_band(scene, 2);
    let (mut correct, mut total, mut covered, mut pixels) = (0usize, 0usize, 0usize, 0usize);
    for y in (0..480).step_by(2) {
        for x in (0..640).step_by(2) {
            if band[y * 640 + x] {
                continue;
            }
            let pixel = Vec2::new(x as f32, y as f32);
            pixels += 1;
            covered += usize::from(mesh.depth_at(pixel).depth_m().is_some());
            let queries = match scene.depth(pixel) {
                Some(z) => vec![(z - 0.05, false), (z + 0.05, true)],
                None => vec![(5.0, false)],
            };
            for (depth, hidden) in queries {
                let point = camera().camera_from_pixel(pixel, depth);
                total += 1;
                correct += usize::from(mesh.is_hidden_in_camera(point, 0.0) == hidden);
            }
        }
    }
    (
        correct as f64 / total as f64,
        covered as f64 / pixels as f64,
    )
}

#[test]
fn analytic_scenes_are_classified_like_the_truth_outside_silhouette_bands() {
    for (index, scene) in scenes().iter().enumerate() {
        for outlier_fraction in [0.0, 0.2] {
            let mut rng = SplitMix(SEED + index as u64);
            let mut points = scene.sample_points(&mut rng);
            let num_outliers =
                (points.len() as f32 * outlier_fraction / (1.0 - outlier_fraction)) as usize;
            for _ in 0..num_outliers {
                let pixel = Vec2::new(rng.next_f32() * 639.0, rng.next_f32() * 479.0);
                let depth_m = 0.3 + rng.next_f32() * 12.0;
                points.push(Observation {
                    id: points.len() as u64,
                    pixel,
                    depth_m,
                });
            }
            let num_true_points = points.len() - num_outliers;
            let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
            let stats = mesh.update(&points);
            let wrongly_rejected = (0..num_true_points as u64)
                .filter(|&id| mesh.vertex(id).is_some() && !mesh.is_consistent(id))
                .count();
            let wrongly_kept = (num_true_points as u64..points.len() as u64)
                .filter(|&id| mesh.is_consistent(id))
                .count();
            mesh.sanity_check();
            let (accuracy, coverage) = accuracy(scene, &mesh);
            println!(
                "{:<30} outliers {:>3.0}%: {} points, {} inconsistent ({} true points, {} outliers kept), coverage {:.1}%, accuracy {:.2}%",
                scene.name,
                outlier_fraction * 100.0,
                points.len(),
                stats.num_inconsistent,
                wrongly_rejected,
                wrongly_kept,
                coverage * 100.0,
                accuracy * 100.0
            );
            assert!(
                accuracy >= 0.99,
                "{} with {}% outliers: accuracy {:.4} < 0.99",
                scene.name,
                outlier_fraction * 100.0,
                accuracy
            );
        }
    }
}

#[test]
fn depth_on_a_plane_is_exact_inside_triangles() {
    let scene = &scenes()[0];
    let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
    mesh.update(&scene.sample_points(&mut SplitMix(SEED)));
    for pixel in [
        Vec2::new(100.5, 300.25),
        Vec2::new(320.0, 240.0),
        Vec2::new(600.0, 50.0),
    ] {
        let truth = scene.depth(pixel).expect("ground");
        let depth = mesh.depth_at(pixel).depth_m().expect("known");
        assert!(
            (depth - truth).abs() < 1e-4 * truth,
            "at {pixel}: {depth} vs {truth}"
        );
    }
}

#[test]
fn invalid_observations_are_refused_with_a_reason() {
    let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
    let bad = [
        Observation {
            id: 1,
            pixel: Vec2::new(f32::NAN, 3.0),
            depth_m: 1.0,
        },
        Observation {
            id: 2,
            pixel: Vec2::new(-1.0, 3.0),
            depth_m: 1.0,
        },
        Observation {
            id: 3,
            pixel: Vec2::new(640.0, 3.0),
            depth_m: 1.0,
        },
        Observation {
            id: 4,
            pixel: Vec2::new(5.0, 3.0),
            depth_m: f32::INFINITY,
        },
        Observation {
            id: 5,
            pixel: Vec2::new(5.0, 3.0),
            depth_m: -2.0,
        },
    ];
    for observation in bad {
        assert!(
            mesh.insert(observation).is_err(),
            "{observation:?} accepted"
        );
    }
    mesh.insert(Observation {
        id: 6,
        pixel: Vec2::new(5.0, 3.0),
        depth_m: 1.0,
    })
    .expect("valid point");
    let duplicate = mesh.insert(Observation {
        id: 7,
        pixel: Vec2::new(5.0, 3.0),
        depth_m: 2.0,
    });
    assert!(
        matches!(
            duplicate,
            Err(DepthMeshError::DuplicatePosition { other: 6, .. })
        ),
        "{duplicate:?}"
    );
    assert_eq!(
        mesh.vertex(6).map(|v| v.depth_m),
        Some(1.0),
        "duplicate overwrote the first point"
    );
    assert!(matches!(
        mesh.remove(99),
        Err(DepthMeshError::UnknownPoint { id: 99 })
    ));
    mesh.sanity_check();
}

#[test]
fn an_update_inserts_moves_and_removes_without_stale_handles() {
    let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
    let frame = |shift: f32, skip: u64| -> Vec<Observation> {
        (0..200u64)
            .filter(|id| id % 7 != skip)
            .map(|id| Observation {
                id,
                pixel: Vec2::new(
                    20.0 + (id % 20) as f32 * 30.0 + shift,
                    20.0 + (id / 20) as f32 * 40.0,
                ),
                depth_m: 2.0 + id as f32 * 0.001,
            })
            .collect()
    };
    let first = mesh.update(&frame(0.0, 0));
    assert_eq!((first.num_inserted, first.num_removed), (171, 0));
    let second = mesh.update(&frame(3.0, 1));
    assert_eq!(second.num_removed, 29, "{second:?}");
    assert_eq!(second.num_inserted, 29, "{second:?}");
    assert_eq!(second.num_moved, 142, "{second:?}");
    mesh.sanity_check();
    for id in (0..200u64).filter(|id| id % 7 != 1) {
        let vertex = mesh.vertex(id).expect("held");
        assert_eq!(vertex.id, id);
        assert!((vertex.pixel.x - (23.0 + (id % 20) as f32 * 30.0)).abs() < 1e-4);
    }
}

#[test]
fn the_export_holds_only_known_triangles_in_camera_space() {
    let scene = &scenes()[3];
    let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
    mesh.update(&scene.sample_points(&mut SplitMix(SEED)));
    let export = mesh.export_camera_space();
    assert!(!export.indices.is_empty() && export.indices.len().is_multiple_of(3));
    assert!(
        !export.unknown_wireframe.is_empty(),
        "the pole's silhouettes must give unknown triangles"
    );
    assert_eq!(export.wireframe.len(), export.indices.len() * 2);
    for &i in &export.indices {
        let p = export.positions[i as usize];
        let pixel = camera().pixel_from_camera(p).expect("in front");
        let truth = scene.depth(pixel).expect("surface");
        assert!(
            (p.z - truth).abs() < 1e-3 * truth + 1e-4,
            "vertex off the scene"
        );
    }
    let world = export.to_world(&scene.world_from_camera);
    assert!(
        world.positions.iter().all(|p| p.y > -1e-3 && p.y < 2.6),
        "world vertices off the scene"
    );
}
