//! FARM-1's sliding window (232.1-B-2 §6.1.8.2): its width, checked once, and where an N(S)
//! lies against V(R), which is what sorts an AD frame into E1–E5.

/// The mission's FARM sliding window width W (`spec/ccsds/link.toml`, `cop1.farm_window`).
pub const FARM_WINDOW: u8 = 20;

/// The FARM sliding window width W (232.1-B-2 §6.1.8.2): even, 2..=254, split into a positive
/// half PW and a negative half NW, both W/2. With V(R) the window holds W sequence numbers:
/// V(R) itself, the PW − 1 above it, the NW below; the other 256 − W are the lockout area.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FarmWindow(u8);

/// A window width 232.1-B-2 §6.1.8.2 does not allow: odd, or outside 2..=254.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("FARM sliding window width must be even and within 2..=254, found {found}")]
pub struct FarmWindowError {
    /// The width asked for.
    pub found: u8,
}

impl FarmWindow {
    /// The mission's window, [`FARM_WINDOW`].
    pub const MISSION: FarmWindow = FarmWindow(FARM_WINDOW);

    /// The window of width `w`, refused unless even and within 2..=254.
    pub const fn new(w: u8) -> Result<FarmWindow, FarmWindowError> {
        if w >= 2 && w <= 254 && w.is_multiple_of(2) {
            Ok(FarmWindow(w))
        } else {
            Err(FarmWindowError { found: w })
        }
    }

    /// W.
    pub const fn width(self) -> u8 {
        self.0
    }

    /// PW = W/2: the positive window holds N(S) ∈ [V(R)+1, V(R)+PW−1].
    pub const fn positive(self) -> u8 {
        self.0 / 2
    }

    /// NW = W/2: the negative window holds N(S) ∈ [V(R)−NW, V(R)−1].
    pub const fn negative(self) -> u8 {
        self.0 / 2
    }

    /// Where `ns` lies relative to `vr` (232.1-B-2 Table 6-1's conditions of E1–E5).
    pub const fn place(self, vr: u8, ns: u8) -> WindowPlace {
        let ahead = ns.wrapping_sub(vr);
        let behind = vr.wrapping_sub(ns);
        if ahead == 0 {
            WindowPlace::Expected
        } else if ahead < self.positive() {
            WindowPlace::Positive
        } else if behind <= self.negative() {
            WindowPlace::Negative
        } else {
            WindowPlace::Lockout
        }
    }
}

impl Default for FarmWindow {
    fn default() -> FarmWindow {
        FarmWindow::MISSION
    }
}

/// Where an AD frame's N(S) lies relative to V(R) and the window.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum WindowPlace {
    /// N(S) = V(R): the frame expected next.
    Expected,
    /// V(R) < N(S) ≤ V(R) + PW − 1: ahead, a frame before it was lost.
    Positive,
    /// V(R) − NW ≤ N(S) < V(R): behind, already accepted (a retransmission).
    Negative,
    /// Neither: the lockout area.
    Lockout,
}
