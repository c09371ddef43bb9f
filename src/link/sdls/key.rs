//! The secret key of a security association: 256 bits for AES-256-GCM.
//!
//! A key is never shown: its `Debug` prints `Key256(..)`, it has no `Display`, no serde and no
//! accessor that hands the octets out of the crate; its octets are overwritten with zeros when
//! it is dropped (`zeroize`). The AES key schedule built from it for one frame is dropped, and
//! zeroized by `aes` (its `zeroize` feature), before the call returns.
//!
//! ```
//! use mmic::link::sdls::Key256;
//!
//! let key = Key256::from_bytes([7; 32]);
//! assert_eq!(format!("{key:?}"), "Key256(..)");
//! ```

use zeroize::{Zeroize, ZeroizeOnDrop};

/// Octets of a key.
pub const KEY_LEN: usize = 32;

/// A 256-bit AES key, zeroized on drop.
#[derive(Clone, Zeroize, ZeroizeOnDrop)]
pub struct Key256([u8; KEY_LEN]);

impl Key256 {
    /// Takes the key's octets (the shell read them from where it keeps keys: a file outside
    /// the source tree, a flash partition).
    pub const fn from_bytes(bytes: [u8; KEY_LEN]) -> Key256 {
        Key256(bytes)
    }

    /// Reads a key from exactly 32 octets (a key file's contents).
    pub fn from_slice(bytes: &[u8]) -> Result<Key256, super::SdlsError> {
        let array: [u8; KEY_LEN] = bytes.try_into().map_err(|_| super::SdlsError::KeyLength {
            expected: KEY_LEN,
            found: bytes.len(),
        })?;
        Ok(Key256(array))
    }

    /// The key schedule for one operation (crate-private: the octets never leave the crate).
    pub(crate) fn cipher(&self) -> aes_gcm::Aes256Gcm {
        use aes_gcm::KeyInit;
        // A reference conversion: no copy of the octets is left on the stack.
        aes_gcm::Aes256Gcm::new((&self.0).into())
    }
}

impl core::fmt::Debug for Key256 {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Key256(..)")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Key256 {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "Key256(..)")
    }
}
