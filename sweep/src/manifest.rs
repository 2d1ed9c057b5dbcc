//! `sweep.json`: what a sweep was asked, the decoders it prepared and whether it finished.

use std::path::Path;

use serde::{Deserialize, Serialize};

use errp_sim::task::DecoderInfo;
use errp_sim::{Result, SimError, write_atomic};

use crate::spec::{Shard, SweepSpec};

/// The contents of `sweep.json`: enough to rerun the sweep exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Format of the sweep directory.
    pub format: u32,
    /// Version of errp that wrote it.
    pub errp_version: String,
    /// What was swept.
    pub spec: SweepSpec,
    /// The slice this directory holds (none: the whole sweep).
    pub shard: Option<Shard>,
    /// Every calibrated decoder, in level order (empty until calibrated).
    pub decoders: Vec<DecoderInfo>,
}

/// Version of the sweep directory layout.
pub const FORMAT: u32 = 1;

impl Manifest {
    /// A manifest with no decoders yet.
    pub fn new(spec: &SweepSpec, shard: Shard) -> Self {
        Self {
            format: FORMAT,
            errp_version: env!("CARGO_PKG_VERSION").to_string(),
            spec: spec.clone(),
            shard: (!shard.is_all()).then_some(shard),
            decoders: Vec::new(),
        }
    }

    /// Reads `dir/sweep.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|source| SimError::Input {
            path: path.clone(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| {
            SimError::Sweep(format!(
                "{}: not a sweep manifest ({e}); was it written by `errp sweep`?",
                path.display()
            ))
        })
    }

    /// Writes `dir/sweep.json` atomically.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("a manifest serialises") + "\n";
        write_atomic(&dir.join(MANIFEST), text.as_bytes())
    }
}

/// The manifest's file name.
pub const MANIFEST: &str = "sweep.json";
/// The episodes' file name.
pub const EPISODES: &str = "episodes.csv";
