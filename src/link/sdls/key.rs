//! The secret key of a security association: 256 bits for AES-256-GCM.
//!
//! A key is never shown: its `Debug` prints `Key256(..)`, it has no `Display`, no serde and no
//! accessor that hands the octets out of the crate; its octets are overwritten with zeros when
//! it is dropped (`zeroize`).
//!
//! A security association keeps its key only as a [`Schedule`]: the AES-256 key schedule and
//! the GHASH key built from it once, when the association is made, and kept for its lifetime
//! (built per frame, they cost some 16,000 instructions of every frame on RV32:
//! benches/rv32/README.md). The schedule is never shown either (`Schedule(..)`), and is
//! zeroized when the association is dropped or replaced (a link secured again under new keys
//! drops its old table) by `aes`, `ghash` and `polyval` (their `zeroize` features, asserted
//! below at compile time) — except on x86, x86_64 and aarch64 hosts, where polyval 0.6's
//! run-time CPU detection keeps its state in a union without `Drop`: the GHASH key H of a
//! dropped association stays in freed memory there (the host simulator; the ESP32 targets use
//! the software backend, which zeroizes; the AES key schedule is zeroized on every target).
//! What this covers is the value dropped: a copy the compiler left behind when an association
//! was moved (into its table, say) is not cleared, for the schedule as for the key. The RV32
//! runner (`mmic-rv32 --sdls`, run by `benches/rv32/run` in CI) checks on the ESP32-C3's
//! software backends that every octet of a dropped association's schedule and GHASH key is
//! zero; no test reads freed memory on the host.
//!
//! What a durable store may record of a key is its [`Fingerprint`], a key check value: the
//! first 8 octets of AES-256 under the key of one fixed block, [`FINGERPRINT_BLOCK`]. It tells
//! whether a stored counter belongs to the key in use (a counter kept for another key must not
//! be continued, nor one for this key forgotten). It reveals nothing of the key (AES is a
//! pseudo-random permutation: one output on a fixed input is the banking world's key check
//! value) nor of any frame: GCM with 96-bit IVs enciphers the zero block (its GHASH key H, which
//! the usual check value of the zero block would give away) and counter blocks `IV ‖ c` with
//! `c` from 1 up; the fingerprint's block ends in a zero counter and starts with a non-zero
//! label, so GCM never enciphers it. Why not HMAC: `hmac` 0.12 keeps the key XOR its pads in a
//! state it does not zeroize, while `aes` zeroizes its key schedule on drop.
//!
//! [`Key256::check`] refuses keys a person might paste by mistake: every octet the same
//! (all zeros), and the fixed test keys of this library, its proofs and the GCM test vectors.
//!
//! ```
//! use mmic::link::sdls::Key256;
//! use mmic::link::sdls::key::WeakKey;
//!
//! let key = Key256::from_bytes([7; 32]);
//! assert_eq!(format!("{key:?}"), "Key256(..)");
//! assert_eq!(key.check(), Err(WeakKey::Repeated { octet: 7 }));
//! let key = Key256::from_bytes(core::array::from_fn(|i| (i as u8).wrapping_mul(73) ^ 0x3c));
//! assert!(key.check().is_ok());
//! assert_eq!(key.fingerprint(), key.clone().fingerprint());
//! assert_eq!(format!("{:?}", key.fingerprint()), "Fingerprint(..)");
//! assert_eq!(format!("{:?}", key.schedule()), "Schedule(..)");
//! ```

use zeroize::{Zeroize, ZeroizeOnDrop};

/// Octets of a key.
pub const KEY_LEN: usize = 32;

/// Octets of a key's fingerprint.
pub const FINGERPRINT_LEN: usize = 8;

/// The block the fingerprint enciphers: a 12-octet label (never all zeros), then a zero 32-bit
/// counter, which GCM with 96-bit IVs never enciphers.
pub const FINGERPRINT_BLOCK: [u8; 16] = *b"mmic-kcv-v1\x01\0\0\0\0";

// The key schedule and the GHASH key are zeroized on drop only if the crates' `zeroize`
// features are on: a build that lost them fails here (aes implements `ZeroizeOnDrop`; polyval
// zeroizes in a `Drop` of its software backend, the one the ESP32 targets use).
const _: () = {
    const fn zeroized_on_drop<T: zeroize::ZeroizeOnDrop>() {}
    zeroized_on_drop::<aes::Aes256>();
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64", target_arch = "aarch64")))]
    assert!(core::mem::needs_drop::<ghash::GHash>());
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64", target_arch = "aarch64")))]
    assert!(core::mem::needs_drop::<polyval::Polyval>());
};

/// A 256-bit AES key, zeroized on drop.
#[derive(Clone, Zeroize, ZeroizeOnDrop)]
pub struct Key256([u8; KEY_LEN]);

