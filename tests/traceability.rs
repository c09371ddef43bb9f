//! Two-way traceability between the requirements, the code and the tests (issue 41).
//!
//! The requirements are the paper's (`spec/requirements/*.toml`: its statements `P<s>.<n>` and
//! the rows `T<n>/<key>` of its Tables 1-8, keyed as their `spec/` transcriptions key them), the
//! supported items of the CCSDS conformance proformas (`spec/ccsds/pics/*.toml`, items with
//! `supported = "Y"`) and of the PUS tailoring (`spec/ccsds/pus-tailoring.toml`), when those
//! files exist. Code and tests cite them with a plain comment line, `// req: ID, ID`, right
//! above the item (attributes and doc comments may sit between); `T5/*` cites every row of
//! Table 5, `D:<id>` a decision of `spec/decisions.toml`. A `// req:` line among a file's
//! header comments, followed by a blank line, cites for the whole module.
//!
//! The generator writes `docs/evidence/traceability.md` (`MMIC_REGENERATE=1 cargo test -p mmic
//! --test traceability`) and fails when an implemented requirement has no test citing it, when
//! an annotation cites an unknown ID or annotates nothing, when the paper's table rows are not
//! exactly the rows of `spec/`, or when the page is stale. Our own text scan rather than duvet:
//! duvet wants a `cargo install` in CI and quotes the specification, which cannot be committed.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[path = "traceability/page.rs"]
mod page;
#[path = "traceability/scan.rs"]
mod scan;
#[path = "traceability/sources.rs"]
mod sources;

use scan::{Scan, Target};
use sources::{Req, Status};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Everything the checks and the page need, read once per test.
struct World {
    reqs: Vec<Req>,
    known: BTreeSet<String>,
    scan: Scan,
}

fn world() -> World {
    let root = root();
    let reqs = sources::requirements(&root);
    let mut known: BTreeSet<String> = reqs.iter().map(|r| r.id.clone()).collect();
    known.extend(sources::other_known_ids(&root));
    let scan = scan::scan_tree(&root, &["src", "tests", "spec/check", "proofs", "host"]);
    World { reqs, known, scan }
}

/// Whether `cited` (an ID or a `prefix/*` wildcard) names `id`.
fn cites(cited: &str, id: &str) -> bool {
    match cited.strip_suffix('*') {
        Some(prefix) => id.starts_with(prefix),
        None => cited == id,
    }
}

/// The tests and the code items citing each requirement, by requirement ID.
fn citations(w: &World) -> BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)> {
    let mut by_req: BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)> = BTreeMap::new();
    for r in &w.reqs {
        by_req.entry(r.id.clone()).or_default();
    }
    for a in &w.scan.annotations {
        let (who, is_test) = match &a.target {
            Target::Module => (a.file.clone(), false),
            Target::Item { name, test, .. } => (format!("{}::{name}", a.file), *test),
        };
        for cited in &a.ids {
            for r in w.reqs.iter().filter(|r| cites(cited, &r.id)) {
                let entry = by_req.entry(r.id.clone()).or_default();
                if is_test { &mut entry.1 } else { &mut entry.0 }.insert(who.clone());
            }
        }
    }
    by_req
}

#[test]
fn every_implemented_requirement_is_cited_by_a_test() {
    let w = world();
    let by_req = citations(&w);
    let untested: Vec<&str> = w
        .reqs
        .iter()
        .filter(|r| r.status == Status::Implemented)
        .filter(|r| by_req.get(&r.id).is_none_or(|(_, tests)| tests.is_empty()))
        .map(|r| r.id.as_str())
        .collect();
    assert!(
        untested.is_empty(),
        "{} implemented requirements no test cites (add `// req: ID` above a test that checks \
         it, or say in its status why it is not implemented): {untested:?}",
        untested.len()
    );
}

#[test]
fn every_annotation_cites_known_ids_and_annotates_an_item() {
    let w = world();
    let mut bad = Vec::new();
    for a in &w.scan.annotations {
        for id in &a.ids {
            let known = match id.strip_suffix('*') {
                Some(prefix) => w.known.iter().any(|k| k.starts_with(prefix)),
                None => w.known.contains(id),
            };
            if !known {
                bad.push(format!("{}:{}: unknown ID `{id}`", a.file, a.line));
            }
        }
        if a.ids.is_empty() {
            bad.push(format!(
                "{}:{}: an annotation citing nothing",
                a.file, a.line
            ));
        }
    }
    bad.extend(w.scan.dangling.iter().cloned());
    assert!(bad.is_empty(), "bad annotations:\n{}", bad.join("\n"));
}

#[test]
fn the_requirements_are_well_formed_and_the_table_rows_are_the_spec_rows() {
    let root = root();
    let reqs = sources::requirements(&root);
    let mut problems = sources::check_requirements(&reqs);
    for (table, rows) in sources::table_rows(&root) {
        let prefix = format!("T{table}/");
        let listed: BTreeSet<String> = reqs
            .iter()
            .filter_map(|r| r.id.strip_prefix(&prefix).map(str::to_string))
            .collect();
        if listed != rows {
            problems.push(format!(
                "Table {table}: spec/ has rows {:?} that paper.toml lacks, paper.toml {:?} that \
                 spec/ lacks",
                rows.difference(&listed).collect::<Vec<_>>(),
                listed.difference(&rows).collect::<Vec<_>>()
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_traceability_page_is_fresh() {
    let w = world();
    let text = page::render(&w.reqs, &citations(&w), &w.scan);
    let path: &Path = &root().join("docs/evidence/traceability.md");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write docs/evidence/traceability.md");
    }
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        on_disk == text,
        "docs/evidence/traceability.md is stale: MMIC_REGENERATE=1 cargo test -p mmic --test \
         traceability"
    );
}

/// The scanner itself: module and item annotations, wildcards, tests and what cites nothing.
#[test]
fn the_scanner_reads_module_item_and_test_annotations() {
    let c = "//";
    let text = format!(
        "//! Docs.\n{c} req: P6.1\n\nuse x;\n\n{c} req: T5/*, D:units\n#[test]\n#[ignore = \"r\"]\n\
         fn cites() {{}}\n\n#[test]\nfn cites_none() {{}}\n\n{c} req: P7.2\npub struct Item;\n\
         pub fn bare() {{}}\n{c} req: P7.3\n\nlet x = 1;\n"
    );
    let s = scan::scan_text("src/x.rs", &text);
    let found: Vec<(Vec<String>, Target)> = s
        .annotations
        .iter()
        .map(|a| (a.ids.clone(), a.target.clone()))
        .collect();
    let item = |kind: &str, name: &str, test| Target::Item {
        kind: kind.to_string(),
        name: name.to_string(),
        test,
    };
    let ids = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(
        found,
        vec![
            (ids(&["P6.1"]), Target::Module),
            (ids(&["T5/*", "D:units"]), item("fn", "cites", true)),
            (ids(&["P7.2"]), item("struct", "Item", false)),
        ]
    );
    assert_eq!(
        s.tests.iter().map(|t| t.name.as_str()).collect::<Vec<_>>(),
        ["cites", "cites_none"]
    );
    assert_eq!(
        s.public.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
        ["Item", "bare"]
    );
    assert_eq!(
        s.dangling.len(),
        1,
        "the last annotation annotates nothing: {:?}",
        s.dangling
    );
    assert!(cites("T5/*", "T5/a") && !cites("T5/*", "T6/1") && cites("P7.2", "P7.2"));
}
