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
