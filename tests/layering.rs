//! The library reads bottom-up: every module of `src/` uses only modules listed before it in
//! [`ORDER`] (the table of `src/lib.rs`'s crate docs), so there is no import circle and no
//! arrow that runs back up. This test reads each `src/**.rs` file's `crate::…` and `super::…`
//! paths (the `use` lines and the paths written out in code, serde attributes included;
//! comments are not read) and fails on the first module that reaches up.
//!
//! A new module must be added to [`ORDER`]; the test refuses a file whose top-level module the
//! table does not name.

use std::path::{Path, PathBuf};

/// The reading order, ground first: each row is a layer of `src/lib.rs`'s table, its modules
/// in the order they may use each other (a module may use those of lower rows, and those before
/// it in its own row). The one place the order is written down.
const ORDER: &[(&str, &[&str])] = &[
    ("ground", &["units", "wire_enum"]),
    (
        "vocabulary",
        &[
            "mode", "faults", "refusal", "restart", "pose", "bolter", "command",
        ],
    ),
    ("behaviour", &["sensors", "control", "motion", "safety"]),
    ("wire", &["wire"]),
    ("ccsds", &["ccsds", "cfdp"]),
    ("link", &["link"]),
    ("pus", &["pus"]),
    ("node", &["node"]),
    ("checks", &["arbitrary"]),
];

/// The module's place in the reading order, and its layer's name.
fn rank(module: &str) -> Option<(usize, &'static str)> {
    ORDER
        .iter()
        .flat_map(|(layer, mods)| mods.iter().map(move |m| (*layer, *m)))
        .enumerate()
        .find(|(_, (_, m))| *m == module)
        .map(|(i, (layer, _))| (i, layer))
}

/// `text` without its `//` comments (doc comments included: an intra-doc link is no import).
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = ' ';
        let mut cut = line.len();
        for (i, c) in line.char_indices() {
            if c == '"' && prev != '\\' {
                in_str = !in_str;
            }
            if !in_str && c == '/' && prev == '/' {
                cut = i - 1;
                break;
            }
            prev = c;
        }
        out.push_str(&line[..cut]);
        out.push('\n');
    }
    out
}

