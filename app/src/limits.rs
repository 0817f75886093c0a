//! Limits on what one request may ask of the growth model, shared by the app and the lean
//! `sylva` front binary.

/// The oldest a tree may be grown, in the app or by `sylva grow` (the years slider offers far
/// less).
pub const MAX_DESIGN_YEARS: f32 = 1000.0;
/// Most growth iterations one request (a command, a session's grow event) runs: a thousand
/// years of a species growing one iteration a year. More would run for hours.
pub const MAX_ITERATIONS_PER_REQUEST: u32 = 1000;
