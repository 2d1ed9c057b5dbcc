//! A slice of a sweep, to run on one node of a cluster.

use std::fmt;

use errp_sim::{Result, SimError};
use serde::{Deserialize, Serialize};

/// A slice of a sweep: episode `g` of the sweep (counted over all levels)
/// belongs to shard `g % count + 1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based index of this shard.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Parses `K/N` with 1 <= K <= N.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            SimError::Sweep(format!(
                "--shard {text:?} is invalid: expected K/N with 1 <= K <= N, e.g. 3/8"
            ))
        };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index == 0 || index > count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }

    /// True if episode `g` of the sweep is this shard's.
    pub fn owns(&self, g: usize) -> bool {
        g % self.count == self.index - 1
    }

    /// True for the whole sweep.
    pub fn is_all(&self) -> bool {
        self.count == 1
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
