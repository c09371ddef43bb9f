//! What a CFDP entity needs of a filestore, as a trait the shell implements (flash on the
//! server board's image, memory in the simulator and the tests): named files to send, and
//! per transaction an incoming file that no one sees by name until the receiver has checked
//! it whole and [`Filestore::commit`]s it. A half-received file is never under its name.
//!
//! ```
//! use mmic::cfdp::entity::{Filestore, MemoryStore, StoreError, TransactionId};
//!
//! let mut store = MemoryStore::<2, 64>::new();
//! let id = TransactionId { source: 1, seq: 7 };
//! store.write_incoming(id, 0, b"plan").unwrap();
//! assert_eq!(store.size(b"plan.txt"), Err(StoreError::NotFound));
//! store.commit(id, b"plan.txt").unwrap();
//! let mut buf = [0u8; 8];
//! assert_eq!(store.read(b"plan.txt", 0, &mut buf), Ok(4));
//! ```

use super::TransactionId;
use heapless::Vec;

/// Why the filestore refused; the transaction ends with filestore rejection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// No file of that name (or no incoming file of that transaction).
    #[error("no such file")]
    NotFound,
    /// The file would not fit.
    #[error("{needed} octets needed, {capacity} available")]
    Full {
        /// Octets the file would need.
        needed: u32,
        /// Octets the store can give it.
        capacity: u32,
    },
    /// A file of that name was committed by transaction `newer`, later than `id` of the same
    /// source: an older transaction, late, never replaces it (decision `cfdp-restarts`).
    #[error("{id:?} is older than {newer:?}, which wrote that file")]
    Stale {
        /// The transaction that would commit.
        id: TransactionId,
        /// The one that did, later.
        newer: TransactionId,
    },
    /// A name the store cannot hold (too long).
    #[error("a name of {len} octets, more than the {max} the store holds")]
    Name {
        /// Octets of the name.
        len: usize,
        /// Octets at most.
        max: usize,
    },
}

/// A CFDP entity's filestore.
pub trait Filestore {
    /// Octets of the named file at `offset` into `buf`: how many (0 at its end).
    fn read(&mut self, name: &[u8], offset: u32, buf: &mut [u8]) -> Result<usize, StoreError>;
    /// The named file's size.
    fn size(&mut self, name: &[u8]) -> Result<u32, StoreError>;
    /// Writes `data` at `offset` of transaction `id`'s incoming file, made empty on first use.
    fn write_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        data: &[u8],
    ) -> Result<(), StoreError>;
    /// Octets of `id`'s incoming file at `offset` into `buf`: how many (0 at its end).
    fn read_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<usize, StoreError>;
    /// Gives `id`'s incoming file the name `name`, in place of any file of that name, unless
    /// that file was committed by a later transaction of the same source
    /// ([`StoreError::Stale`]): the store remembers which transaction wrote each file.
    fn commit(&mut self, id: TransactionId, name: &[u8]) -> Result<(), StoreError>;
    /// Forgets `id`'s incoming file, if any.
    fn discard(&mut self, id: TransactionId);
    /// Forgets every incoming file: the shell calls it at boot, before the entity's first
    /// step, since a restarted entity has no receiver left to finish them (727.0 keeps no
    /// transaction across a restart: decision `cfdp-restarts`).
    fn discard_all_incoming(&mut self);
}

/// Longest name a [`MemoryStore`] keeps, octets.
pub const NAME_MAX: usize = 64;

/// Who a slot of a [`MemoryStore`] belongs to.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum Owner {
    Named(Vec<u8, NAME_MAX>),
    Incoming(TransactionId),
}

/// A filestore in memory: up to `F` files (named or incoming) of up to `C` octets each.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct MemoryStore<const F: usize, const C: usize> {
    files: Vec<Slot<C>, F>,
}

/// A file: whose it is, the transaction that wrote it (none when an operator put it), its
/// octets.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Slot<const C: usize> {
    owner: Owner,
    by: Option<TransactionId>,
    data: Vec<u8, C>,
}

impl<const F: usize, const C: usize> MemoryStore<F, C> {
    /// No files.
    pub const fn new() -> Self {
        MemoryStore { files: Vec::new() }
    }

    /// Puts a named file (as an operator would), replacing any of that name.
    pub fn put(&mut self, name: &[u8], data: &[u8]) -> Result<(), StoreError> {
        let owner = Owner::Named(name_of(name)?);
        let full = StoreError::Full {
            needed: len_u32(data.len()),
            capacity: len_u32(C),
        };
        let data = Vec::from_slice(data).map_err(|_| full)?;
        self.files.retain(|f| f.owner != owner);
        let slot = Slot {
            owner,
            by: None,
            data,
        };
        self.files.push(slot).map_err(|_| full)
    }

