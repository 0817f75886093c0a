//! Diagnostic: how the map's scale evolves while tracking a TUM sequence that has depth maps.
//! For every frame with a depth map, prints the median ratio of the tracked points' depths (in
//! the tracker's world units) to the depths the sensor measured at their pixels. A constant
//! ratio means no scale drift. `cargo run --release -p sylva-tracking --example scale_probe --
//! SEQUENCE`.
use sylva_tracking::sequence::{FrameSource, SourceEvent, decode_depth_m};
use sylva_tracking::{Tracker, TumSequence};

#[path = "common/cfg.rs"]
mod cfg;

fn main() {
    let Some(root) = std::env::args().nth(1) else {
        eprintln!("usage: scale_probe SEQUENCE");
        std::process::exit(2);
    };
    let sequence = TumSequence::open(std::path::Path::new(&root)).expect("sequence opens");
    let Some(depth_scale) = sequence.camera.depth_scale else {
        eprintln!("{root}: camera.txt gives no depth scale");
        std::process::exit(2);
    };
    let mut tracker = Tracker::new(sequence.camera, cfg::config_from_env()).expect("tracker");
    let mut source = sequence.source();
    let mut line = String::new();
    while let Some(event) = source.next_event() {
        let SourceEvent::Frame(frame) = event else {
            continue;
        };
        let up = sequence.up_in_camera_at(frame.timestamp_s);
        let output = tracker
            .track(&frame, up.map(|u| u * 9.81))
            .expect("tracking runs");
        let Some(depth) = sequence
            .depth
            .iter()
            .find(|d| (d.timestamp_s - frame.timestamp_s).abs() < 0.02)
        else {
            continue;
        };
        let Some(world_from_camera) = output.world_from_camera else {
            continue;
        };
        let Ok((width, height, metres)) = decode_depth_m(&depth.path, depth_scale) else {
            continue;
        };
        let camera_from_world = world_from_camera.inverse();
        let mut ratios: Vec<f64> = output
            .tracked_points
            .iter()
            .filter_map(|p| {
                let (x, y) = (p.pixel.x.round() as i64, p.pixel.y.round() as i64);
                if x < 0 || y < 0 || x >= width as i64 || y >= height as i64 {
                    return None;
                }
                let measured = metres[(y as usize) * width as usize + x as usize] as f64;
                let z = camera_from_world.transform_point3(p.world.as_dvec3()).z;
                (measured > 0.1).then_some(z / measured)
            })
            .collect();
        if ratios.len() < 10 {
            continue;
        }
        ratios.sort_by(f64::total_cmp);
        let q = |f: f64| ratios[((ratios.len() - 1) as f64 * f) as usize];
        line += &format!(
            "{}:{:.3}[{:.2}-{:.2}] ",
            frame.index,
            q(0.5),
            q(0.25) / q(0.5),
            q(0.75) / q(0.5)
        );
    }
    println!("{line}");
}
