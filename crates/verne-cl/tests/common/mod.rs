//! What the integration tests of the CL reader share.

use std::path::{Path, PathBuf};

/// The CL corpus: `$CL_CORPUS`, else `tests/data/cl-corpus` at the workspace root.
pub fn corpus_dir() -> PathBuf {
    match std::env::var_os("CL_CORPUS") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cl-corpus"),
    }
}
