//! The Protocol Implementation Conformance Statements (spec/ccsds/pics/<book>.toml) and the
//! PUS-C tailoring (spec/ccsds/pus-tailoring.toml) held to the code and the tests: every item
//! complete, every supported item's code present and cited by a test's `// req: <book>/<item>`
//! line (in src/'s test modules, tests/ or proofs/), every cited ID one of the files', and the
//! review pages spec/pages/pics-<book>.md and spec/pages/pus-tailoring.md written from them
//! (stale pages fail; `MMIC_REGENERATE=1 cargo test -p mmic --test library ccsds::pics` rewrites them).

use super::repo;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a status may be: mandatory, optional, conditional (C, C1, C:x), excluded, not applicable.
fn status_ok(s: &str) -> bool {
    matches!(s, "M" | "O" | "X" | "N/A") || s.starts_with('C')
}

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One conformance file: its path (from the root), its header table and its items.
struct Statement {
    path: String,
    id: String,
    header: toml::Table,
    items: Vec<toml::Table>,
}

/// The five books' statements, in file-name order, then the PUS tailoring.
fn statements() -> Vec<Statement> {
    let dir = root().join("spec/ccsds/pics");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("spec/ccsds/pics")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut out: Vec<Statement> = files
        .iter()
        .map(|p| {
            let rel = format!(
                "spec/ccsds/pics/{}",
                p.file_name().unwrap().to_string_lossy()
            );
            read(&rel, "book")
        })
        .collect();
    out.push(read("spec/ccsds/pus-tailoring.toml", "standard"));
    out
}

/// A statement file: `head` names its header table (`book` or `standard`).
fn read(rel: &str, head: &str) -> Statement {
    let t: toml::Table = toml::from_str(&repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let header = t[head]
        .as_table()
        .unwrap_or_else(|| panic!("{rel}: no [{head}]"))
        .clone();
    let items = t["item"]
        .as_array()
        .unwrap_or_else(|| panic!("{rel}: no [[item]]"))
        .iter()
        .map(|i| i.as_table().expect("an item is a table").clone())
        .collect();
    let id = header["id"].as_str().expect("an id").to_string();
    Statement {
        path: rel.to_string(),
        id,
        header,
        items,
    }
}

/// A string field of an item, or "".
fn field<'a>(t: &'a toml::Table, k: &str) -> &'a str {
    t.get(k).and_then(|v| v.as_str()).unwrap_or("")
}

/// The requirement ID an item is cited by: `<book>/<item>`, or the PUS entry's own `PUS/...`.
fn req_id(s: &Statement, item: &toml::Table) -> String {
    let id = field(item, "id");
    if id.starts_with("PUS/") {
        id.to_string()
    } else {
        format!("{}/{id}", s.id)
    }
}

/// The `code` paths of an item.
fn code(item: &toml::Table) -> Vec<&str> {
    item.get("code")
        .and_then(|v| v.as_array())
        .map(|a| a.iter().filter_map(|c| c.as_str()).collect())
        .unwrap_or_default()
}

