//! `mmic sdls`: the explicit provisioning step of a durable store (issue 38, decision
//! `sdls-store`), and the key files' reader every command shares.
//!
//! `mmic sdls provision --keys DIR --state FILE` makes the simulator's state file for the keys
//! of DIR: each robot's key fingerprints and first counters, for the server board's end and the
//! ground's. `mmic sdls image --keys DIR --keys-image K --counters-image C` makes the server
//! image's two flash partitions (`mmic_keys` with the keys, `mmic_ctr` with the provisioned
//! counter log), flashed with `espflash write-bin` (firmware/README.md, "Keys"). Both refuse
//! weak keys, an existing output (going back to fresh counters under used keys reuses IVs),
//! and an output inside the key directory. Nothing prints a key or a fingerprint.

use crate::error::CliError;
use crate::sim::durable::{Durable, Section};
use mmic::link::sdls::{mission, Key256, KEY_LEN};
use mmic::node::server::store::{self, keys, log, End, Resume};
use mmic::units::BoardNumber;
use std::io::Write;
use std::path::{Path, PathBuf};
use zeroize::Zeroizing;

/// The keys partition's size (firmware/server-ccsds/partitions.csv `mmic_keys`).
pub const KEYS_PARTITION: usize = 0x1000;
/// The counters partition's sector, and its size: two sectors (`mmic_ctr`).
pub const COUNTER_SECTOR: usize = 0x1000;

/// `mmic sdls`'s subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum SdlsCmd {
    /// Provision the simulator's durable state file for the keys of DIR (once per set of keys).
    Provision {
        /// The key directory: `spi-<SPI>.key`, 32 raw octets each.
        #[arg(long, value_name = "DIR")]
        keys: PathBuf,
        /// The state file to make (refused if it exists, or inside DIR).
        #[arg(long, value_name = "FILE")]
        state: PathBuf,
        /// The robots (comma-separated board numbers).
        #[arg(long, default_value = "1", value_delimiter = ',')]
        robots: Vec<u8>,
        #[command(flatten)]
        resume: ResumeArgs,
    },
    /// Make the server image's keys and counters partitions for the keys of DIR.
    Image {
        /// The key directory: `spi-<SPI>.key`, 32 raw octets each.
        #[arg(long, value_name = "DIR")]
        keys: PathBuf,
        /// The robots the server board serves (comma-separated board numbers).
        #[arg(long, default_value = "1", value_delimiter = ',')]
        robots: Vec<u8>,
        /// The `mmic_keys` partition image to write (4 KiB, mode 0600; it holds the keys).
        #[arg(long, value_name = "FILE")]
        keys_image: PathBuf,
        /// The `mmic_ctr` partition image to write (8 KiB: the counter log, provisioned).
        #[arg(long, value_name = "FILE")]
        counters_image: PathBuf,
        #[command(flatten)]
        resume: ResumeArgs,
    },
}

/// Where the counters start: fresh keys by default.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct ResumeArgs {
    /// The sending associations' first IV (a key used before: above every IV it was used
    /// with; decimal or 0x hex).
    #[arg(long, value_name = "IV", value_parser = parse_iv)]
    pub resume_tx: Option<u128>,
    /// The receiving associations' last IV accepted (a key used before: the highest the sender
    /// has used; decimal or 0x hex).
    #[arg(long, value_name = "IV", value_parser = parse_iv)]
    pub resume_rx: Option<u128>,
}

impl ResumeArgs {
    fn resume(&self) -> Resume {
        Resume {
            tx_from: self.resume_tx.unwrap_or(0),
            rx_after: self.resume_rx,
        }
    }
}

fn parse_iv(s: &str) -> Result<u128, String> {
    let v = match s.strip_prefix("0x") {
        Some(h) => u128::from_str_radix(h, 16),
        None => s.parse(),
    }
    .map_err(|e| format!("{s:?}: {e}"))?;
    if v < store::VALUE_LIMIT {
        Ok(v)
    } else {
        Err(format!("{s}: an IV is below 2^96"))
    }
}

/// Runs `mmic sdls`.
pub fn run(cmd: SdlsCmd, out: &mut dyn Write) -> Result<(), CliError> {
    match cmd {
        SdlsCmd::Provision {
            keys,
            state,
            robots,
            resume,
        } => provision(&keys, &state, &boards(&robots)?, resume.resume(), out),
        SdlsCmd::Image {
            keys,
            robots,
            keys_image,
            counters_image,
            resume,
        } => image(
            &keys,
            &boards(&robots)?,
            (&keys_image, &counters_image),
            resume.resume(),
            out,
        ),
    }
}

fn boards(robots: &[u8]) -> Result<Vec<BoardNumber>, CliError> {
    let mut out: Vec<BoardNumber> = Vec::new();
    for &r in robots {
        let b = BoardNumber::new(r)
            .map_err(|_| CliError::Usage(format!("--robots: {r} is no board number (1..=255)")))?;
        if out.contains(&b) {
            return Err(CliError::Usage(format!("--robots: {r} twice")));
        }
        out.push(b);
    }
    Ok(out)
}

