//! # sylva-app
//!
//! The Sylva app library shared by the desktop binary and the Android and iOS shells: renderer,
//! UI, sessions and the command line.

pub mod cli;
pub mod cmd_grow;
