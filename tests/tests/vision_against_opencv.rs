//! The portable vision backend (`sylva_tracking::vision`, what phones run) against OpenCV on
//! real footage: Shi–Tomasi corners, the essential-matrix pose and homography inliers on TUM
//! fr1_rpy frame pairs, PnP on the same correspondences. ORB is not compared bit for bit (the
//! portable backend's test pattern is its own, learned on other footage): it is compared by how
//! often its ratio-test matches are right.

use glam::{DVec2, DVec3, Vec2};
use sylva_tests::shared_data_dir;
use sylva_tracking::sequence::decode_gray;
use sylva_tracking::{GrayImage, TumSequence, cv, lk, vision};

fn frames(
    pairs: impl Iterator<Item = (usize, usize)>,
) -> (TumSequence, Vec<(GrayImage, GrayImage)>) {
    let root = shared_data_dir().join("tum_fr1_rpy");
    let sequence = TumSequence::open(&root).expect("fr1_rpy opens");
    let images = pairs
        .map(|(a, b)| {
            let get = |i: usize| {
                decode_gray(&sequence.frames[i].path, &sequence.camera).expect("frame decodes")
            };
            (get(a), get(b))
        })
        .collect();
    (sequence, images)
}

#[test]
fn portable_corners_are_opencvs() {
    let (_, images) = frames((0..700).step_by(50).map(|i| (i, i)));
    let (mut matched, mut total, mut counts) = (0usize, 0usize, (0usize, 0usize));
    for (image, _) in &images {
        let theirs = cv::detect_corners(image, 600, 10.0, &[]).expect("OpenCV corners");
        let ours = vision::detect_corners(image, 600, 10.0, &[]);
        counts.0 += ours.len();
        counts.1 += theirs.len();
        total += theirs.len();
        matched += theirs
            .iter()
            .filter(|c| ours.iter().any(|o| o.distance(**c) < 0.5))
            .count();
    }
    let summary = format!(
        "ours {} / OpenCV {}, same pixel {matched}",
        counts.0, counts.1
    );
    println!("{summary}");
    assert!(
        counts.0.abs_diff(counts.1) * 100 <= counts.1 * 2,
        "{summary}"
    );
    assert!(matched * 100 >= total * 95, "{summary}");
}

/// Corners of the first frame followed by Lucas–Kanade into the second, as normalised pairs.
fn tracked_pairs(sequence: &TumSequence, a: &GrayImage, b: &GrayImage) -> (Vec<DVec2>, Vec<DVec2>) {
    let corners = vision::detect_corners(a, 600, 10.0, &[]);
    let moved = lk::track_points(
        &lk::Pyramid::build(a),
        &lk::Pyramid::build(b),
        &corners,
        None,
        lk::LkOptions {
            levels: 3,
            max_fb_error_px: Some(2.0),
        },
    );
    let camera = &sequence.camera;
    corners
        .iter()
        .zip(moved)
        .filter_map(|(p, q): (&Vec2, Option<Vec2>)| {
            let q = q?;
            Some((
                camera.normalized_from_pixel(p.as_dvec2()),
                camera.normalized_from_pixel(q.as_dvec2()),
            ))
        })
        .unzip()
}

