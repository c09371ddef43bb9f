//! What side B reports of its bolter to board A (the internal heartbeat's auxiliary bytes): the
//! progress board A's coordinator waits on before it orders the next step.
// req: P5.9, T3/active_bolter, T3/bolter_attempt

use super::{BolterDirection, BolterPair, BolterStep, MuxLines};

/// Bolter B's progress, the nine "auxiliary variables" A needs to keep both bolters in step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct BolterAux {
    /// Step B is executing; none when idle (wire 0).
    pub step: Option<BolterStep>,
    #[cfg_attr(feature = "serde", serde(deserialize_with = "crate::units::de::seq8"))]
    /// Sequence number of the A→B command that ordered that step.
    pub seq: u8,
    /// Pair B has selected; none when idle.
    pub pair: Option<BolterPair>,
    /// Bolting or unbolting; none when idle.
    pub direction: Option<BolterDirection>,
    /// B's bolter current passed its threshold in the current step.
    pub threshold_reached: bool,
    /// B's current says the fastener is locked (unlocked when unbolting).
    pub locked: bool,
    /// The current step timed out on B.
    pub timed_out: bool,
    /// Bolter B is in its initial configuration.
    pub at_home: bool,
    /// Read-back of B's multiplexer lines.
    pub mux: MuxLines,
}