/// Why a key is refused ([`Key256::check`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WeakKey {
    /// Every octet is the same (all zeros, an erased flash's all ones, a filler).
    #[error("the key's 32 octets are all {octet:#04x}: not a key")]
    Repeated {
        /// The octet.
        octet: u8,
    },
    /// One of the fixed keys of this library's tests and proofs or of the GCM test vectors:
    /// public.
    #[error("the key is a published test key ({name}): anyone has it")]
    TestKey {
        /// Which.
        name: &'static str,
    },
}

/// The published keys [`Key256::check`] refuses besides repeated octets: the proofs' fixed
/// test keys (`proofs/src/sdls.rs`, `test_key`) and the GCM specification's test cases 16 to
/// 18 (McGrew and Viega; test cases 13 to 15 use the zero key).
pub fn test_keys() -> [(&'static str, [u8; KEY_LEN]); 3] {
    let proofs = |which: u8| -> [u8; KEY_LEN] {
        let mut key = [0u8; KEY_LEN];
        // The key first: the zip stops at its 32nd octet, before the counter would pass 255.
        for (k, i) in key.iter_mut().zip(0u8..) {
            *k = i.wrapping_mul(0x9d) ^ which.wrapping_mul(0x5b) ^ 0xa7;
        }
        key
    };
    let gcm16 = || -> [u8; KEY_LEN] {
        let mut key = [0u8; KEY_LEN];
        for (k, g) in key.iter_mut().zip(GCM16.iter().cycle()) {
            *k = *g;
        }
        key
    };
    const GCM16: [u8; 16] = [
        0xfe, 0xff, 0xe9, 0x92, 0x86, 0x65, 0x73, 0x1c, 0x6d, 0x6a, 0x8f, 0x94, 0x67, 0x30, 0x83,
        0x08,
    ];
    [
        ("proofs test_key(0)", proofs(0)),
        ("proofs test_key(1)", proofs(1)),
        ("GCM test case 16", gcm16()),
    ]
}

/// What a durable store records of a key: the first 8 octets of AES-256 under the key of
/// [`FINGERPRINT_BLOCK`] (a key check value; the module's documentation says why it reveals
/// nothing). Not a secret, but kept out of logs all the same (`Debug` prints
/// `Fingerprint(..)`).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint([u8; FINGERPRINT_LEN]);

impl Fingerprint {
    /// From its octets (read back from a store).
    pub const fn from_bytes(bytes: [u8; FINGERPRINT_LEN]) -> Fingerprint {
        Fingerprint(bytes)
    }

    /// Its octets (to write into a store).
    pub const fn to_bytes(self) -> [u8; FINGERPRINT_LEN] {
        self.0
    }
}

impl core::fmt::Debug for Fingerprint {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Fingerprint(..)")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Fingerprint {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "Fingerprint(..)")
    }
}

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

    /// Refuses a key nobody should use: every octet the same, or a published test key.
    pub fn check(&self) -> Result<(), WeakKey> {
        let first = self.0[0];
        if self.0.iter().all(|&b| b == first) {
            return Err(WeakKey::Repeated { octet: first });
        }
        match test_keys().iter().find(|(_, k)| *k == self.0) {
            Some((name, _)) => Err(WeakKey::TestKey { name }),
            None => Ok(()),
        }
    }

    /// The key's fingerprint (see the module's documentation).
    pub fn fingerprint(&self) -> Fingerprint {
        use aes::cipher::{BlockEncrypt, KeyInit};
        // The key schedule is zeroized when `aes` drops it, at the end of this call.
        let cipher = aes::Aes256::new((&self.0).into());
        let mut block = aes::Block::from(FINGERPRINT_BLOCK);
        cipher.encrypt_block(&mut block);
        let mut out = [0u8; FINGERPRINT_LEN];
        for (o, b) in out.iter_mut().zip(block.iter()) {
            *o = *b;
        }
        Fingerprint(out)
    }

    /// The octets, for the keys partition's writer (crate-private: they never leave the crate
    /// but into a buffer the caller clears).
    pub(crate) fn octets(&self) -> &[u8; KEY_LEN] {
        &self.0
    }

    /// The key schedule and GHASH key, built once for an association's lifetime.
    pub fn schedule(&self) -> Schedule {
        use aes_gcm::KeyInit;
        // A reference conversion: no copy of the octets is left on the stack.
        Schedule(aes_gcm::Aes256Gcm::new((&self.0).into()))
    }
}

/// A key's AES-256 key schedule and GHASH key ([`Key256::schedule`]): what a security
/// association keeps instead of the key, so that a frame costs no key expansion. Never shown,
/// no accessor; zeroized on drop as the module's documentation says.
#[derive(Clone)]
pub struct Schedule(aes_gcm::Aes256Gcm);

impl Schedule {
    /// The cipher (crate-private: the schedule never leaves the crate).
    pub(crate) fn cipher(&self) -> &aes_gcm::Aes256Gcm {
        &self.0
    }
}

impl core::fmt::Debug for Schedule {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Schedule(..)")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Schedule {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "Schedule(..)")
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
