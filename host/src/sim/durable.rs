//! The simulator's durable store: the entries of `mmic::node::server::store` (SDLS counters and
//! their keys' fingerprints, FARM-1's progress, the gateway's kept telecommand keys) for each
//! end of the space data link, the server board's (`server`) and the ground's (`ground`).
//!
//! In memory for the run with keys made for the run (they die with it), or in a state file with
//! keys the user gave (`--sdls-state FILE` beside `--sdls-keys DIR`): every write goes to a
//! temporary file beside it, is flushed to the disk (fsync), renamed over the state file, and
//! the directory flushed, before the library is told it is durable, so that a process killed
//! at any instant leaves either the old file or the new one. A state file never holds a key;
//! it is made by the provisioning step (`mmic sdls provision`), never by a run: a missing or
//! blank one stops the run before anything is sent.
//!
//! ```no_run
//! use mmic::node::server::store::Entry;
//! use mmic_host::sim::durable::{Durable, Section};
//!
//! let d = Durable::open(std::path::Path::new("target/sdls-state.json")).unwrap();
//! d.write(Section::Server, &[Entry { key: 0x0201, aux: 0, value: 512 }]).unwrap();
//! assert_eq!(d.lookup(Section::Server, 0x0201), Some((0, 512)));
//! ```

use mmic::node::server::store::{Entry, VALUE_LIMIT};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The state file's format name.
pub const FORMAT: &str = "mmic-durable/1";

/// Which end's entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Section {
    /// The server board's.
    Server,
    /// The ground's.
    Ground,
}

impl Section {
    /// Its name in the file.
    pub const fn name(self) -> &'static str {
        match self {
            Section::Server => "server",
            Section::Ground => "ground",
        }
    }
}

/// Why a state file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum DurableError {
    /// It does not exist: the provisioning step makes it.
    #[error("{path}: no such state file: make it with `mmic sdls provision --keys DIR --state {path}` (once, for these keys)")]
    Missing {
        /// The file.
        path: PathBuf,
    },
    /// It exists already (provisioning refuses to go back to fresh counters).
    #[error("{path}: the state file exists: provisioning it again would start the counters afresh under keys that may have been used (IV reuse); keep it, or provision new keys")]
    Exists {
        /// The file.
        path: PathBuf,
    },
    /// It cannot be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// It is not a state file of this format.
    #[error("{path}: not a {FORMAT} state file: {why}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

#[derive(Debug, Default)]
struct Inner {
    path: Option<PathBuf>,
    sections: BTreeMap<Section, BTreeMap<u16, (u8, u128)>>,
    /// Writes that failed (the library was not told they were durable).
    failed: u64,
    /// After a failure, no write is tried before this (the wait doubles from 10 ms to 1 s
    /// while they keep failing: a broken disk is not hammered on every pass).
    retry_at: Option<std::time::Instant>,
    backoff_ms: u64,
}

/// The store, shared by the nodes of a run (cheap to clone: one store).
#[derive(Debug, Clone, Default)]
pub struct Durable(Arc<Mutex<Inner>>);

fn lock(d: &Durable) -> std::sync::MutexGuard<'_, Inner> {
    d.0.lock().unwrap_or_else(|p| p.into_inner())
}

impl Durable {
    /// A store in memory, for the run (keys made for the run).
    pub fn memory() -> Durable {
        Durable::default()
    }

