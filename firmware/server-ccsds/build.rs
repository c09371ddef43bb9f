//! The robots the server image serves, at build time: `MMIC_ROBOTS` (comma-separated board
//! numbers 1..=255, each once; default `1`), written into OUT_DIR as `robots.rs`.
//!
//! No key goes in at build time: the image reads its SDLS keys from the `mmic_keys` partition,
//! flashed apart from it (firmware/README.md, "Keys"). `MMIC_SDLS_KEY_DIR`, which once named the
//! keys to build in, is refused, so that nobody believes the keys went in.

use std::env;
use std::fs;
use std::path::PathBuf;
use std::process::exit;

fn fail(msg: &str) -> ! {
    println!("cargo::error={msg}");
    exit(0)
}

fn main() {
    println!("cargo::rerun-if-env-changed=MMIC_SDLS_KEY_DIR");
    println!("cargo::rerun-if-env-changed=MMIC_ROBOTS");
    println!("cargo::rerun-if-changed=build.rs");
    if env::var_os("MMIC_SDLS_KEY_DIR").is_some() {
        fail(
            "MMIC_SDLS_KEY_DIR is set, but the server image takes no key at build time: it reads \
             its SDLS keys from the mmic_keys flash partition, written apart from the image \
             (`mmic sdls image`, then `espflash write-bin`: firmware/README.md, \"Keys\"). \
             Unset it.",
        );
    }
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
    if boards.len() > 8 {
        fail(&format!(
            "MMIC_ROBOTS = {robots:?}: at most 8 robots (the keys partition holds 16 keys)"
        ));
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap_or_else(|| fail("no OUT_DIR")));
    let rs = format!(
        "/// The robots this image serves (build-time `MMIC_ROBOTS`).\n\
         pub const ROBOTS: [u8; {}] = {boards:?};\n",
        boards.len()
    );
    if let Err(e) = fs::write(out.join("robots.rs"), rs) {
        fail(&format!("writing robots.rs into OUT_DIR: {e}"));
    }
}
