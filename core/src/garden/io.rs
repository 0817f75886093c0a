//! Saving and loading gardens: versioned JSON (`"format": "sylva-garden"`). Each tree is saved
//! as a tree file saves it (species, skeleton, generator, persistent points) with its place,
//! planting age, seed and links; a loaded garden is checked as plantings and tree files are
//! (positions, spacing, species, tree invariants, links), so a damaged file is an error naming
//! the file and the tree, never a panic.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::planting::{PlantedTree, check_trees};
use super::{Garden, MAX_GARDEN_YEARS};

/// Version written by this build; files with a larger version are refused.
pub const GARDEN_FORMAT_VERSION: u32 = 1;
const FORMAT_NAME: &str = "sylva-garden";

/// Why a garden file could not be saved or loaded.
#[derive(Debug, thiserror::Error)]
pub enum GardenFileError {
    #[error("cannot read garden file {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("cannot write garden file {path}: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
    #[error("{path} is not a Sylva garden file: {reason}")]
    NotAGarden { path: String, reason: String },
    #[error(
        "{path} was written by a newer Sylva (format version {found}; this build reads up to {supported})"
    )]
    NewerVersion {
        path: String,
        found: u32,
        supported: u32,
    },
    #[error("garden file {path} is malformed: {reason}")]
    Malformed { path: String, reason: String },
}

#[derive(Serialize)]
struct FileOut<'a> {
    format: &'static str,
    version: u32,
    garden: &'a Garden,
}

#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u32>,
}

#[derive(Deserialize)]
struct FileIn {
    garden: Garden,
}

impl Garden {
    /// The garden as versioned JSON bytes (deterministic).
    pub fn to_json_bytes(&self) -> Vec<u8> {
        let file = FileOut {
            format: FORMAT_NAME,
            version: GARDEN_FORMAT_VERSION,
            garden: self,
        };
        // Plain data with finite floats: serialization cannot fail.
        serde_json::to_vec(&file).unwrap_or_default()
    }

    /// Parses and checks versioned JSON bytes; `origin` names the source in errors.
    pub fn from_json_bytes_named(bytes: &[u8], origin: &str) -> Result<Garden, GardenFileError> {
        let path = origin.to_string();
        let not = |reason: String| GardenFileError::NotAGarden {
            path: path.clone(),
            reason,
        };
        let header: Header = serde_json::from_slice(bytes).map_err(|e| not(e.to_string()))?;
        match header.format.as_deref() {
            Some(FORMAT_NAME) => {}
            Some(other) => {
                return Err(not(format!(
                    "format is {other:?}, expected {FORMAT_NAME:?}"
                )));
            }
            None => return Err(not("no \"format\" field".into())),
        }
        let found = header
            .version
            .ok_or_else(|| not("no \"version\" field".into()))?;
        if found > GARDEN_FORMAT_VERSION {
            return Err(GardenFileError::NewerVersion {
                path,
                found,
                supported: GARDEN_FORMAT_VERSION,
            });
        }
        let malformed = |reason: String| GardenFileError::Malformed {
            path: path.clone(),
            reason,
        };
        let file: FileIn = serde_json::from_slice(bytes).map_err(|e| malformed(e.to_string()))?;
        let mut garden = file.garden;
        garden.check().map_err(malformed)?;
        for t in &mut garden.trees {
            t.tree.update_widths();
        }
        garden.rebuild_environment();
        Ok(garden)
    }

    /// Everything a loaded garden must hold: valid trees in valid places, links in range.
    fn check(&self) -> Result<(), String> {
        if !(self.years.is_finite() && (0.0..=MAX_GARDEN_YEARS).contains(&self.years)) {
            return Err(format!(
                "years is {}, expected 0 to {MAX_GARDEN_YEARS}",
                self.years
            ));
        }
        let planted: Vec<PlantedTree> = self
            .trees
            .iter()
            .map(|t| {
                PlantedTree::new(
                    t.tree.species.clone(),
                    t.x_m,
                    t.z_m,
                    t.planting_age_years,
                    t.seed,
                )
            })
            .collect();
        check_trees(&planted).map_err(|e| e.to_string())?;
        for (i, t) in self.trees.iter().enumerate() {
            t.tree
                .sanity_check()
                .map_err(|e| format!("tree {i}: {e}"))?;
            if let Some(&j) = t
                .neighbours
                .iter()
                .find(|&&j| j as usize >= self.trees.len() || j as usize == i)
            {
                return Err(format!(
                    "tree {i}: neighbour {j} is not another tree of the garden"
                ));
            }
        }
        Ok(())
    }

    /// Parses versioned JSON bytes.
    pub fn from_json_bytes(bytes: &[u8]) -> Result<Garden, GardenFileError> {
        Self::from_json_bytes_named(bytes, "<bytes>")
    }

    /// Saves atomically: a temporary file next to `path`, renamed over it.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), GardenFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        crate::safe_write::write_file(path, &self.to_json_bytes()).map_err(|source| {
            GardenFileError::Write {
                path: shown,
                source,
            }
        })
    }

    /// Loads a garden saved by [`Garden::save`].
    pub fn load(path: impl AsRef<Path>) -> Result<Garden, GardenFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| GardenFileError::Read {
            path: shown.clone(),
            source,
        })?;
        Self::from_json_bytes_named(&bytes, &shown)
    }
}
