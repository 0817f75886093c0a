//! The seeds the preset tools grow: `SYLVA_SEEDS` (comma-separated), else their defaults.

/// The seeds in `SYLVA_SEEDS`, or `default` when it is unset; a seed that is not a number stops
/// the tool with its text.
pub fn seeds_from_env(default: &[u64]) -> Vec<u64> {
    std::env::var("SYLVA_SEEDS").map_or(default.to_vec(), |list| {
        list.split(',')
            .map(|s| {
                s.trim()
                    .parse()
                    .unwrap_or_else(|e| panic!("SYLVA_SEEDS {s}: {e}"))
            })
            .collect()
    })
}