#[test]
fn every_item_is_complete_and_its_code_exists() {
    let mut bad = Vec::new();
    for s in statements() {
        let book = s.path.starts_with("spec/ccsds/pics/");
        if book {
            let stem = Path::new(&s.path)
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .to_string();
            assert_eq!(s.id, stem, "{}: the book id is the file's name", s.path);
            for k in ["title", "annex", "source"] {
                assert!(!field(&s.header, k).is_empty(), "{}: [book] {k}", s.path);
            }
            let numbering = field(&s.header, "numbering");
            assert!(
                matches!(numbering, "book" | "ours" | "transcribed"),
                "{}: numbering {numbering:?}",
                s.path
            );
            let count = s
                .header
                .get("items_in_book")
                .or_else(|| s.header.get("items_in_source"));
            if let Some(n) = count.and_then(|v| v.as_integer()) {
                assert_eq!(s.items.len() as i64, n, "{}: the item count", s.path);
            }
        }
        let mut seen = std::collections::BTreeSet::new();
        for item in &s.items {
            let id = field(item, "id");
            let at = format!("{} {id}", s.path);
            assert!(
                !id.is_empty() && seen.insert(id.to_string()),
                "{at}: an id, once"
            );
            assert!(!field(item, "clause").is_empty(), "{at}: clause");
            assert!(
                item.get("checked").is_some_and(|v| v.is_bool()),
                "{at}: checked"
            );
            if book {
                assert!(!field(item, "feature").is_empty(), "{at}: feature");
                assert!(status_ok(field(item, "status")), "{at}: status");
            } else {
                assert!(!field(item, "name").is_empty(), "{at}: name");
            }
            match field(item, "supported") {
                "Y" => {
                    if code(item).is_empty() {
                        bad.push(format!("{at}: Y without code"));
                    }
                    for c in code(item) {
                        if !root().join(c).is_file() {
                            bad.push(format!("{at}: {c} does not exist"));
                        }
                    }
                }
                "N" | "N/A" => {
                    if field(item, "why").is_empty() {
                        bad.push(format!("{at}: N or N/A without why"));
                    }
                }
                other => bad.push(format!("{at}: supported {other:?}")),
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// Every `// req:` line of the tree's tests: each ID to the tests citing it ("file fn").
fn citations() -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for dir in ["src", "tests", "proofs"] {
        let mut files = Vec::new();
        rust_files(&root().join(dir), &mut files);
        for f in files {
            let rel = f
                .strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let text = std::fs::read_to_string(&f).unwrap();
            for (ids, test) in annotations(&text, dir == "src") {
                for id in ids {
                    out.entry(id).or_default().push(format!("{rel} {test}"));
                }
            }
        }
    }
    out
}

/// The `.rs` files under `dir`, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = rd.map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if !p.ends_with("target") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The annotations of one file: each `// req: A, B` line's IDs and the item it stands above
/// (the next `fn`'s name; "(module)" when it heads the file). In src/ only what follows the
/// file's `#[cfg(test)]` counts: code there is not a test.
fn annotations(text: &str, src: bool) -> Vec<(Vec<String>, String)> {
    let lines: Vec<&str> = text.lines().collect();
    let start = if src {
        match lines
            .iter()
            .position(|l| l.trim_start().starts_with("#[cfg(test)]"))
        {
            Some(i) => i,
            None => return Vec::new(),
        }
    } else {
        0
    };
    let mut out = Vec::new();
    let mut in_header = !src;
    for (i, line) in lines.iter().enumerate().skip(start) {
        let t = line.trim_start();
        let comment = t.starts_with("//") || t.is_empty();
        let req = t.strip_prefix("//").map(str::trim_start);
        if let Some(list) = req.and_then(|rest| rest.strip_prefix("req:")) {
            let ids = list
                .split(',')
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty());
            let target = if in_header {
                "(module)".to_string()
            } else {
                next_fn(&lines[i + 1..]).unwrap_or_else(|| "(none)".to_string())
            };
            out.push((ids.collect(), target));
        }
        if !comment {
            in_header = false;
        }
    }
    out
}

/// The name of the first `fn` in `lines`.
fn next_fn(lines: &[&str]) -> Option<String> {
    lines.iter().find_map(|l| {
        let i = l.find("fn ")?;
        let before = l[..i].chars().last();
        if before.is_some_and(|c| !c.is_whitespace()) {
            return None;
        }
        let name: String = l[i + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        (!name.is_empty()).then_some(name)
    })
}

#[test]
fn every_supported_item_is_cited_by_a_test_and_every_citation_exists() {
    let cites = citations();
    let mut missing = Vec::new();
    let mut known = std::collections::BTreeSet::new();
    let mut books = Vec::new();
    for s in statements() {
        books.push(format!("{}/", s.id));
        for item in &s.items {
            let id = req_id(&s, item);
            if field(item, "supported") == "Y" && !cites.contains_key(&id) {
                let flagged = item.get("tests_missing").and_then(|v| v.as_bool()) == Some(true);
                missing.push(format!(
                    "{id}{}",
                    if flagged { " (tests_missing)" } else { "" }
                ));
            }
            known.insert(id);
        }
    }
    assert!(
        missing.is_empty(),
        "supported, but no test says `// req:` for:\n{}",
        missing.join("\n")
    );
    let ours =
        |id: &str| id.starts_with("PUS/") || books.iter().any(|b| id.starts_with(b.as_str()));
    let unknown: Vec<String> = cites
        .iter()
        .filter(|(id, _)| ours(id) && !known.contains(*id))
        .map(|(id, at)| format!("{id} ({})", at.join("; ")))
        .collect();
    assert!(
        unknown.is_empty(),
        "cited, but in no statement:\n{}",
        unknown.join("\n")
    );
}

/// A table cell: no pipe or newline breaks the row.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// The counts of a page: items by status (by direction for the PUS tailoring), by support,
/// and the support of each status.
fn counts(s: &Statement, book: bool) -> String {
    let class = |item: &toml::Table| -> String {
        let k = if book {
            field(item, "status")
        } else {
            field(item, "direction")
        };
        let k = if book && k.starts_with('C') { "C" } else { k };
        if k.is_empty() {
            "service or capability".to_string()
        } else {
            k.to_string()
        }
    };
    let mut by_class: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    let mut by_support: BTreeMap<String, usize> = BTreeMap::new();
    for item in &s.items {
        let sup = field(item, "supported").to_string();
        *by_class
            .entry(class(item))
            .or_default()
            .entry(sup.clone())
            .or_default() += 1;
        *by_support.entry(sup).or_default() += 1;
    }
    let list = |m: &BTreeMap<String, usize>| {
        m.iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let checked = s
        .items
        .iter()
        .filter(|i| i["checked"].as_bool() == Some(true))
        .count();
    let mut out = format!(
        "{} items; supported: {}; checked against the {}'s text: {checked}.\n\n",
        s.items.len(),
        list(&by_support),
        if book { "book" } else { "standard" }
    );
    out += &format!(
        "| {} | items | supported |\n|---|---|---|\n",
        if book { "status" } else { "direction" }
    );
    for (k, m) in &by_class {
        out += &format!("| {k} | {} | {} |\n", m.values().sum::<usize>(), list(m));
    }
    out
}

/// The review page of one statement.
fn page(s: &Statement, cites: &BTreeMap<String, Vec<String>>) -> String {
    let book = s.path.starts_with("spec/ccsds/pics/");
    let mut out = format!(
        "# {} {}\n\n<!-- generated by tests/ccsds/pics.rs from {}; regenerate: \
         MMIC_REGENERATE=1 cargo test -p mmic --test library ccsds::pics -->\n\n",
        if book {
            "PICS of CCSDS"
        } else {
            "PUS-C tailoring,"
        },
        s.id,
        s.path
    );
    out += &format!("{}.\n\n", field(&s.header, "title"));
    out += &format!("Source: {}\n\n", field(&s.header, "source"));
    if book {
        out += &format!("Numbering: {}.", field(&s.header, "numbering"));
        if let Some(n) = s.header.get("note").and_then(|v| v.as_str()) {
            out += &format!(" {}.", n.trim_end_matches('.'));
        }
        out += "\n\n";
    }
    out += &counts(s, book);
    out += &format!(
        "\n| item | clause | feature | {} |",
        if book { "status" } else { "direction" }
    );
    out += " value | supported | code or why | tests citing it |\n";
    out += "|---|---|---|---|---|---|---|---|\n";
    for item in &s.items {
        let id = req_id(s, item);
        let feature = if book {
            field(item, "feature")
        } else {
            field(item, "name")
        };
        let status = if book {
            field(item, "status")
        } else {
            field(item, "direction")
        };
        let code_or_why = if field(item, "supported") == "Y" {
            code(item)
                .iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", ")
        } else {
            cell(field(item, "why"))
        };
        let tests = cites.get(&id).map(|t| t.join("<br>")).unwrap_or_default();
        out += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            cell(field(item, "id")),
            cell(field(item, "clause")),
            cell(feature),
            status,
            cell(field(item, "value")),
            field(item, "supported"),
            code_or_why,
            cell(&tests)
        );
    }
    out
}

#[test]
fn the_pics_pages_are_fresh() {
    let cites = citations();
    let mut stale = Vec::new();
    for s in statements() {
        let name = if s.path.starts_with("spec/ccsds/pics/") {
            format!("spec/pages/pics-{}.md", s.id)
        } else {
            "spec/pages/pus-tailoring.md".to_string()
        };
        let text = page(&s, &cites);
        let path = root().join(&name);
        if std::env::var_os("MMIC_REGENERATE").is_some() {
            std::fs::write(&path, &text).expect("write the page");
        }
        if std::fs::read_to_string(&path).unwrap_or_default() != text {
            stale.push(name);
        }
    }
    assert!(
        stale.is_empty(),
        "stale: {} (MMIC_REGENERATE=1 cargo test -p mmic --test library ccsds::pics)",
        stale.join(", ")
    );
}

#[test]
fn the_annotation_reader_takes_the_next_fn_and_skips_src_outside_tests() {
    let text = "//! doc\n// req: A/1\nuse x;\n// req: A/2, PUS/ST[8].1\n#[test]\nfn one() {}\n";
    let got = annotations(text, false);
    assert_eq!(got[0], (vec!["A/1".to_string()], "(module)".to_string()));
    assert_eq!(
        got[1],
        (
            vec!["A/2".to_string(), "PUS/ST[8].1".to_string()],
            "one".to_string()
        )
    );
    assert!(
        annotations(text, true).is_empty(),
        "src/ without #[cfg(test)]"
    );
    let src = "fn shipped() {}\n// req: A/3\n#[cfg(test)]\nmod tests {\n    // req: A/4\n    #[test]\n    fn two() {}\n}\n";
    let got = annotations(src, true);
    assert_eq!(got, vec![(vec!["A/4".to_string()], "two".to_string())]);
}
