//! Writes the seed corpus of every fuzz target into `fuzz/tests/__fuzz__/<target>/corpus/`.
//!
//! `cargo run -p mmic-fuzz --bin mmic-fuzz-seeds` (from anywhere in the workspace). Files the
//! generator does not produce are left alone; `tests/seeds.rs` checks that the committed
//! corpus holds exactly the generated files.

use std::path::Path;

fn main() -> std::io::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/__fuzz__");
    let seeds = mmic_fuzz::seeds();
    for s in &seeds {
        let dir = root.join(s.target).join("corpus");
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join(&s.name), &s.bytes)?;
    }
    println!("wrote {} seed files under {}", seeds.len(), root.display());
    Ok(())
}
