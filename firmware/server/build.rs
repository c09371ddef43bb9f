//! The server image's SDLS keys, at build time: from the directory named by
//! `MMIC_SDLS_KEY_DIR` (outside the tree), one file `spi-<SPI>.key` of 32 raw octets per
//! security association (sdls-plan.md: robot n's TC SA is SPI 0x100 + n, its TM SA 0x200 + n)
//! for each robot in `MMIC_ROBOTS` (comma-separated board numbers, default `1`). The keys are
//! copied into OUT_DIR (mode 0600) and included from there (`keys.rs`): they never enter the
//! tree, and the build fails, naming the file, when the variable is missing or a key is not
//! 32 octets. Nothing here prints a key.

use std::env;
use std::fs;
use std::io::Write;
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::exit;

/// Octets in an AES-256 key.
const KEY_LEN: usize = 32;

fn fail(msg: &str) -> ! {
    println!("cargo::error={msg}");
    exit(0)
}

fn main() {
    println!("cargo::rerun-if-env-changed=MMIC_SDLS_KEY_DIR");
    println!("cargo::rerun-if-env-changed=MMIC_ROBOTS");
    println!("cargo::rerun-if-changed=build.rs");
    let Some(dir) = env::var_os("MMIC_SDLS_KEY_DIR").map(PathBuf::from) else {
        fail(
            "MMIC_SDLS_KEY_DIR is not set: the server image needs its SDLS keys at build time, \
             a directory outside the tree holding spi-<SPI>.key files of 32 raw octets \
             (robot n: spi-<256+n>.key for TC, spi-<512+n>.key for TM; see firmware/README.md)",
        );
    };
    let robots = env::var("MMIC_ROBOTS").unwrap_or_else(|_| "1".into());
    let mut boards = Vec::new();
    for r in robots.split(',') {
        match r.trim().parse::<u8>() {
            Ok(n) if n > 0 && !boards.contains(&n) => boards.push(n),
            _ => fail(&format!(
                "MMIC_ROBOTS = {robots:?}: board numbers 1..=255, comma-separated, each once"
            )),
        }
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap_or_else(|| fail("no OUT_DIR")));
    let mut rs = String::new();
    rs += "/// The robots this image serves (build-time `MMIC_ROBOTS`).\n";
    rs += &format!("pub const ROBOTS: [u8; {}] = {boards:?};\n", boards.len());
    rs += "/// The SDLS keys, one per SA of each robot (build-time `MMIC_SDLS_KEY_DIR`).\n";
    rs += &format!(
        "pub static KEYS: [support::server::SdlsKey; {}] = [\n",
        2 * boards.len()
    );
    for n in &boards {
        for spi in [0x100 + u16::from(*n), 0x200 + u16::from(*n)] {
            let name = format!("spi-{spi}.key");
            copy_key(&dir.join(&name), &out.join(&name));
            rs += &format!(
                "    support::server::SdlsKey {{ spi: {spi}, key: *include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{name}\")) }},\n"
            );
        }
    }
    rs += "];\n";
    if let Err(e) = fs::write(out.join("keys.rs"), rs) {
        fail(&format!("writing keys.rs into OUT_DIR: {e}"));
    }
}

/// Checks the key file at `from` and copies it to `to` (mode 0600).
fn copy_key(from: &Path, to: &Path) {
    println!("cargo::rerun-if-changed={}", from.display());
    let key = fs::read(from).unwrap_or_else(|e| {
        fail(&format!(
            "{}: {e} (MMIC_SDLS_KEY_DIR must hold one key file per SA of each robot in MMIC_ROBOTS)",
            from.display()
        ))
    });
    if key.len() != KEY_LEN {
        fail(&format!(
            "{}: {} octets; an SDLS key file holds exactly {KEY_LEN} raw octets",
            from.display(),
            key.len()
        ));
    }
    if let Ok(m) = fs::metadata(from) {
        if m.permissions().mode() & 0o077 != 0 {
            println!(
                "cargo::warning={}: readable by others (mode {:o}); key files should be 0600",
                from.display(),
                m.permissions().mode() & 0o777
            );
        }
    }
    let _ = fs::remove_file(to);
    let written = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .open(to)
        .and_then(|mut f| f.write_all(&key));
    if let Err(e) = written {
        fail(&format!("{}: {e}", to.display()));
    }
}
