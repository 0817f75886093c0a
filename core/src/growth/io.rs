//! Saving and loading trees: versioned JSON (serde). Saving the same tree twice gives the same
//! bytes; loading a newer, foreign or malformed file is an error naming the file and the problem.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::Tree;

/// Version written by this build; files with a larger version are refused.
pub const TREE_FORMAT_VERSION: u32 = 1;
const FORMAT_NAME: &str = "sylva-tree";

/// Why a tree file could not be saved or loaded.
#[derive(Debug, thiserror::Error)]
pub enum TreeFileError {
    #[error("cannot read tree file {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("cannot write tree file {path}: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
    #[error("{path} is not a Sylva tree file: {reason}")]
    NotATree { path: String, reason: String },
    #[error(
        "{path} was written by a newer Sylva (format version {found}; this build reads up to {supported})"
    )]
    NewerVersion {
        path: String,
        found: u32,
        supported: u32,
    },
    #[error("tree file {path} is malformed: {reason}")]
    Malformed { path: String, reason: String },
    #[error("cannot encode tree for {path}: {reason}")]
    Encode { path: String, reason: String },
}

#[derive(Serialize)]
struct FileOut<'a> {
    format: &'static str,
    version: u32,
    tree: &'a Tree,
}

#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u32>,
}

#[derive(Deserialize)]
struct FileIn {
    tree: Tree,
}

impl Tree {
    /// The tree as versioned JSON bytes (deterministic).
    pub fn to_json_bytes(&self) -> Result<Vec<u8>, TreeFileError> {
        let file = FileOut {
            format: FORMAT_NAME,
            version: TREE_FORMAT_VERSION,
            tree: self,
        };
        serde_json::to_vec(&file).map_err(|e| TreeFileError::Encode {
            path: "<memory>".into(),
            reason: e.to_string(),
        })
    }

    /// Parses versioned JSON bytes; `origin` (a path or a label) names the source in errors.
    pub fn from_json_bytes_named(bytes: &[u8], origin: &str) -> Result<Tree, TreeFileError> {
        let path = origin.to_string();
        let header: Header =
            serde_json::from_slice(bytes).map_err(|e| TreeFileError::NotATree {
                path: path.clone(),
                reason: e.to_string(),
            })?;
        match header.format.as_deref() {
            Some(FORMAT_NAME) => {}
            Some(other) => {
                return Err(TreeFileError::NotATree {
                    path,
                    reason: format!("format is {other:?}, expected {FORMAT_NAME:?}"),
                });
            }
            None => {
                return Err(TreeFileError::NotATree {
                    path,
                    reason: "no \"format\" field".into(),
                });
            }
        }
        let Some(found) = header.version else {
            return Err(TreeFileError::NotATree {
                path,
                reason: "no \"version\" field".into(),
            });
        };
        if found > TREE_FORMAT_VERSION {
            return Err(TreeFileError::NewerVersion {
                path,
                found,
                supported: TREE_FORMAT_VERSION,
            });
        }
        let file: FileIn = serde_json::from_slice(bytes).map_err(|e| TreeFileError::Malformed {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        let mut tree = file.tree;
        tree.species
            .validate()
            .map_err(|reason| TreeFileError::Malformed {
                path: path.clone(),
                reason,
            })?;
        tree.sanity_check().map_err(|e| TreeFileError::Malformed {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        tree.rebuild_shadow();
        tree.update_widths();
        Ok(tree)
    }

    /// Parses versioned JSON bytes.
    pub fn from_json_bytes(bytes: &[u8]) -> Result<Tree, TreeFileError> {
        Self::from_json_bytes_named(bytes, "<bytes>")
    }

    /// Saves atomically and durably ([`crate::safe_write`]): a reader sees the old file or the new one.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), TreeFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = self.to_json_bytes().map_err(|e| match e {
            TreeFileError::Encode { reason, .. } => TreeFileError::Encode {
                path: shown.clone(),
                reason,
            },
            other => other,
        })?;
        crate::safe_write::write_file(path, &bytes).map_err(|source| TreeFileError::Write {
            path: shown,
            source,
        })
    }

    /// Loads a tree saved by [`Tree::save`].
    pub fn load(path: impl AsRef<Path>) -> Result<Tree, TreeFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| TreeFileError::Read {
            path: shown.clone(),
            source,
        })?;
        Self::from_json_bytes_named(&bytes, &shown)
    }
}