    /// The state file at `path`, which must exist (the provisioning step made it).
    pub fn open(path: &Path) -> Result<Durable, DurableError> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(DurableError::Missing {
                    path: path.to_path_buf(),
                })
            }
            Err(source) => {
                return Err(DurableError::Io {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        let sections = parse(&text).map_err(|why| DurableError::Format {
            path: path.to_path_buf(),
            why,
        })?;
        Ok(Durable(Arc::new(Mutex::new(Inner {
            path: Some(path.to_path_buf()),
            sections,
            ..Inner::default()
        }))))
    }

    /// Makes the state file at `path` with `entries` (the provisioning step); refuses if it
    /// exists.
    pub fn create(path: &Path, entries: &[(Section, Entry)]) -> Result<Durable, DurableError> {
        if path.exists() {
            return Err(DurableError::Exists {
                path: path.to_path_buf(),
            });
        }
        let d = Durable(Arc::new(Mutex::new(Inner {
            path: Some(path.to_path_buf()),
            ..Inner::default()
        })));
        for s in [Section::Server, Section::Ground] {
            let mine: Vec<Entry> = entries
                .iter()
                .filter(|(t, _)| *t == s)
                .map(|(_, e)| *e)
                .collect();
            if !mine.is_empty() {
                d.write(s, &mine).map_err(|source| DurableError::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
            }
        }
        Ok(d)
    }

    /// Whether it is a file (not memory).
    pub fn path(&self) -> Option<PathBuf> {
        lock(self).path.clone()
    }

    /// The entry `key` of `section`: (aux, value).
    pub fn lookup(&self, section: Section, key: u16) -> Option<(u8, u128)> {
        lock(self)
            .sections
            .get(&section)
            .and_then(|m| m.get(&key))
            .copied()
    }

    /// Every entry of `section` (for a boot: the library's `store::boot` looks them up).
    pub fn section(&self, section: Section) -> BTreeMap<u16, (u8, u128)> {
        lock(self)
            .sections
            .get(&section)
            .cloned()
            .unwrap_or_default()
    }

    /// Writes `entries` into `section` durably; on an error nothing changed (the caller
    /// must not confirm them to the library, and tries again later).
    pub fn write(&self, section: Section, entries: &[Entry]) -> std::io::Result<()> {
        if entries.is_empty() {
            return Ok(());
        }
        let mut inner = lock(self);
        let now = std::time::Instant::now();
        if inner.retry_at.is_some_and(|t| now < t) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::WouldBlock,
                "the last durable write failed: backing off",
            ));
        }
        let mut next = inner.sections.clone();
        let map = next.entry(section).or_default();
        for e in entries {
            if e.value >= VALUE_LIMIT {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("entry {:#06x}: a value of 96 bits at most", e.key),
                ));
            }
            map.insert(e.key, (e.aux, e.value));
        }
        if let Some(path) = inner.path.clone() {
            if let Err(e) = write_atomically(&path, &render(&next)) {
                inner.failed += 1;
                inner.backoff_ms = (inner.backoff_ms * 2).clamp(10, 1000);
                inner.retry_at = Some(now + std::time::Duration::from_millis(inner.backoff_ms));
                return Err(e);
            }
        }
        inner.retry_at = None;
        inner.backoff_ms = 0;
        inner.sections = next;
        Ok(())
    }

    /// Writes that failed so far.
    pub fn failed(&self) -> u64 {
        lock(self).failed
    }
}

/// The file's text: sorted, one entry a line, values in hex (no key, ever).
fn render(sections: &BTreeMap<Section, BTreeMap<u16, (u8, u128)>>) -> String {
    let mut doc = serde_json::Map::new();
    doc.insert("format".into(), json!(FORMAT));
    doc.insert(
        "what".into(),
        json!("SDLS counters, key fingerprints (not keys), FARM-1 progress and kept telecommand keys (mmic::node::server::store)"),
    );
    for (s, m) in sections {
        let list: Vec<Value> = m
            .iter()
            .map(|(k, (aux, v))| json!({"key": format!("{k:#06x}"), "aux": aux, "value": format!("{v:#x}")}))
            .collect();
        doc.insert(s.name().into(), Value::Array(list));
    }
    let mut text = serde_json::to_string_pretty(&Value::Object(doc)).unwrap_or_default();
    text.push('\n');
    text
}

type Sections = BTreeMap<Section, BTreeMap<u16, (u8, u128)>>;

