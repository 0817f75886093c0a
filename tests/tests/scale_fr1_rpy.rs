//! Metric scale on real footage (issue 20): on TUM fr1_rpy the camera-height guess is far off
//! (the plane the tracker finds is the desk, not a floor 1.5 m below), and a known length marked
//! in one frame brings the world to metres. The length's truth comes from the sensor: the
//! registered Kinect depth map of the frame back-projects the two marked pixels, as a tape
//! measure would; the tracker never sees the depth maps.

use glam::DVec2;
use sylva_tests::shared_data_dir;
use sylva_tracking::TrackerConfig;
use sylva_tracking::measure::{KnownLength, PixelPair};
use sylva_tracking::report::run_sequence_scaled;
use sylva_tracking::run_scale::ScaleOptions;
use sylva_tracking::sequence::decode_depth_m;
use sylva_tracking::{TumSequence, scale::DEFAULT_HOLDING_HEIGHT_M};

/// Frame 60 sees the desk (papers, a book, a mouse) from above; these pixels lie on it (an
/// envelope near the desk's front edge, papers at the right), 0.90 m and 0.80 m from the sensor.
const FRAME: usize = 60;
const MARKS: [DVec2; 2] = [DVec2::new(320.0, 440.0), DVec2::new(580.0, 330.0)];

#[test]
fn a_known_length_from_one_frame_makes_fr1_rpy_metric_where_the_camera_height_cannot() {
    let root = shared_data_dir().join("tum_fr1_rpy");
    let sequence = TumSequence::open(&root).expect("fr1_rpy");
    let timestamp_s = sequence.frames[FRAME].timestamp_s;
    let depth = sequence
        .depth
        .iter()
        .find(|d| (d.timestamp_s - timestamp_s).abs() < 0.02)
        .expect("a depth map at the marked frame");
    let scale = sequence.camera.depth_scale.expect("depth scale");
    let (width, _, depth_m) = decode_depth_m(&depth.path, scale).expect("depth map");
    let camera = &sequence.camera;
    let [a, b] = MARKS.map(|pixel| {
        let d = depth_m[pixel.y as usize * width as usize + pixel.x as usize] as f64;
        assert!(d > 0.0, "no sensor depth at {pixel}");
        camera.normalized_from_pixel(pixel).extend(1.0) * d
    });
    let length_m = a.distance(b);
    let options = ScaleOptions {
        holding_height_m: DEFAULT_HOLDING_HEIGHT_M,
        known_length: Some(KnownLength {
            pixels: PixelPair {
                frame: FRAME,
                a: MARKS[0],
                b: MARKS[1],
            },
            length_m,
        }),
        measures: Vec::new(),
    };
    let run = |options: &ScaleOptions| {
        run_sequence_scaled(
            &root,
            TrackerConfig::default(),
            options,
            |_, _| {},
            |s| panic!("frame {} unreadable", s.path.display()),
        )
        .expect("fr1_rpy tracks")
    };
    let known = run(&options);
    let guessed = run(&ScaleOptions {
        known_length: None,
        ..options
    });
    let (known_line, guessed_line) = (known.summary_line(), guessed.summary_line());
    println!("known length {length_m:.3} m: {known_line}\ncamera height: {guessed_line}");
    let error = |r: &sylva_tracking::report::TrackReport| {
        r.errors.expect("fr1_rpy has ground truth").scale_error
    };
    assert!(
        error(&guessed).abs() > 0.2,
        "the camera height happened to be right: {guessed_line}"
    );
    // Measured: +0.095 (the camera height: -0.47). The map's scale drifts along this sequence
    // (its depths over the sensor's run 1.9 to 2.3 units per metre in 80% of frames), so one
    // frame's mark can be 10% off the whole trajectory's scale; the bound guards against worse.
    assert!(
        error(&known).abs() <= 0.15,
        "known length {length_m:.3} m: {known_line}"
    );
}