/// Refuses an output inside the key directory (keys and what is made from them stay apart),
/// or one that exists.
pub fn outside_keys(keys: &Path, file: &Path, what: &str) -> Result<(), CliError> {
    let canon = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
    let dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if canon(dir).starts_with(canon(keys)) {
        return Err(CliError::Usage(format!(
            "{what} {}: inside the key directory {}: keep it apart from the keys",
            file.display(),
            keys.display()
        )));
    }
    Ok(())
}

fn provision(
    dir: &Path,
    state: &Path,
    robots: &[BoardNumber],
    resume: Resume,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    outside_keys(dir, state, "--state")?;
    let mut entries = Vec::new();
    for &b in robots {
        let (tc, tm) = read_keys(dir, b)?;
        for (end, section) in [
            (End::Server, Section::Server),
            (End::Ground, Section::Ground),
        ] {
            let e = store::provision(end, b, &tc, &tm, resume)
                .map_err(|e| CliError::Usage(format!("robot {}: {e}", b.get())))?;
            entries.extend(e.iter().map(|e| (section, *e)));
        }
    }
    Durable::create(state, &entries).map_err(|e| CliError::Usage(e.to_string()))?;
    writeln!(
        out,
        "provisioned {}: robots {}, server board and ground ends: key fingerprints (not keys) and first counters ({})",
        state.display(),
        list(robots),
        describe(resume)
    )
    .map_err(CliError::Output)
}

fn image(
    dir: &Path,
    robots: &[BoardNumber],
    (keys_image, counters_image): (&Path, &Path),
    resume: Resume,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    for (f, what) in [
        (keys_image, "--keys-image"),
        (counters_image, "--counters-image"),
    ] {
        outside_keys(dir, f, what)?;
        if f.exists() {
            return Err(CliError::Usage(format!(
                "{what} {}: exists: a partition image is made once per set of keys (remove it deliberately)",
                f.display()
            )));
        }
    }
    let mut all: Vec<(u16, Key256)> = Vec::new();
    let mut entries = Vec::new();
    for &b in robots {
        let (tc, tm) = read_keys(dir, b)?;
        let e = store::provision(End::Server, b, &tc, &tm, resume)
            .map_err(|e| CliError::Usage(format!("robot {}: {e}", b.get())))?;
        entries.extend(e);
        all.push((mission::tc_spi(b), tc));
        all.push((mission::tm_spi(b), tm));
    }
    let mut part = Zeroizing::new(vec![0xFFu8; KEYS_PARTITION]);
    let refs: Vec<(u16, &Key256)> = all.iter().map(|(s, k)| (*s, k)).collect();
    keys::emit(&refs, &mut part).map_err(|e| CliError::Usage(e.to_string()))?;
    let mut ctr = vec![0u8; 2 * COUNTER_SECTOR];
    log::image(&entries, COUNTER_SECTOR, &mut ctr).map_err(|e| CliError::Usage(e.to_string()))?;
    write_new(keys_image, &part)?;
    write_new(counters_image, &ctr)?;
    writeln!(
        out,
        "wrote {} (mmic_keys, {} keys, mode 0600) and {} (mmic_ctr, provisioned counters: {}) for robots {}",
        keys_image.display(),
        all.len(),
        counters_image.display(),
        describe(resume),
        list(robots)
    )
    .map_err(CliError::Output)
}

fn list(robots: &[BoardNumber]) -> String {
    robots
        .iter()
        .map(|b| b.get().to_string())
        .collect::<Vec<_>>()
        .join(",")
}

fn describe(r: Resume) -> String {
    let rx = r.rx_after.map_or("nothing accepted yet".to_string(), |v| {
        format!("accepted up to {v:#x}")
    });
    format!("sending from IV {:#x}, receiving: {rx}", r.tx_from)
}

/// Writes a new file, mode 0600, flushed to the disk.
fn write_new(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let mut o = std::fs::OpenOptions::new();
    o.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut o, 0o600);
    let w = |source| CliError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut f = o.open(path).map_err(w)?;
    f.write_all(bytes).map_err(w)?;
    f.sync_all().map_err(w)
}

/// Robot `board`'s SDLS keys from `dir` (`spi-<TC SPI>.key`, `spi-<TM SPI>.key`: 32 octets
/// each; robot 1's are `spi-257.key` and `spi-513.key`), each checked ([`Key256::check`]). The
/// file's octets are cleared from memory once read; an error names the file and the length
/// found, never the octets.
pub fn read_keys(dir: &Path, board: BoardNumber) -> Result<(Key256, Key256), CliError> {
    let read = |spi: u16| -> Result<Key256, CliError> {
        let path = dir.join(format!("spi-{spi}.key"));
        let bytes = Zeroizing::new(
            std::fs::read(&path)
                .map_err(|e| CliError::Usage(format!("--sdls-keys: {}: {e}", path.display())))?,
        );
        if bytes.len() != KEY_LEN {
            return Err(CliError::Usage(format!(
                "--sdls-keys: {}: {} octets, a key file holds exactly {KEY_LEN}",
                path.display(),
                bytes.len()
            )));
        }
        let key = Key256::from_slice(&bytes)
            .map_err(|e| CliError::Usage(format!("--sdls-keys: {}: {e}", path.display())))?;
        key.check()
            .map_err(|e| CliError::Usage(format!("--sdls-keys: {}: {e}", path.display())))?;
        Ok(key)
    };
    Ok((read(mission::tc_spi(board))?, read(mission::tm_spi(board))?))
}
