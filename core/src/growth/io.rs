//! Saving and loading trees: versioned JSON (serde), or the same content compact
//! ([`TreeFileFormat::Compact`]). Saving the same tree twice gives the same bytes; loading a
//! newer, foreign, truncated or malformed file is an error naming the file and the problem.
//!
//! The compact file is a frame around the JSON file's content encoded as CBOR (RFC 8949, by
//! ciborium): the magic bytes `SYLVATRC`, the format version (u32, little-endian), the length of
//! the payload (u64), the payload, and its FNV-1a 64 checksum (u64), so a file cut short or
//! damaged is refused before it is parsed. [`Tree::load`] reads either kind.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::Tree;

/// Version written by this build; files with a larger version are refused.
pub const TREE_FORMAT_VERSION: u32 = 1;
const FORMAT_NAME: &str = "sylva-tree";
/// Largest tree file [`Tree::load`] reads, bytes (a 300 000-internode tree saves to about
/// 200 MB).
const MAX_TREE_FILE_BYTES: u64 = 1 << 30;

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

/// How a tree file is written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TreeFileFormat {
    /// Versioned JSON: readable, the default.
    #[default]
    Json,
    /// The same content as CBOR in a checked frame (see the module doc): about 60% of the
    /// JSON's size (numbers in binary; field names stay), faster to write and read.
    Compact,
}

/// First bytes of a compact tree file.
const COMPACT_MAGIC: &[u8; 8] = b"SYLVATRC";
/// Magic, version and payload length.
const COMPACT_HEADER_LEN: usize = 8 + 4 + 8;
const CHECKSUM_LEN: usize = 8;

/// FNV-1a, 64 bit.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
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

#[derive(Deserialize)]
struct FileInChecked {
    format: String,
    version: u32,
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

    /// The tree as a compact file's bytes (deterministic; see the module doc).
    pub fn to_compact_bytes(&self) -> Result<Vec<u8>, TreeFileError> {
        let file = FileOut {
            format: FORMAT_NAME,
            version: TREE_FORMAT_VERSION,
            tree: self,
        };
        let mut bytes = Vec::with_capacity(COMPACT_HEADER_LEN + 64 * self.skeleton.len());
        bytes.extend_from_slice(COMPACT_MAGIC);
        bytes.extend_from_slice(&TREE_FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&0u64.to_le_bytes());
        ciborium::into_writer(&file, &mut bytes).map_err(|e| TreeFileError::Encode {
            path: "<memory>".into(),
            reason: e.to_string(),
        })?;
        let payload_len = (bytes.len() - COMPACT_HEADER_LEN) as u64;
        bytes[12..COMPACT_HEADER_LEN].copy_from_slice(&payload_len.to_le_bytes());
        let checksum = fnv1a(&bytes[COMPACT_HEADER_LEN..]);
        bytes.extend_from_slice(&checksum.to_le_bytes());
        Ok(bytes)
    }

    /// The tree as `format`'s bytes.
    pub fn to_bytes(&self, format: TreeFileFormat) -> Result<Vec<u8>, TreeFileError> {
        match format {
            TreeFileFormat::Json => self.to_json_bytes(),
            TreeFileFormat::Compact => self.to_compact_bytes(),
        }
    }

    /// Whether `bytes` start like a compact tree file.
    pub fn is_compact_file(bytes: &[u8]) -> bool {
        bytes.starts_with(COMPACT_MAGIC)
    }

    /// Parses a compact file's bytes; `origin` (a path or a label) names the source in errors.
    pub fn from_compact_bytes_named(bytes: &[u8], origin: &str) -> Result<Tree, TreeFileError> {
        let path = origin.to_string();
        if !Self::is_compact_file(bytes) {
            return Err(TreeFileError::NotATree {
                path,
                reason: "it does not start with the compact tree file's magic bytes".into(),
            });
        }
        if bytes.len() < COMPACT_HEADER_LEN + CHECKSUM_LEN {
            return Err(TreeFileError::Malformed {
                path,
                reason: format!(
                    "truncated: {} bytes, shorter than a compact file's frame",
                    bytes.len()
                ),
            });
        }
        let found = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if found > TREE_FORMAT_VERSION {
            return Err(TreeFileError::NewerVersion {
                path,
                found,
                supported: TREE_FORMAT_VERSION,
            });
        }
        let payload_len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
        let expected = (COMPACT_HEADER_LEN + CHECKSUM_LEN) as u64 + payload_len;
        if bytes.len() as u64 != expected {
            return Err(TreeFileError::Malformed {
                path,
                reason: format!(
                    "{} bytes where its header announces {expected}: {}",
                    bytes.len(),
                    if (bytes.len() as u64) < expected {
                        "truncated"
                    } else {
                        "bytes after its end"
                    }
                ),
            });
        }
        let (payload, checksum) = bytes[COMPACT_HEADER_LEN..].split_at(payload_len as usize);
        let checksum = u64::from_le_bytes(checksum.try_into().expect("8 bytes"));
        if fnv1a(payload) != checksum {
            return Err(TreeFileError::Malformed {
                path,
                reason: "damaged: its checksum does not match its content".into(),
            });
        }
        let file: FileInChecked =
            ciborium::from_reader(payload).map_err(|e| TreeFileError::Malformed {
                path: path.clone(),
                reason: e.to_string(),
            })?;
        if file.format != FORMAT_NAME || file.version != found {
            return Err(TreeFileError::Malformed {
                path,
                reason: format!(
                    "its content says format {:?} version {}, its frame {FORMAT_NAME:?} version {found}",
                    file.format, file.version
                ),
            });
        }
        Self::checked(file.tree, path)
    }