    /// The named file's octets.
    pub fn get(&self, name: &[u8]) -> Option<&[u8]> {
        self.named(name).map(|f| f.data.as_slice())
    }

    fn named(&self, name: &[u8]) -> Option<&Slot<C>> {
        self.files
            .iter()
            .find(|f| matches!(&f.owner, Owner::Named(n) if n.as_slice() == name))
    }

    /// How many incoming files are held (of transactions not yet ended).
    pub fn incoming(&self) -> usize {
        self.files
            .iter()
            .filter(|f| matches!(f.owner, Owner::Incoming(_)))
            .count()
    }

    fn file(&mut self, owner: &Owner) -> Option<&mut Vec<u8, C>> {
        self.files
            .iter_mut()
            .find_map(|f| (f.owner == *owner).then_some(&mut f.data))
    }
}

impl<const F: usize, const C: usize> Filestore for MemoryStore<F, C> {
    fn read(&mut self, name: &[u8], offset: u32, buf: &mut [u8]) -> Result<usize, StoreError> {
        let data = self.get(name).ok_or(StoreError::NotFound)?;
        Ok(copy_out(data, offset, buf))
    }

    fn size(&mut self, name: &[u8]) -> Result<u32, StoreError> {
        self.get(name)
            .map(|d| len_u32(d.len()))
            .ok_or(StoreError::NotFound)
    }

    fn write_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        data: &[u8],
    ) -> Result<(), StoreError> {
        let owner = Owner::Incoming(id);
        if self.file(&owner).is_none() {
            let slot = Slot {
                owner: owner.clone(),
                by: Some(id),
                data: Vec::new(),
            };
            self.files.push(slot).map_err(|_| StoreError::Full {
                needed: len_u32(data.len()),
                capacity: 0,
            })?;
        }
        let file = self.file(&owner).ok_or(StoreError::NotFound)?;
        let start = usize::try_from(offset).unwrap_or(usize::MAX);
        let end = start.saturating_add(data.len());
        let full = StoreError::Full {
            needed: len_u32(end),
            capacity: len_u32(C),
        };
        if end > file.len() {
            file.resize(end, 0).map_err(|_| full)?;
        }
        file.get_mut(start..end).ok_or(full)?.copy_from_slice(data);
        Ok(())
    }

    fn read_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<usize, StoreError> {
        let data = self
            .file(&Owner::Incoming(id))
            .ok_or(StoreError::NotFound)?;
        Ok(copy_out(data, offset, buf))
    }

    fn commit(&mut self, id: TransactionId, name: &[u8]) -> Result<(), StoreError> {
        let named = Owner::Named(name_of(name)?);
        let incoming = Owner::Incoming(id);
        let by = self.named(name).and_then(|f| f.by);
        if let Some(newer) = by.filter(|b| b.source == id.source && b.seq > id.seq) {
            return Err(StoreError::Stale { id, newer });
        }
        if self.file(&incoming).is_none() {
            // An empty file: nothing was ever written.
            self.write_incoming(id, 0, &[])?;
        }
        self.files.retain(|f| f.owner != named);
        for f in self.files.iter_mut() {
            if f.owner == incoming {
                f.owner = named.clone();
            }
        }
        Ok(())
    }

    fn discard(&mut self, id: TransactionId) {
        self.files.retain(|f| f.owner != Owner::Incoming(id));
    }

    fn discard_all_incoming(&mut self) {
        self.files
            .retain(|f| !matches!(f.owner, Owner::Incoming(_)));
    }
}

/// `name` as a stored name (`name` when too long).
fn name_of(name: &[u8]) -> Result<Vec<u8, NAME_MAX>, StoreError> {
    Vec::from_slice(name).map_err(|_| StoreError::Name {
        len: name.len(),
        max: NAME_MAX,
    })
}

/// Copies `data` from `offset` into `buf`: how many octets.
fn copy_out(data: &[u8], offset: u32, buf: &mut [u8]) -> usize {
    let start = usize::try_from(offset).unwrap_or(usize::MAX);
    let from = data.get(start..).unwrap_or(&[]);
    let n = from.len().min(buf.len());
    if let (Some(dst), Some(src)) = (buf.get_mut(..n), from.get(..n)) {
        dst.copy_from_slice(src);
    }
    n
}

/// A length as a file size (saturating: files here are under 4 GiB).
fn len_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}
