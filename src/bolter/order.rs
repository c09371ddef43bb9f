//! What is asked of the bolters: by a command, which fasteners ([`Fasteners`]); by board A of
//! side B, one step of one pair ([`BolterOrder`], carried in the A→B command's bolter bytes).
// req: D:b-command

use super::{BolterDirection, BolterPair, BolterStep};

/// Which fasteners a bolt or unbolt command works on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Fasteners {
    /// One pair.
    Pair(BolterPair),
    /// Pairs 1–4 in order, stopping at the first that fails.
    All,
}

/// A bolter step ordered on side B: which pair, which way, which step of Figure 8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct BolterOrder {
    /// Pair selected through the multiplexer.
    pub pair: BolterPair,
    /// Bolt or unbolt.
    pub direction: BolterDirection,
    /// Step to execute.
    pub step: BolterStep,
}