    /// A parsed tree made ready for use: species and arena checked, shadow and widths derived.
    fn checked(mut tree: Tree, path: String) -> Result<Tree, TreeFileError> {
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
        Self::checked(file.tree, path)
    }

    /// Parses versioned JSON bytes.
    pub fn from_json_bytes(bytes: &[u8]) -> Result<Tree, TreeFileError> {
        Self::from_json_bytes_named(bytes, "<bytes>")
    }

    /// Saves as JSON atomically and durably ([`crate::safe_write`]): a reader sees the old file
    /// or the new one.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), TreeFileError> {
        self.save_as(path, TreeFileFormat::Json)
    }

    /// [`Tree::save`] in `format`.
    pub fn save_as(
        &self,
        path: impl AsRef<Path>,
        format: TreeFileFormat,
    ) -> Result<(), TreeFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = self.to_bytes(format).map_err(|e| match e {
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

    /// Loads a tree saved by [`Tree::save`] or [`Tree::save_as`] (either format). Only a regular
    /// file of at most 1 GiB is read (a FIFO would block, `/dev/zero` would fill memory).
    pub fn load(path: impl AsRef<Path>) -> Result<Tree, TreeFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes =
            read_bounded(path, MAX_TREE_FILE_BYTES).map_err(|source| TreeFileError::Read {
                path: shown.clone(),
                source,
            })?;
        if Self::is_compact_file(&bytes) {
            Self::from_compact_bytes_named(&bytes, &shown)
        } else {
            Self::from_json_bytes_named(&bytes, &shown)
        }
    }
}

/// The bytes of the regular file at `path`, at most `max_bytes` of them (checked before it is
/// opened and on the opened handle; a file growing while read stops one byte past the limit).
fn read_bounded(path: &Path, max_bytes: u64) -> std::io::Result<Vec<u8>> {
    use std::io::{Error, ErrorKind, Read};
    let regular = |metadata: &std::fs::Metadata| {
        if metadata.is_file() {
            Ok(())
        } else {
            Err(Error::new(ErrorKind::InvalidInput, "not a regular file"))
        }
    };
    let too_large = |size: u64| {
        Error::new(
            ErrorKind::InvalidData,
            format!("file is larger than the {max_bytes} bytes allowed (at least {size} bytes)"),
        )
    };
    regular(&std::fs::metadata(path)?)?;
    let file = std::fs::File::open(path)?;
    let opened = file.metadata()?;
    regular(&opened)?;
    if opened.len() > max_bytes {
        return Err(too_large(opened.len()));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(opened.len()).unwrap_or(0));
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loading_a_device_or_an_oversized_file_as_a_tree_is_a_clear_error_not_a_hang() {
        #[cfg(unix)]
        {
            let e = Tree::load("/dev/zero").expect_err("a device is no tree file");
            let text = e.to_string();
            assert!(
                text.contains("/dev/zero") && text.contains("not a regular file"),
                "{text}"
            );
        }
        let dir = tempfile::tempdir().expect("tempdir");
        let huge = dir.path().join("huge.tree.json");
        // Sparse: no disk is used.
        std::fs::File::create(&huge)
            .and_then(|f| f.set_len(MAX_TREE_FILE_BYTES + 1))
            .expect("sparse file");
        let text = Tree::load(&huge).expect_err("too large").to_string();
        assert!(
            text.contains("huge.tree.json") && text.contains("larger than"),
            "{text}"
        );
    }
}