/// The crate's top-level modules that `text`, the source of module `path` (e.g. `["wire",
/// "opcode"]`), names through `crate::`, `$crate::` or `super::` paths, with `use` groups
/// (`crate::{a, b::c}`) opened.
fn used_modules(path: &[String], text: &str) -> Vec<String> {
    let text = strip_comments(text);
    let b = text.as_bytes();
    let mut found = Vec::new();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        let preceded = i > 0 && (ident(b[i - 1]) || b[i - 1] == b':');
        let (base, after, via_super): (Vec<String>, usize, bool) =
            if !preceded && rest.starts_with(b"crate::") {
                (Vec::new(), i + "crate::".len(), false)
            } else if !preceded && rest.starts_with(b"super::") {
                let mut base = path.to_vec();
                let mut j = i;
                while b[j..].starts_with(b"super::") {
                    base.pop();
                    j += "super::".len();
                }
                (base, j, true)
            } else {
                i += 1;
                continue;
            };
        if !base.is_empty() {
            // Still inside the module: not an import of another one.
            i = after;
            continue;
        }
        let start = found.len();
        if b.get(after) == Some(&b'{') {
            // A group: each top-level item of it.
            let mut depth = 0;
            let mut item_start = true;
            for (k, &c) in b[after..].iter().enumerate() {
                match c {
                    b'{' => {
                        depth += 1;
                        item_start = depth == 1;
                    }
                    b'}' => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    b',' if depth == 1 => item_start = true,
                    c if item_start && depth == 1 && ident(c) => {
                        let s = &text[after + k..];
                        let end = s.find(|c: char| !c.is_ascii_alphanumeric() && c != '_');
                        found.push(s[..end.unwrap_or(s.len())].to_string());
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            let s = &text[after..];
            let end = s.find(|c: char| !c.is_ascii_alphanumeric() && c != '_');
            found.push(s[..end.unwrap_or(s.len())].to_string());
        }
        if via_super {
            // `super::` in an inline module (`mod tests`) names its file's items: only a
            // name of the table is taken for a module reached through the crate root.
            let mut k = start;
            while k < found.len() {
                if rank(&found[k]).is_none() {
                    found.remove(k);
                } else {
                    k += 1;
                }
            }
        }
        i = after;
    }
    found.retain(|m| m != "self" && !m.is_empty() && Some(m) != path.first());
    found.sort();
    found.dedup();
    found
}

/// The module path of a file under `src/`: `src/wire/opcode/mod.rs` is `["wire", "opcode"]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("under src/");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable directory") {
        let p = entry.expect("directory entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Every arrow that runs back up, as "file: module (layer) uses module (layer)"; and every
/// module the table does not name.
fn violations(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut bad = Vec::new();
    for file in files {
        let path = module_path(src, &file);
        let Some(top) = path.first().filter(|t| *t != "lib") else {
            continue; // lib.rs: the root declares every module.
        };
        let Some((own, own_layer)) = rank(top) else {
            bad.push(format!(
                "{}: module `{top}` is not in ORDER",
                file.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(&file).expect("readable source");
        for used in used_modules(&path, &text) {
            match rank(&used) {
                Some((r, layer)) if r > own => bad.push(format!(
                    "{}: `{top}` ({own_layer}) uses `{used}` ({layer}), listed above it",
                    file.display()
                )),
                Some(_) => {}
                None => bad.push(format!(
                    "{}: `{top}` uses `crate::{used}`, which ORDER does not name",
                    file.display()
                )),
            }
        }
    }
    bad
}

#[test]
fn no_module_uses_one_listed_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let bad = violations(&src);
    assert!(
        bad.is_empty(),
        "arrows that run back up:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_table_names_every_top_level_module_once() {
    let mut all: Vec<&str> = ORDER.iter().flat_map(|(_, m)| m.iter().copied()).collect();
    let n = all.len();
    all.sort_unstable();
    all.dedup();
    assert_eq!(all.len(), n, "a module listed twice");
    let lib = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs"))
        .expect("src/lib.rs");
    for m in all {
        assert!(
            lib.contains(&format!("mod {m};")),
            "`{m}` is in ORDER but src/lib.rs declares no such module"
        );
        assert!(
            lib.contains(&format!("`{m}`")),
            "`{m}` is in ORDER but missing from src/lib.rs's layer table"
        );
    }
}

/// The reader itself: a planted upward import in each of the forms it must see is found, and
/// comments, the module's own paths and lower layers are not.
#[test]
fn the_reader_sees_each_form_of_import() {
    let at = |p: &[&str]| p.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let uses = |p: &[&str], t: &str| used_modules(&at(p), t);
    assert_eq!(uses(&["units"], "use crate::wire::X;"), ["wire"]);
    assert_eq!(
        uses(&["command"], "use crate::{mode::Mode, pus::{a, b}};"),
        ["mode", "pus"]
    );
    assert_eq!(uses(&["refusal"], "fn f(e: &crate::wire::E) {}"), ["wire"]);
    assert_eq!(uses(&["refusal"], "use super::node::X;"), ["node"]);
    assert_eq!(
        uses(&["units"], "use super::{Number, Side};"),
        Vec::<String>::new()
    );
    assert_eq!(
        uses(&["bolter", "side"], "use super::super::wire::X;"),
        ["wire"]
    );
    assert_eq!(
        uses(&["bolter", "side"], "use super::BolterAux;"),
        Vec::<String>::new()
    );
    assert_eq!(
        uses(&["units"], "#[serde(try_from = \"crate::ccsds::N\")]"),
        ["ccsds"]
    );
    assert_eq!(uses(&["units"], "$crate::pus::f()"), ["pus"]);
    assert_eq!(
        uses(
            &["units"],
            "/// see [`crate::wire`]\n// crate::pus\nfn f() {}"
        ),
        Vec::<String>::new()
    );
    assert_eq!(
        uses(&["wire", "x"], "use crate::wire::y;"),
        Vec::<String>::new()
    );
    assert!(rank("units").unwrap().0 < rank("wire").unwrap().0);
}
