//! # sylva-app
//!
//! The Sylva app library shared by the desktop binary and the Android and iOS shells: renderer,
//! UI, sessions and the command line.

pub mod cli;
pub mod cmd_grow;
pub mod render;
pub mod tree_model;
pub mod footage;
pub mod state;
pub mod session;
pub mod ui;
pub mod desktop;
pub mod player;
pub mod cmd_app;
pub mod demo_script;
