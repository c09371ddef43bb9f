//! The security association table: up to `N` associations by SPI, with what the receiving end
//! refused counted per reason.

use super::iv::Iv;
use super::sa::{Channel, SecurityAssociation};
use super::{SdlsError, SdlsRefusal, SPI_LEN};
use heapless::Vec;

/// Frames verified and refused, per [`SdlsRefusal`] reason (in [`SdlsRefusal::NAMES`]'s
/// order). Each counter wraps at `u32::MAX`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SdlsCounters {
    /// Frames that verified.
    pub accepted: u32,
    /// Frames protected.
    pub protected: u32,
    /// Refused, by reason.
    pub refused: [u32; SdlsRefusal::NAMES.len()],
}

impl SdlsCounters {
    /// Frames refused for any reason.
    pub fn refused_total(&self) -> u32 {
        self.refused.iter().fold(0, |a, b| a.wrapping_add(*b))
    }

    /// Refused for this reason (by name).
    pub fn refused_for(&self, name: &str) -> u32 {
        SdlsRefusal::NAMES
            .iter()
            .position(|n| *n == name)
            .and_then(|i| self.refused.get(i))
            .copied()
            .unwrap_or(0)
    }
}

/// A frame that verified.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verified {
    /// The association.
    pub spi: u16,
    /// Its IV, now the window's last.
    pub iv: Iv,
}

/// Up to `N` security associations.
#[derive(Debug, Clone, Default)]
pub struct SaTable<const N: usize> {
    sas: Vec<SecurityAssociation, N>,
    counters: SdlsCounters,
}

impl<const N: usize> SaTable<N> {
    /// An empty table.
    pub const fn new() -> Self {
        SaTable {
            sas: Vec::new(),
            counters: SdlsCounters {
                accepted: 0,
                protected: 0,
                refused: [0; SdlsRefusal::NAMES.len()],
            },
        }
    }

    /// Adds `sa`; hands it back when the table is full or has its SPI already (heapless's
    /// way: nothing is dropped silently, so the error is as large as the association).
    #[expect(
        clippy::result_large_err,
        reason = "heapless's way: the error hands the association back, so nothing is dropped silently"
    )]
    pub fn add(&mut self, sa: SecurityAssociation) -> Result<(), SecurityAssociation> {
        if self.get(sa.spi()).is_some() {
            return Err(sa);
        }
        self.sas.push(sa)
    }

    /// The association of `spi`.
    pub fn get(&self, spi: u16) -> Option<&SecurityAssociation> {
        self.sas.iter().find(|sa| sa.spi() == spi)
    }

    fn get_mut(&mut self, spi: u16) -> Option<&mut SecurityAssociation> {
        self.sas.iter_mut().find(|sa| sa.spi() == spi)
    }

    /// Every association.
    pub fn iter(&self) -> impl Iterator<Item = &SecurityAssociation> {
        self.sas.iter()
    }

    /// What was verified and refused.
    pub fn counters(&self) -> &SdlsCounters {
        &self.counters
    }

    /// The durable numbers to write now: (SPI, value) pairs.
    pub fn due(&self) -> impl Iterator<Item = (u16, u128)> + '_ {
        self.sas
            .iter()
            .filter_map(|sa| sa.due().map(|v| (sa.spi(), v)))
    }

    /// The shell wrote `value` for `spi` durably.
    pub fn persisted(&mut self, spi: u16, value: u128) -> bool {
        self.get_mut(spi).is_some_and(|sa| sa.persisted(value))
    }

    /// `spi`'s receiving association resumes from the last IV it accepted before a restart
    /// (`last`, below 2^96); false if there is none or the IV is beyond its floor.
    pub fn resume(&mut self, spi: u16, last: u128) -> bool {
        let Some(iv) = Iv::new(last) else {
            return false;
        };
        self.get_mut(spi).is_some_and(|sa| sa.resume(iv))
    }

    /// Whether `spi`'s association can protect a frame now (a sending one whose next IV is
    /// reserved).
    pub fn ready(&self, spi: u16) -> bool {
        self.get(spi).is_some_and(|sa| match sa.role() {
            super::Role::Send(c) => c.next() < c.reserved(),
            super::Role::Receive(_) => false,
        })
    }

    /// Protects `frame` in place under `spi` (see [`SecurityAssociation::protect`]).
    pub fn protect(
        &mut self,
        spi: u16,
        frame: &mut [u8],
        sec_start: usize,
        mac_end: usize,
    ) -> Result<Iv, SdlsError> {
        let sa = self.get_mut(spi).ok_or(SdlsError::NoSuchSpi { spi })?;
        let iv = sa.protect(frame, sec_start, mac_end)?;
        self.counters.protected = self.counters.protected.wrapping_add(1);
        Ok(iv)
    }

    /// Verifies `frame` in place, a frame of `channel` whose security header starts at
    /// `sec_start` and whose MAC ends at `mac_end`: the SPI picks the association. Counts
    /// the outcome.
    pub fn verify(
        &mut self,
        frame: &mut [u8],
        sec_start: usize,
        mac_end: usize,
        channel: Channel,
    ) -> Result<Verified, SdlsRefusal> {
        let outcome = self.verify_uncounted(frame, sec_start, mac_end, channel);
        match &outcome {
            Ok(_) => self.counters.accepted = self.counters.accepted.wrapping_add(1),
            Err(e) => {
                if let Some(c) = self.counters.refused.get_mut(e.position()) {
                    *c = c.wrapping_add(1);
                }
            }
        }
        outcome
    }

    fn verify_uncounted(
        &mut self,
        frame: &mut [u8],
        sec_start: usize,
        mac_end: usize,
        channel: Channel,
    ) -> Result<Verified, SdlsRefusal> {
        let spi = frame
            .get(sec_start..)
            .and_then(|b| b.first_chunk::<SPI_LEN>())
            .copied()
            .map(u16::from_be_bytes)
            .ok_or(SdlsRefusal::Truncated {
                needed: sec_start.saturating_add(super::OVERHEAD),
                found: frame.len(),
            })?;
        let sa = self.get_mut(spi).ok_or(SdlsRefusal::UnknownSpi { spi })?;
        let iv = sa.verify(frame, sec_start, mac_end, channel)?;
        Ok(Verified { spi, iv })
    }
}