fn parse(text: &str) -> Result<Sections, String> {
    let doc: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    if doc.get("format").and_then(Value::as_str) != Some(FORMAT) {
        return Err(format!("\"format\" is not {FORMAT:?}"));
    }
    let mut out = BTreeMap::new();
    for s in [Section::Server, Section::Ground] {
        let Some(list) = doc.get(s.name()) else {
            continue;
        };
        let list = list
            .as_array()
            .ok_or_else(|| format!("{:?} is not a list", s.name()))?;
        let map: &mut BTreeMap<u16, (u8, u128)> = out.entry(s).or_default();
        for (i, e) in list.iter().enumerate() {
            let hex = |field: &str| -> Result<u128, String> {
                let t = e
                    .get(field)
                    .and_then(Value::as_str)
                    .ok_or_else(|| format!("{} entry {i}: no {field}", s.name()))?;
                u128::from_str_radix(t.trim_start_matches("0x"), 16)
                    .map_err(|err| format!("{} entry {i}: {field} {t:?}: {err}", s.name()))
            };
            let key = u16::try_from(hex("key")?)
                .map_err(|_| format!("{} entry {i}: key beyond 16 bits", s.name()))?;
            let value = hex("value")?;
            if value >= VALUE_LIMIT {
                return Err(format!("{} entry {i}: value beyond 96 bits", s.name()));
            }
            let aux = e
                .get("aux")
                .and_then(Value::as_u64)
                .and_then(|a| u8::try_from(a).ok())
                .ok_or_else(|| format!("{} entry {i}: aux is not 0..=255", s.name()))?;
            if map.insert(key, (aux, value)).is_some() {
                return Err(format!("{} entry {i}: key {key:#06x} twice", s.name()));
            }
        }
    }
    Ok(out)
}

/// Writes `text` to `path` so that a crash at any instant leaves the old contents or the new:
/// a temporary file beside it, fsync, rename over, fsync of the directory.
pub fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let tmp = dir.join(format!(".{}.tmp", name.unwrap_or_default()));
    {
        let mut o = std::fs::OpenOptions::new();
        o.write(true).create(true).truncate(true);
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut o, 0o600);
        let mut f = o.open(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)?;
    std::fs::File::open(dir)?.sync_all()
}

/// The frame gateway the simulator's server board runs (the replay's type, so that a recorded
/// trace replays with the same sizes).
pub type FrameGateway = mmic_replay::ReplayFrameGateway;

