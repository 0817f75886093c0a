//! Property tests: random insert / remove / move sequences, including duplicate and
//! degenerate (collinear, coincident) positions, keep the mesh valid and never panic.

use glam::Vec2;
use proptest::prelude::*;

use super::tests::camera;
use super::*;

#[derive(Clone, Debug)]
enum Op {
    Insert {
        id: u64,
        u: f32,
        v: f32,
        depth_m: f32,
    },
    Remove {
        id: u64,
    },
    Update {
        ids: Vec<u64>,
        shift: f32,
    },
}

fn coordinate() -> impl Strategy<Value = f32> {
    // Few distinct values: duplicates and collinear points are frequent. Some are invalid.
    prop_oneof![
        (0u32..8).prop_map(|i| i as f32 * 80.0),
        0.0f32..640.0,
        Just(f32::NAN),
        Just(-3.0f32),
        Just(1e9f32),
    ]
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        4 => (0u64..40, coordinate(), coordinate(), prop_oneof![0.5f32..8.0, Just(0.0f32), Just(f32::INFINITY)])
            .prop_map(|(id, u, v, depth_m)| Op::Insert { id, u, v, depth_m }),
        2 => (0u64..40).prop_map(|id| Op::Remove { id }),
        1 => (proptest::collection::vec(0u64..40, 0..30), -20.0f32..20.0).prop_map(|(ids, shift)| Op::Update { ids, shift }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_edit_sequences_keep_the_mesh_valid(ops in proptest::collection::vec(op(), 1..60)) {
        let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
        for op in ops {
            match op {
                Op::Insert { id, u, v, depth_m } => {
                    let _ = mesh.insert(Observation { id, pixel: Vec2::new(u, v), depth_m });
                }
                Op::Remove { id } => {
                    let held = mesh.vertex(id).is_some();
                    prop_assert_eq!(mesh.remove(id).is_ok(), held);
                }
                Op::Update { ids, shift } => {
                    let observations: Vec<Observation> = ids
                        .iter()
                        .map(|&id| Observation {
                            id,
                            pixel: Vec2::new((id % 8) as f32 * 80.0 + shift.abs(), (id / 8) as f32 * 60.0),
                            depth_m: 1.0 + id as f32 * 0.1,
                        })
                        .collect();
                    mesh.update(&observations);
                }
            }
            mesh.sanity_check();
            prop_assert!(mesh.num_surface_points() <= mesh.num_points());
            for probe in [Vec2::new(100.0, 100.0), Vec2::new(320.0, 240.0), Vec2::new(f32::NAN, 1.0)] {
                if let Some(depth) = mesh.depth_at(probe).depth_m() {
                    prop_assert!(depth.is_finite() && depth > 0.0);
                }
            }
        }
    }
}

/// Inner faces of a layer as id triples (rotated to start at the smallest id, so the
/// counter-clockwise order is kept), sorted: equal for equal triangulations.
fn faces_by_id(layer: &super::layer::Layer) -> Vec<[u64; 3]> {
    use spade::Triangulation;
    let mut faces: Vec<[u64; 3]> = layer
        .triangles
        .inner_faces()
        .map(|face| {
            let ids = face.vertices().map(|v| v.data().id);
            let first = (0..3).min_by_key(|&i| ids[i]).unwrap_or(0);
            [ids[first], ids[(first + 1) % 3], ids[(first + 2) % 3]]
        })
        .collect();
    faces.sort_unstable();
    faces
}

/// Depth of a plane seen from 1.5 m, pitched down (inverse depth affine in the image).
fn plane_depth(pixel: Vec2) -> f32 {
    1.5 / (0.5 + 0.866 * (pixel.y - 239.5) / 525.0 + 0.05 * (pixel.x - 319.5) / 525.0)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Points in general position have one Delaunay triangulation, so frames of jittered,
    /// lost and new points (in-place moves, remove + insert, hints) must end in exactly the
    /// triangulation a fresh mesh builds from the same vertices.
    #[test]
    fn incremental_updates_end_in_the_triangulation_built_from_scratch(
        seed in any::<u64>(),
        num_points in 20usize..300,
        jitter_px in 0.3f32..12.0,
        num_frames in 1usize..6,
    ) {
        let mut rng = super::tests::SplitMix(seed);
        let random_pixel = |rng: &mut super::tests::SplitMix| {
            Vec2::new(rng.next_f32() * 639.0, rng.next_f32() * 479.0)
        };
        // One point in ten is an outlier (off the plane): the surface then differs from all
        // points, and inconsistent vertices move, vanish and appear too.
        let observation = |id: u64, pixel: Vec2| {
            let outlier = if id % 10 == 3 { 1.6 } else { 1.0 };
            Observation { id, pixel, depth_m: plane_depth(pixel) * outlier }
        };
        let mut frame: Vec<Observation> =
            (0..num_points as u64).map(|id| observation(id, random_pixel(&mut rng))).collect();
        let mut mesh = DepthMesh::new(camera(), DepthMeshConfig::default());
        mesh.update(&frame);
        let mut next_id = num_points as u64;
        for _ in 0..num_frames {
            for item in frame.iter_mut() {
                let roll = rng.next_f32();
                if roll < 0.1 {
                    *item = observation(next_id, random_pixel(&mut rng));
                    next_id += 1;
                } else if roll < 0.8 {
                    let step = Vec2::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 2.0 * jitter_px;
                    let pixel = (item.pixel + step).clamp(Vec2::ZERO, Vec2::new(639.0, 479.0));
                    *item = observation(item.id, pixel);
                }
            }
            frame.retain(|_| rng.next_f32() > 0.05);
            mesh.update(&frame);
            mesh.sanity_check();
        }
        // Points that moved less than the move tolerance keep their vertex where it was, so
        // the reference is built from the vertices held (every observation is held).
        let held: Vec<Observation> = frame
            .iter()
            .filter_map(|o| mesh.vertex(o.id))
            .map(|v| Observation { id: v.id, pixel: v.pixel, depth_m: v.depth_m })
            .collect();
        prop_assert_eq!(held.len(), frame.len());
        prop_assert_eq!(mesh.num_points(), frame.len());
        let mut fresh = DepthMesh::new(camera(), DepthMeshConfig::default());
        fresh.update(&held);
        prop_assert_eq!(faces_by_id(&mesh.all), faces_by_id(&fresh.all));
    }
}
