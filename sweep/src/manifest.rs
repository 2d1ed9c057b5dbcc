//! `sweep.json`: what a sweep was asked, the decoders it prepared and whether it finished.

use std::path::Path;

use serde::{Deserialize, Serialize};

use errp_sim::task::DecoderInfo;
use errp_sim::{Result, SimError, truncate, write_atomic};

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

/// Version of the sweep directory layout (2: rows end in a checksum).
pub const FORMAT: u32 = 2;

/// The largest `sweep.json` read (it holds the scenario's text, at most
/// 1 MiB, and a line per decoder).
pub const MAX_MANIFEST_BYTES: u64 = 16 << 20;

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

    /// Reads `dir/sweep.json` (at most [`MAX_MANIFEST_BYTES`]), which must
    /// be of this version's [`FORMAT`].
    pub fn read(dir: &Path) -> Result<Self> {
        use std::io::Read;
        let path = dir.join(MANIFEST);
        let input = |source| SimError::Input {
            path: path.clone(),
            source,
        };
        let mut text = String::new();
        errp_sim::open_regular(&path)
            .map_err(input)?
            .take(MAX_MANIFEST_BYTES + 1)
            .read_to_string(&mut text)
            .map_err(input)?;
        let not_ours = |why: String| {
            SimError::Sweep(format!(
                "{}: not a sweep manifest ({why}); was it written by `errp sweep`?",
                path.display()
            ))
        };
        if text.len() as u64 > MAX_MANIFEST_BYTES {
            return Err(not_ours(format!(
                "it is over {} MiB",
                MAX_MANIFEST_BYTES >> 20
            )));
        }
        #[derive(Deserialize)]
        struct Format {
            format: u32,
        }
        let format = serde_json::from_str::<Format>(&text)
            .map_err(|e| not_ours(e.to_string()))?
            .format;
        if format != FORMAT {
            return Err(SimError::Sweep(format!(
                "{}: a sweep directory of format {format}, written by another version of errp \
                 (this one reads format {FORMAT}); rerun the sweep into a new --out",
                path.display()
            )));
        }
        let manifest: Self = serde_json::from_str(&text).map_err(|e| not_ours(e.to_string()))?;
        let this = env!("CARGO_PKG_VERSION");
        if manifest.errp_version != this {
            return Err(SimError::Sweep(format!(
                "{}: a sweep written by errp {:?}, and this is errp {this}: a sweep is resumed \
                 and merged by the version that started it (its decoders and rows may differ \
                 in another); rerun it into a new --out, or use errp {:?}",
                path.display(),
                truncate(&manifest.errp_version, 40),
                truncate(&manifest.errp_version, 40),
            )));
        }
        Ok(manifest)
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
