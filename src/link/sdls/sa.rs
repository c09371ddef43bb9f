//! A security association (355.0-B-2 §2.3.1): one SPI, one key, the channel it protects, the
//! authentication mask, and the counter of its one direction.
//!
//! Protecting a frame (355.0-B-2 §2.3.2, YAMCS's `applySecurity`) works on a frame already
//! laid out with room for the security header and trailer: the security header gets the SPI
//! and the next IV, the data between them is encrypted in place, the MAC goes into the
//! trailer; the caller then writes the FECF (it covers the frame as sent). Verifying
//! (YAMCS's `processSecurity`) is the reverse, and changes nothing in the frame or the
//! association unless the frame is accepted: the anti-replay window is checked first (a
//! replay costs no cryptography), then the MAC (before anything is decrypted), and only an
//! authenticated frame moves the window.
//!
//! GCM's inputs: the nonce is the IV; the additional authenticated data is the frame from its
//! first octet through the security header, ANDed with the association's [`AuthMask`]; the
//! plaintext is everything between the security header and the trailer.

use super::counter::{ReplayWindow, TxCounter};
use super::iv::{Iv, IV_LEN};
use super::key::{Key256, Schedule};
use super::{SdlsError, SdlsRefusal, HEADER_LEN, MAC_LEN, OVERHEAD, SPI_LEN};
use aes_gcm::aead::AeadInPlace;

/// The longest authentication mask: a primary header (up to 6 octets here), a segment
/// header, the security header (14), with room to spare.
pub const MAX_MASK_LEN: usize = 32;

/// Which header bits the MAC covers: the AAD is the frame's first `len` octets ANDed with
/// these (355.0-B-2 §4.2.2.2; YAMCS's `authMask`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AuthMask {
    bytes: [u8; MAX_MASK_LEN],
    len: u8,
}

impl AuthMask {
    /// A mask of these octets, `None` when longer than [`MAX_MASK_LEN`].
    pub const fn new(octets: &[u8]) -> Option<AuthMask> {
        if octets.len() > MAX_MASK_LEN {
            return None;
        }
        Some(AuthMask::truncated(octets))
    }

    /// The first [`MAX_MASK_LEN`] octets at most (for the constant masks, all shorter).
    pub(crate) const fn truncated(octets: &[u8]) -> AuthMask {
        let mut bytes = [0u8; MAX_MASK_LEN];
        let n = if octets.len() < MAX_MASK_LEN {
            octets.len()
        } else {
            MAX_MASK_LEN
        };
        // Both splits are at most their slice's length: always `Some`.
        if let (Some((from, _)), Some((to, _))) =
            (octets.split_at_checked(n), bytes.split_at_mut_checked(n))
        {
            to.copy_from_slice(from);
        }
        // n <= MAX_MASK_LEN = 32: its low octet is all of it.
        let [.., len] = n.to_be_bytes();
        AuthMask { bytes, len }
    }

    /// The mask's octets.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// The AAD of `frame` under this mask, in `out`; `None` when the frame is shorter.
    fn aad<'a>(&self, frame: &[u8], out: &'a mut [u8; MAX_MASK_LEN]) -> Option<&'a [u8]> {
        let mask = self.as_bytes();
        let head = frame.get(..mask.len())?;
        for ((o, f), m) in out.iter_mut().zip(head).zip(mask) {
            *o = f & m;
        }
        out.get(..mask.len())
    }
}

/// The global virtual channel an association protects: a frame of another spacecraft or
/// channel under its SPI is refused ([`SdlsRefusal::WrongChannel`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Channel {
    /// Spacecraft ID (10 bits).
    pub spacecraft_id: u16,
    /// Virtual channel ID.
    pub vcid: u8,
}

/// The direction of an association, with its counter.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Role {
    /// This end protects frames.
    Send(TxCounter),
    /// This end verifies frames.
    Receive(ReplayWindow),
}

/// One security association: AES-256-GCM with a 12-octet IV and a 16-octet MAC.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SecurityAssociation {
    spi: u16,
    /// The key as its schedule, built once (the key itself is dropped, zeroized, in `new`).
    schedule: Schedule,
    channel: Channel,
    mask: AuthMask,
    role: Role,
}

impl SecurityAssociation {
    /// An association of `spi` under `key` for `channel`, its AAD masked by `mask`. The key
    /// schedule is built here, once for the association's lifetime; the key is dropped
    /// (zeroized).
    pub fn new(spi: u16, key: Key256, channel: Channel, mask: AuthMask, role: Role) -> Self {
        SecurityAssociation {
            spi,
            schedule: key.schedule(),
            channel,
            mask,
            role,
        }
    }

    /// The SPI.
    pub fn spi(&self) -> u16 {
        self.spi
    }

    /// The channel it protects.
    pub fn channel(&self) -> Channel {
        self.channel
    }

    /// The authentication mask.
    pub fn mask(&self) -> &AuthMask {
        &self.mask
    }

    /// The direction and its counter.
    pub fn role(&self) -> &Role {
        &self.role
    }

    /// The durable number to write now (the sender's reservation or the receiver's floor).
    pub fn due(&self) -> Option<u128> {
        match &self.role {
            Role::Send(c) => c.due(),
            Role::Receive(w) => w.due(),
        }
    }

    /// A receiving association resumes after a restart from the last IV it accepted
    /// ([`ReplayWindow::resume`]); false for a sending one, or an IV beyond the floor.
    pub fn resume(&mut self, last: Iv) -> bool {
        match &mut self.role {
            Role::Receive(w) => w.resume(last),
            Role::Send(_) => false,
        }
    }

