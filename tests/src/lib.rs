//! Helpers shared by Sylva's workspace-level tests (`tests/tests/*.rs`).

use std::path::PathBuf;

pub mod corners;
pub mod synthetic;

/// The shared test data folder: `$SYLVA_DATA`, else `../shared/test-data` beside the checkout.
///
/// Panics with a clear message when it is absent: data-driven tests fail loudly, never skip.
pub fn shared_data_dir() -> PathBuf {
    let dir = std::env::var_os("SYLVA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/test-data")
        });
    assert!(
        dir.is_dir(),
        "test data not found at {} (set SYLVA_DATA; the README says how to download the TUM sequences)",
        dir.display()
    );
    dir
}

/// The project's own data folder (`test-data/` at the workspace root).
pub fn project_data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data")
}
