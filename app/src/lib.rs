//! # sylva-app
//!
//! The Sylva app library shared by the desktop binary and the Android and iOS shells: renderer,
//! UI, sessions and the command line.

pub mod autosave;
pub mod cli;
pub mod cli_growth;
pub mod cmd_app;
pub mod cmd_garden;
pub mod cmd_grow;
pub mod cmd_recreate;
pub mod cmd_track;
pub mod demo_script;
pub mod desktop;
pub mod footage;
pub mod frame_report;
pub mod garden_view;
pub mod limits;
pub mod live;
#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub mod live_capture;
pub mod memory;
pub mod outputs;
pub mod planting;
pub mod platform;
pub mod player;
pub mod recreate;
pub mod render;
pub mod scale;
pub mod scene_tracking;
pub mod session;
pub mod state;
#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub mod track_plot;
pub mod tracking_worker;
pub mod tree_model;
pub mod ui;