    /// The shell wrote `value` durably.
    pub fn persisted(&mut self, value: u128) -> bool {
        match &mut self.role {
            Role::Send(c) => c.persisted(value),
            Role::Receive(w) => w.persisted(value),
        }
    }

    /// Where the security header starts and the MAC ends must leave room for both and for
    /// the mask, which may reach no further than the security header. Returns where the
    /// security header ends and the octets of the text between it and the MAC.
    fn layout(
        &self,
        len: usize,
        sec_start: usize,
        mac_end: usize,
    ) -> Result<(usize, usize), SdlsError> {
        let bad = SdlsError::Layout {
            sec_start,
            mac_end,
            len,
        };
        let needed = sec_start.checked_add(OVERHEAD).ok_or(bad)?;
        if mac_end > len || mac_end < needed {
            return Err(bad);
        }
        // sec_start + HEADER_LEN + MAC_LEN = needed <= mac_end: neither form saturates.
        let header_end = sec_start.saturating_add(HEADER_LEN);
        let text = mac_end.saturating_sub(header_end).saturating_sub(MAC_LEN);
        let mask = self.mask.as_bytes().len();
        if mask > header_end {
            return Err(SdlsError::MaskTooLong { mask, header_end });
        }
        Ok((header_end, text))
    }

    /// Protects `frame` in place: its security header at `sec_start`, its MAC ending at
    /// `mac_end`, the plaintext between them. Returns the IV used. The caller writes the
    /// FECF afterwards.
    pub fn protect(
        &mut self,
        frame: &mut [u8],
        sec_start: usize,
        mac_end: usize,
    ) -> Result<Iv, SdlsError> {
        let (header_end, text) = self.layout(frame.len(), sec_start, mac_end)?;
        let Role::Send(counter) = &mut self.role else {
            return Err(SdlsError::NotSender { spi: self.spi });
        };
        let iv = counter.take()?;
        // The layout holds both splits (header_end and the text end within the frame).
        let bad = SdlsError::Layout {
            sec_start,
            mac_end,
            len: 0,
        };
        let (head, rest) = frame.split_at_mut_checked(header_end).ok_or(bad)?;
        let sec = head.get_mut(sec_start..).ok_or(bad)?;
        let (spi, iv_field) = sec.split_at_mut(SPI_LEN);
        spi.copy_from_slice(&self.spi.to_be_bytes());
        iv_field.copy_from_slice(&iv.to_bytes());
        let mut aad = [0u8; MAX_MASK_LEN];
        let aad = self.mask.aad(head, &mut aad).unwrap_or(&[]);
        let (plain, trailer) = rest.split_at_mut_checked(text).ok_or(bad)?;
        let tag = self
            .schedule
            .cipher()
            .encrypt_in_place_detached(&iv.to_bytes().into(), aad, plain)
            .map_err(|_| SdlsError::Cipher)?;
        if let Some(mac) = trailer.get_mut(..MAC_LEN) {
            mac.copy_from_slice(&tag);
        }
        Ok(iv)
    }

    /// Verifies `frame` in place (the reverse of [`SecurityAssociation::protect`]) as a frame
    /// of `channel`: on success the data between the security header and the MAC is the
    /// plaintext, and the window has moved to the frame's IV. On refusal neither the frame
    /// nor the association has changed (except that an authenticated frame beyond the floor
    /// asks for the next reservation).
    pub fn verify(
        &mut self,
        frame: &mut [u8],
        sec_start: usize,
        mac_end: usize,
        channel: Channel,
    ) -> Result<Iv, SdlsRefusal> {
        let malformed = SdlsRefusal::Truncated {
            needed: sec_start.saturating_add(OVERHEAD),
            found: mac_end.min(frame.len()),
        };
        let (header_end, text) = self
            .layout(frame.len(), sec_start, mac_end)
            .map_err(|_| malformed)?;
        let Role::Receive(window) = &mut self.role else {
            return Err(SdlsRefusal::UnknownSpi { spi: self.spi });
        };
        if channel != self.channel {
            return Err(SdlsRefusal::WrongChannel {
                spi: self.spi,
                expected: self.channel,
                found: channel,
            });
        }
        let (head, rest) = frame.split_at_mut_checked(header_end).ok_or(malformed)?;
        let iv_bytes: [u8; IV_LEN] = head
            .get(sec_start..)
            .and_then(|s| s.get(SPI_LEN..))
            .and_then(|b| b.try_into().ok())
            .ok_or(malformed)?;
        let iv = Iv::from_bytes(iv_bytes);
        window.check(iv)?;
        let mut aad = [0u8; MAX_MASK_LEN];
        let aad = self.mask.aad(head, &mut aad).ok_or(malformed)?;
        let (cipher_text, trailer) = rest.split_at_mut_checked(text).ok_or(malformed)?;
        let tag: [u8; MAC_LEN] = trailer
            .get(..MAC_LEN)
            .and_then(|t| t.try_into().ok())
            .ok_or(malformed)?;
        // aes-gcm checks the tag before it decrypts: a refused frame is left as it came.
        self.schedule
            .cipher()
            .decrypt_in_place_detached(&iv_bytes.into(), aad, cipher_text, &tag.into())
            .map_err(|_| SdlsRefusal::BadMac { spi: self.spi })?;
        if let Err(e) = window.admit(iv) {
            // Put the ciphertext back: a refused frame is left as it came.
            let _ = self.schedule.cipher().encrypt_in_place_detached(
                &iv_bytes.into(),
                aad,
                cipher_text,
            );
            return Err(e);
        }
        Ok(iv)
    }
}