/// Why a link could not start from its store.
#[derive(Debug, thiserror::Error)]
pub enum BootError {
    /// The store is not provisioned for these keys (the library's reason).
    #[error("robot {board}'s link: {why}")]
    Stopped {
        /// The robot.
        board: u8,
        /// Why.
        why: mmic::node::server::store::Stopped,
    },
    /// The library could not secure the link.
    #[error(transparent)]
    Secure(#[from] mmic::node::server::frames::SecureError),
    /// The robot could not be served.
    #[error("robot {0} could not be served by its gateway")]
    NotServed(u8),
    /// The store could not be written.
    #[error("the durable store: {0}")]
    Write(#[from] std::io::Error),
}

impl From<BootError> for std::io::Error {
    fn from(e: BootError) -> Self {
        match e {
            BootError::Write(e) => e,
            e => std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()),
        }
    }
}

/// Provisions a store in memory for robot `board`'s keys made for this run, both ends (the
/// keys die with the run, and so does the store).
pub fn provision_memory(
    d: &Durable,
    board: mmic::units::BoardNumber,
    keys: &(mmic::link::sdls::Key256, mmic::link::sdls::Key256),
) -> Result<(), BootError> {
    use mmic::node::server::store::{provision, End, Resume};
    for (end, section) in [
        (End::Server, Section::Server),
        (End::Ground, Section::Ground),
    ] {
        let entries = provision(end, board, &keys.0, &keys.1, Resume::FRESH).map_err(|why| {
            BootError::Stopped {
                board: board.get(),
                why,
            }
        })?;
        d.write(section, &entries)?;
    }
    Ok(())
}

/// Robot `board`'s server board as it starts, from what `d` kept: afresh, or after a restart
/// with its kept telecommand keys (decision `restart-server`), FARM-1's progress and, with
/// SDLS keys, its counters (decision `sdls-counters`). A store not provisioned for the keys
/// is refused: the link does not run, in clear or otherwise.
pub fn boot_gateway(
    config: mmic::node::server::gateway::Config,
    board: mmic::units::BoardNumber,
    d: &Durable,
    keys: Option<(mmic::link::sdls::Key256, mmic::link::sdls::Key256)>,
) -> Result<Box<FrameGateway>, BootError> {
    use mmic::node::server::store;
    let lookup = |k: u16| d.lookup(Section::Server, k);
    let boot = match &keys {
        Some((tc, tm)) => {
            store::boot(store::End::Server, board, tc, tm, lookup).map_err(|why| {
                BootError::Stopped {
                    board: board.get(),
                    why,
                }
            })?
        }
        None => store::boot_clear(board, lookup),
    };
    let mut g = Box::new(FrameGateway::new(mmic::node::server::frames::FrameConfig {
        gateway: config,
        ..Default::default()
    }));
    let added = match boot.kept {
        Some(k) => g.add_restarted(board, k),
        None => g.add(board),
    };
    if !added {
        return Err(BootError::NotServed(board.get()));
    }
    match keys {
        Some((tc, tm)) => g.secure(board, tc, tm, boot.stored)?,
        None => {
            if let Some(p) = boot.stored.progress {
                g.resume(board, p);
            }
        }
    }
    // The telecommands it had accepted and not yet sent to board A: each runs once.
    if !boot.queue.is_empty() && !g.restore_queue(board, &boot.queue) {
        return Err(BootError::NotServed(board.get()));
    }
    Ok(g)
}

/// Writes what the gateway asks to keep and confirms it once durable; false when the write
/// failed (nothing confirmed: the gateway holds back what needs it, and asks again).
pub fn persist_gateway(g: &mut FrameGateway, d: &Durable) -> bool {
    write_due(g, d).is_some()
}

/// [`persist_gateway`], telling how many entries were due (and written): none when the write
/// failed. With none due, the gateway asks nothing more until it is called again.
pub fn write_due(g: &mut FrameGateway, d: &Durable) -> Option<usize> {
    let due: heapless::Vec<Entry, 64> = g.durable_due();
    if due.is_empty() {
        return Some(0);
    }
    if d.write(Section::Server, &due).is_err() {
        return None;
    }
    for e in &due {
        g.durable_written(e);
    }
    Some(due.len())
}

/// The gateway's tick with what it asks kept written first and, when the tick held a
/// telecommand back until the store says it left the queue (write-ahead), written and ticked
/// again at once: the hand-over to board A follows its write in the same pass.
pub fn tick_gateway(
    g: &mut FrameGateway,
    d: &Durable,
    now: u32,
) -> heapless::Vec<(mmic::units::BoardNumber, mmic::wire::command::CommandRepr), 1> {
    persist_gateway(g, d);
    let visits = g.tick(now);
    if visits.is_empty() && !g.durable_due::<1>().is_empty() && persist_gateway(g, d) {
        return g.tick(now);
    }
    visits
}

/// Secures the ground's end of robot `board`'s link from what `d` kept of its counters.
pub fn boot_ground<const K: usize, const Q: usize, const N: usize>(
    gl: &mut mmic::node::ground::frames::GroundLink<K, Q, N>,
    board: mmic::units::BoardNumber,
    d: &Durable,
    keys: (mmic::link::sdls::Key256, mmic::link::sdls::Key256),
) -> Result<(), BootError> {
    use mmic::node::server::store;
    let boot = store::boot(store::End::Ground, board, &keys.0, &keys.1, |k| {
        d.lookup(Section::Ground, k)
    })
    .map_err(|why| BootError::Stopped {
        board: board.get(),
        why,
    })?;
    gl.secure(keys.0, keys.1, (boot.stored.tc, boot.stored.tm));
    Ok(())
}

/// The ground's due SDLS counters, written and confirmed; false when the write failed.
pub fn persist_ground<const K: usize, const Q: usize, const N: usize>(
    gl: &mut mmic::node::ground::frames::GroundLink<K, Q, N>,
    d: &Durable,
) -> bool {
    let due: Vec<Entry> = gl
        .due()
        .map(|(spi, value)| Entry {
            key: spi,
            aux: 0,
            value,
        })
        .collect();
    if due.is_empty() {
        return true;
    }
    if d.write(Section::Ground, &due).is_err() {
        return false;
    }
    for e in &due {
        gl.persisted(e.key, e.value);
    }
    true
}
