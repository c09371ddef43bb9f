//! `docs/evidence/traceability.md`: counts, the matrix, and the reverse lists.

use super::scan::{Scan, Target};
use super::sources::{Req, Status};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

type Citations = BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)>;

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn list(items: &BTreeSet<String>) -> String {
    if items.is_empty() {
        return "—".to_string();
    }
    items
        .iter()
        .map(|i| format!("`{i}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The groups of the counts table, in order: the paper's statements, its table rows, then each
/// other source.
fn group(r: &Req) -> String {
    match (r.source.as_str(), r.kind.as_str()) {
        ("paper", "statement") => "paper: statements (Sections 2-8)".to_string(),
        ("paper", "table-row") => "paper: table rows (Tables 1-8)".to_string(),
        (source, _) => source.to_string(),
    }
}

fn counts(page: &mut String, reqs: &[Req], by_req: &Citations) {
    page.push_str(
        "## Counts\n\n| source | requirements | implemented | implemented and cited by ≥1 test | \
         not implemented | informative |\n|---|---|---|---|---|---|\n",
    );
    // In the order the sources come: the paper first.
    let mut groups: Vec<(String, [usize; 5])> = Vec::new();
    for r in reqs {
        let name = group(r);
        if groups.last().is_none_or(|(last, _)| *last != name) {
            groups.push((name, [0; 5]));
        }
        let Some((_, g)) = groups.last_mut() else {
            continue;
        };
        let tested = by_req.get(&r.id).is_some_and(|(_, t)| !t.is_empty());
        g[0] += 1;
        g[1] += usize::from(r.status == Status::Implemented);
        g[2] += usize::from(r.status == Status::Implemented && tested);
        g[3] += usize::from(r.status == Status::NotImplemented);
        g[4] += usize::from(r.status == Status::Informative);
    }
    let mut total = [0; 5];
    for (name, g) in &groups {
        let _ = writeln!(
            page,
            "| {name} | {} | {} | {} | {} | {} |",
            g[0], g[1], g[2], g[3], g[4]
        );
        total.iter_mut().zip(g).for_each(|(t, n)| *t += n);
    }
    let [a, b, c, d, e] = total;
    let _ = writeln!(page, "| **all** | {a} | {b} | {c} | {d} | {e} |\n");
}

fn matrix(page: &mut String, reqs: &[Req], by_req: &Citations) {
    page.push_str("## Matrix: requirement → spec → code → tests\n");
    let mut last = String::new();
    for r in reqs {
        let g = group(r);
        if g != last {
            let _ = write!(
                page,
                "\n### {g}\n\n| ID | requirement (paraphrased) | status | spec | code | tests |\n\
                 |---|---|---|---|---|---|\n"
            );
            last = g;
        }
        let status = match (r.status, &r.why) {
            (Status::Implemented, _) => "implemented".to_string(),
            (s, why) => format!(
                "{}: {}",
                if s == Status::Informative {
                    "informative"
                } else {
                    "not implemented"
                },
                why.as_deref().unwrap_or("")
            ),
        };
        let (code, tests) = by_req.get(&r.id).cloned().unwrap_or_default();
        let _ = writeln!(
            page,
            "| {} | {} | {} | {} | {} | {} |",
            r.id,
            cell(&r.text),
            cell(&status),
            r.spec
                .as_deref()
                .map(|s| format!("`{s}`"))
                .unwrap_or_else(|| "—".to_string()),
            list(&code),
            list(&tests)
        );
    }
}

/// The tests citing no requirement, by file; then the public items of `src/` tracing nowhere.
fn reverse(page: &mut String, scan: &Scan) {
    // Per test, (file, name): whether it cites a requirement, or only decisions (`D:`).
    let mut citing: BTreeMap<(String, String), bool> = BTreeMap::new();
    for a in &scan.annotations {
        if let Target::Item {
            name, test: true, ..
        } = &a.target
        {
            let req = a.ids.iter().any(|id| !id.starts_with("D:"));
            *citing.entry((a.file.clone(), name.clone())).or_default() |= req;
        }
    }
    let mut by_file: BTreeMap<&str, (usize, Vec<&str>)> = BTreeMap::new();
    for t in &scan.tests {
        let entry = by_file.entry(&t.file).or_default();
        entry.0 += 1;
        if !citing
            .get(&(t.file.clone(), t.name.clone()))
            .copied()
            .unwrap_or(false)
        {
            entry.1.push(&t.name);
        }
    }
    let none: usize = by_file.values().map(|(_, v)| v.len()).sum();
    let decisions_only = citing.values().filter(|r| !**r).count();
    let _ = write!(
        page,
        "\n## Tests citing no requirement\n\n{none} of {} tests (`#[test]` functions in src/, \
         tests/, proofs/, host/) cite no requirement ({decisions_only} of them cite decisions \
         only): checks of the project's own design (its decisions, the CCSDS layer, the tools) \
         or not yet annotated.\n\n\
         | file | tests | citing none | those tests |\n|---|---|---|---|\n",
        scan.tests.len()
    );
    for (file, (all, names)) in by_file.iter().filter(|(_, (_, v))| !v.is_empty()) {
        let names: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
        let _ = writeln!(
            page,
            "| `{file}` | {all} | {} | {} |",
            names.len(),
            names.join(", ")
        );
    }
    let bare: Vec<_> = scan.public.iter().filter(|p| !scan.traces(p)).collect();
    let _ = write!(
        page,
        "\n## Public items of src/ tracing to nothing\n\n{} of {} public items (`pub` at the start \
         of a line, `pub use` and `pub mod` left out) neither cite a requirement or a decision \
         nor sit in a module (or under a module) that does.\n\n",
        bare.len(),
        scan.public.len()
    );
    let mut by_file: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    for p in bare {
        by_file
            .entry(&p.file)
            .or_default()
            .push(format!("`{}`", p.name));
    }
    if !by_file.is_empty() {
        page.push_str("| file | items |\n|---|---|\n");
    }
    for (file, names) in by_file {
        let _ = writeln!(page, "| `{file}` | {} |", names.join(", "));
    }
}

/// The whole page.
pub fn render(reqs: &[Req], by_req: &Citations, scan: &Scan) -> String {
    let mut page = String::from(
        "# Traceability: requirements, code, tests\n\n\
         Generated by `tests/traceability.rs` (`MMIC_REGENERATE=1 cargo test -p mmic --test \
         traceability`; the test fails when this page is stale). The requirements: \
         `spec/requirements/paper.toml` (the paper's statements `P<section>.<n>`, paraphrased, \
         and the rows `T<table>/<key>` of its Tables 1-8 as `spec/` keys them), and the \
         supported items of `spec/ccsds/pics/*.toml` and `spec/ccsds/pus-tailoring.toml` where \
         present. Code and tests cite them with a `// req: ID, ...` comment line above the item \
         (`T5/*`: every row of Table 5; `D:<id>`: a decision of `spec/decisions.toml`); a \
         module cites in its header comments. Every implemented requirement is cited by at \
         least one test, or the test fails.\n\n",
    );
    counts(&mut page, reqs, by_req);
    matrix(&mut page, reqs, by_req);
    reverse(&mut page, scan);
    page
}
