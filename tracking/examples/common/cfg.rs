//! Tuning aid shared by the tracking examples: `SYLVA_CFG="min_parallax_deg=0.5,outlier_px=4"`
//! overrides [`sylva_tracking::TrackerConfig`] fields; `SYLVA_BACKEND=portable` (or `opencv`)
//! picks the vision backend.

pub fn config_from_env() -> sylva_tracking::TrackerConfig {
    let mut config = sylva_tracking::TrackerConfig::default();
    if let Ok(name) = std::env::var("SYLVA_BACKEND") {
        config.backend = sylva_tracking::VisionBackend::from_name(&name)
            .unwrap_or_else(|| panic!("SYLVA_BACKEND: opencv or portable, not {name}"));
    }
    for pair in std::env::var("SYLVA_CFG")
        .unwrap_or_default()
        .split(',')
        .filter(|p| !p.is_empty())
    {
        let (key, value) = pair.split_once('=').expect("key=value");
        let v: f64 = value.parse().expect("number");
        match key {
            "max_tracks" => config.max_tracks = v as usize,
            "min_corner_distance_px" => config.min_corner_distance_px = v as f32,
            "max_fb_error_px" => config.max_fb_error_px = v as f32,
            "outlier_px" => config.outlier_px = v,
            "huber_px" => config.huber_px = v,
            "min_parallax_deg" => config.min_parallax_deg = v,
            "init_min_parallax_deg" => config.init_min_parallax_deg = v,
            "local_window" => config.local_window = v as usize,
            "max_local_search" => config.max_local_search = v as usize,
            "max_keyframe_gap" => config.max_keyframe_gap = v as usize,
            "rolling_shutter_readout_s" => config.rolling_shutter_readout_s = Some(v),
            "lk_levels" => config.lk_levels = v as usize,
            "search_lk_levels" => config.search_lk_levels = v as usize,
            "search_fb_check" => config.search_fb_check = v != 0.0,
            "min_baseline_ratio" => config.min_baseline_ratio = v,
            "adopt_map_points" => config.adopt_map_points = v != 0.0,
            "adopt_radius_px" => config.adopt_radius_px = v as f32,
            "min_pose_inliers" => config.min_pose_inliers = v as usize,
            "init_min_points" => config.init_min_points = v as usize,
            other => panic!("unknown key {other}"),
        }
    }
    config
}
