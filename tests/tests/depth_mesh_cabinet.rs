//! Depth mesh on real data (issue 6, Done-when 2): on tum_fr3_cabinet, corners found by a
//! Shi–Tomasi detector in each colour keyframe get their depth from the registered depth map;
//! the mesh of those points then classifies, per pixel, a virtual point 5 cm in front of and
//! 5 cm behind the measured surface. At least 95 % of the covered pixels (pooled over the 58
//! keyframes) must be right, and every keyframe at least 90 %.

use std::fs;
use std::path::Path;

use glam::Vec2;
use sylva_tests::corners::shi_tomasi;
use sylva_tests::shared_data_dir;
use sylva_tracking::Camera;
use sylva_tracking::depth_mesh::{DepthMesh, DepthMeshConfig, Observation, PinholeIntrinsics};

struct FrameResult {
    num_corners: usize,
    num_queries: usize,
    num_correct: usize,
    coverage: f64,
    accuracy: f64,
}

fn evaluate_frame(
    root: &Path,
    rgb: &str,
    depth: &str,
    camera: PinholeIntrinsics,
    scale: f32,
) -> FrameResult {
    let grey_image = image::open(root.join(rgb))
        .unwrap_or_else(|e| panic!("{rgb}: {e}"))
        .into_luma8();
    let depth_image = image::open(root.join(depth))
        .unwrap_or_else(|e| panic!("{depth}: {e}"))
        .into_luma16();
    let (width, height) = (grey_image.width() as usize, grey_image.height() as usize);
    let grey: Vec<f32> = grey_image.pixels().map(|p| p.0[0] as f32).collect();
    let depth_m: Vec<f32> = depth_image
        .pixels()
        .map(|p| p.0[0] as f32 / scale)
        .collect();
    let corners = shi_tomasi(&grey, width, height, 800, 8);
    let observations: Vec<Observation> = corners
        .iter()
        .filter_map(|&pixel| {
            let depth = depth_m[pixel.y as usize * width + pixel.x as usize];
            (depth > 0.0).then_some(Observation {
                id: 0,
                pixel,
                depth_m: depth,
            })
        })
        .enumerate()
        .map(|(id, o)| Observation { id: id as u64, ..o })
        .collect();
    // Few corners on this texture-poor floor: allow longer edges than the default.
    let config = DepthMeshConfig {
        max_edge_px: 160.0,
        ..DepthMeshConfig::default()
    };
    let mut mesh = DepthMesh::new(camera, config);
    mesh.update(&observations);
    let (mut pixels, mut covered, mut correct, mut queries) = (0usize, 0usize, 0usize, 0usize);
    for y in (0..height).step_by(3) {
        for x in (0..width).step_by(3) {
            let truth = depth_m[y * width + x];
            if truth <= 0.0 {
                continue;
            }
            pixels += 1;
            let pixel = Vec2::new(x as f32, y as f32);
            if mesh.depth_at(pixel).depth_m().is_none() {
                continue;
            }
            covered += 1;
            for (offset_m, hidden) in [(-0.05, false), (0.05, true)] {
                let point = camera.camera_from_pixel(pixel, truth + offset_m);
                queries += 1;
                correct += usize::from(mesh.is_hidden_in_camera(point, 0.0) == hidden);
            }
        }
    }
    FrameResult {
        num_corners: observations.len(),
        num_queries: queries,
        num_correct: correct,
        coverage: covered as f64 / pixels.max(1) as f64,
        accuracy: correct as f64 / queries.max(1) as f64,
    }
}

#[test]
fn cabinet_occlusion_from_corner_depths_is_right_on_95_percent_of_covered_pixels() {
    let root = shared_data_dir().join("tum_fr3_cabinet");
    let camera = Camera::from_file(&root.join("camera.txt")).expect("camera.txt");
    let scale = camera.depth_scale.unwrap_or(5000.0) as f32;
    let associations = fs::read_to_string(root.join("associations.txt")).expect("associations.txt");
    let mut results = Vec::new();
    for line in associations
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
    {
        let fields: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(fields.len(), 4, "associations.txt: bad line '{line}'");
        let result = evaluate_frame(
            &root,
            fields[1],
            fields[3],
            PinholeIntrinsics::from(&camera),
            scale,
        );
        println!(
            "{}: {} corners, coverage {:.1}%, accuracy {:.2}%",
            fields[1],
            result.num_corners,
            result.coverage * 100.0,
            result.accuracy * 100.0
        );
        results.push(result);
    }
    assert_eq!(results.len(), 58, "the cabinet clip has 58 keyframes");
    let mean =
        |f: fn(&FrameResult) -> f64| results.iter().map(f).sum::<f64>() / results.len() as f64;
    let worst = results.iter().map(|r| r.accuracy).fold(1.0, f64::min);
    println!(
        "mean coverage {:.1}%, mean accuracy {:.2}%, worst frame {:.2}%",
        mean(|r| r.coverage) * 100.0,
        mean(|r| r.accuracy) * 100.0,
        worst * 100.0
    );
    assert!(
        mean(|r| r.coverage) > 0.5,
        "the mesh covers only {:.1}% of the depth pixels",
        mean(|r| r.coverage) * 100.0
    );
    let pooled = results.iter().map(|r| r.num_correct).sum::<usize>() as f64
        / results.iter().map(|r| r.num_queries).sum::<usize>().max(1) as f64;
    println!(
        "pooled accuracy over all covered pixels {:.2}%",
        pooled * 100.0
    );
    assert!(
        pooled >= 0.95,
        "accuracy over the covered pixels {pooled:.4} < 0.95"
    );
    for (index, result) in results.iter().enumerate() {
        assert!(
            result.accuracy >= 0.90,
            "keyframe {index}: accuracy {:.4} < 0.90",
            result.accuracy
        );
    }
}
