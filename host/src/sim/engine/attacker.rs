//! The attacker on a robot's uplink (SDLS runs with `attack` > 0): it replays captured TC
//! frames, flips a bit in one (its FECF made good again), or sends a BC frame from its own
//! address.

use std::collections::VecDeque;

/// The attacker on a robot's uplink ([`crate::sim::SdlsConfig::attack`]): it captures the TC data
/// frames the uplink delivers and, at its rate, sends one of them again or a copy with one bit
/// flipped (its FECF made good again). Its draws are its own stream, seeded from the robot's.
pub(super) struct Attacker {
    rate: f64,
    rng: fastrand::Rng,
    /// The last [`Attacker::KEPT`] data frames the uplink delivered.
    captured: VecDeque<Vec<u8>>,
    /// Attack frames waiting for the server board's loop.
    pub(super) waiting: VecDeque<Vec<u8>>,
    pub(super) sent: u64,
    pub(super) refused_sdls: u64,
    pub(super) refused_frame: u64,
    pub(super) passed: u64,
}

impl Attacker {
    const KEPT: usize = 64;

    /// An attacker sending at `rate`, its draws seeded from the robot's `seed`.
    pub(super) fn new(rate: f64, seed: u64) -> Attacker {
        Attacker {
            rate,
            rng: fastrand::Rng::with_seed(seed ^ 0xa77a_c4e5_0000),
            captured: VecDeque::new(),
            waiting: VecDeque::new(),
            sent: 0,
            refused_sdls: 0,
            refused_frame: 0,
            passed: 0,
        }
    }

    /// The uplink delivered `frame`: captured if a data frame (BC frames go in clear by
    /// decision `sdls-clear-bc`), and maybe an attack frame made.
    pub(super) fn delivered(&mut self, frame: &[u8]) {
        let data_frame = frame.first().is_some_and(|b| b & 0x10 == 0);
        if data_frame && frame.len() > 2 {
            if self.captured.len() == Self::KEPT {
                self.captured.pop_front();
            }
            self.captured.push_back(frame.to_vec());
        }
        if self.captured.is_empty() || self.rng.f64() >= self.rate {
            return;
        }
        let pick = self.rng.usize(..self.captured.len());
        let mut f = self.captured[pick].clone();
        match self.rng.u8(..3) {
            0 => {}
            1 => {
                let n = f.len();
                let bit = self.rng.usize(..(n - 2) * 8);
                f[bit / 8] ^= 0x80 >> (bit % 8);
                let crc = mmic::ccsds::pec(&f[..n - 2]);
                f[n - 2..].copy_from_slice(&crc.to_be_bytes());
            }
            _ => {
                // A BC frame (in clear by decision sdls-clear-bc) for the same spacecraft:
                // Set V(R) to any value, or Unlock, from the attacker's own address.
                use mmic::link::tc_frame::{
                    SpacecraftId, TcContent, TcFrameRepr, TcPrimaryHeader, Vcid,
                };
                let Some(h) = TcPrimaryHeader::read(&f) else {
                    return;
                };
                let command = if self.rng.bool() {
                    mmic::link::ControlCommand::Unlock
                } else {
                    mmic::link::ControlCommand::SetVr(self.rng.u8(..))
                };
                let repr = TcFrameRepr {
                    spacecraft_id: SpacecraftId::new(h.spacecraft_id).unwrap_or_default(),
                    vcid: Vcid::new(h.vcid).unwrap_or_default(),
                    seq: 0,
                    content: TcContent::Bc(command),
                };
                let mut b = [0u8; 16];
                let Ok(n) = repr.emit(&mut b) else {
                    return;
                };
                f = b[..n].to_vec();
            }
        }
        self.sent += 1;
        self.waiting.push_back(f);
    }
}