/// Both backends' relative rotations against the ground truth's, on pairs six frames apart:
/// short baselines of a mostly rotating camera, where the essential matrix is poorly
/// conditioned and neither backend is the truth.
#[test]
fn portable_two_view_geometry_is_as_good_as_opencvs() {
    let pairs: Vec<(usize, usize)> = (20..700).step_by(40).map(|i| (i, i + 6)).collect();
    let (sequence, images) = frames(pairs.iter().copied());
    let camera = sequence.camera;
    let (mut ours_err, mut theirs_err) = (Vec::new(), Vec::new());
    let mut five_err = Vec::new();
    let mut homography = (0usize, 0usize);
    for (&(i, j), (a, b)) in pairs.iter().zip(&images) {
        let (first, second) = tracked_pairs(&sequence, a, b);
        let truth = |k: usize| sequence.groundtruth_at(sequence.frames[k].timestamp_s, 0.05);
        let (Some(ga), Some(gb)) = (truth(i), truth(j)) else {
            continue;
        };
        // second_from_first = (world_from_second)⁻¹ · world_from_first.
        let relative = glam::DQuat::from_mat3(&(gb.inverse() * ga).matrix3).normalize();
        let theirs = cv::relative_pose(&camera, &first, &second, 1.0).expect("OpenCV");
        let ours = vision::relative_pose(&camera, &first, &second, 1.0);
        let five = vision::relative_pose_with(
            &camera,
            &first,
            &second,
            1.0,
            vision::EssentialMinimal::FivePoint,
        );
        if let (Some((t, _)), Some((o, _)), Some((f, _))) = (theirs, ours, five) {
            ours_err.push(o.rotation.angle_between(relative).to_degrees());
            theirs_err.push(t.rotation.angle_between(relative).to_degrees());
            five_err.push(f.rotation.angle_between(relative).to_degrees());
        }
        homography.0 += vision::homography_inliers(&camera, &first, &second, 1.0);
        homography.1 += cv::homography_inliers(&camera, &first, &second, 1.0).expect("OpenCV");
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let n = ours_err.len();
    let (ours, theirs, five) = (median(ours_err), median(theirs_err), median(five_err));
    let summary = format!(
        "{n} pairs, rotation error against ground truth: median ours {ours:.3}° (five-point {five:.3}°), OpenCV {theirs:.3}°; homography inliers ours {} / OpenCV {}",
        homography.0, homography.1
    );
    println!("{summary}");
    assert!(n >= 15, "{summary}");
    assert!(ours <= 1.25 * theirs + 0.05, "{summary}");
    assert!(five <= 1.25 * theirs + 0.05, "{summary}");
    // Model selection compares the homography's consensus with the essential matrix's: the
    // portable RANSAC must find at least OpenCV's.
    assert!(homography.0 * 100 >= homography.1 * 95, "{summary}");
}

#[test]
fn portable_pnp_finds_opencvs_pose() {
    // Map points from a known pose with 0.5 px noise and a third of them wrong.
    let camera = sylva_tracking::Camera::pinhole(640, 480, 517.3, 516.5, 318.6, 255.3);
    let truth = sylva_tracking::pose::Se3::new(
        glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.05, -0.2, 0.1),
        DVec3::new(0.1, -0.05, 0.3),
    );
    let inverse = truth.inverse();
    let mut state = 12345u64;
    let mut unit = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut world, mut image) = (Vec::new(), Vec::new());
    for k in 0..150 {
        let z = 1.0 + 3.0 * unit();
        let pc = DVec3::new((unit() - 0.5) * z, (unit() - 0.5) * 0.75 * z, z);
        world.push(inverse.transform_point(pc));
        let noise = DVec2::new(unit() - 0.5, unit() - 0.5) * (1.0 / 517.0);
        let wrong = if k % 3 == 0 {
            DVec2::new(unit() - 0.5, unit() - 0.5) * 0.3
        } else {
            DVec2::ZERO
        };
        image.push(pc.truncate() / pc.z + noise + wrong);
    }
    for minimal in [vision::PnpMinimal::Epnp, vision::PnpMinimal::Ap3p] {
        let (theirs, _) = cv::pnp_ransac(&camera, &world, &image, None, 4.0, 100, minimal)
            .expect("OpenCV")
            .expect("OpenCV finds a pose");
        let (ours, inliers) = vision::pnp_ransac(&camera, &world, &image, None, 4.0, 100, minimal)
            .expect("portable finds a pose");
        let gap = ours.rotation.angle_between(theirs.rotation).to_degrees();
        let shift = (ours.translation - theirs.translation).length();
        assert!(gap < 0.1 && shift < 0.005, "{minimal:?}: {gap}° {shift} m");
        assert!(ours.rotation.angle_between(truth.rotation).to_degrees() < 0.1);
        assert!(
            inliers.len() >= 95,
            "{minimal:?}: {} inliers",
            inliers.len()
        );
    }
}

/// Descriptor matching as keyframe re-finding and relocalisation use it (Hamming ≤ 40, ratio
/// 0.8), on fr1_rpy pairs five frames apart: every described corner of the first frame matched
/// against all of the second's, right when the match lies within 2 px of where Lucas–Kanade
/// follows the corner. `describe` gives each backend's descriptors. (accepted, right).
fn ratio_test_matches(
    images: &[(GrayImage, GrayImage)],
    mut describe: impl FnMut(&GrayImage, &[Vec2]) -> Vec<Option<vision::Descriptor>>,
) -> (usize, usize) {
    let (mut accepted, mut right) = (0, 0);
    for (a, b) in images {
        let corners = vision::detect_corners(a, 500, 10.0, &[]);
        let moved = lk::track_points(
            &lk::Pyramid::build(a),
            &lk::Pyramid::build(b),
            &corners,
            None,
            lk::LkOptions {
                levels: 3,
                max_fb_error_px: Some(1.0),
            },
        );
        let second = vision::detect_corners(b, 500, 10.0, &[]);
        let (first_d, second_d) = (describe(a, &corners), describe(b, &second));
        for (d, m) in first_d.iter().zip(&moved) {
            let (Some(d), Some(m)) = (d, m) else { continue };
            let mut nearest = vision::NearestTwo::default();
            for (j, e) in second_d.iter().enumerate() {
                if let Some(e) = e {
                    nearest.offer(vision::hamming(d, e), j);
                }
            }
            if let Some((j, _)) = nearest.accepted(40, 0.8) {
                accepted += 1;
                right += usize::from(second[j].distance(*m) <= 2.0);
            }
        }
    }
    (accepted, right)
}

#[test]
fn portable_orb_matches_are_as_often_right_as_opencvs() {
    let (_, images) = frames((0..700).step_by(25).map(|i| (i, i + 5)));
    let orb = vision::Orb::new();
    let ours = ratio_test_matches(&images, |i, p| orb.describe(i, p));
    let mut cv_orb = cv::OrbFeatures::new(1000).expect("OpenCV ORB");
    let theirs = ratio_test_matches(&images, |i, p| cv_orb.describe(i, p).expect("OpenCV"));
    let share = |(a, r): (usize, usize)| r as f64 / a.max(1) as f64;
    let summary = format!(
        "ratio-test matches right: ours {} of {} ({:.3}), OpenCV {} of {} ({:.3})",
        ours.1,
        ours.0,
        share(ours),
        theirs.1,
        theirs.0,
        share(theirs)
    );
    println!("{summary}");
    assert!(share(ours) >= share(theirs) - 0.01, "{summary}");
    // As many right matches, within a tenth: a pattern that matched little would be useless.
    assert!(ours.1 * 10 >= theirs.1 * 9, "{summary}");
}
