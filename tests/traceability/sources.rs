//! The requirement sources: the paper's (`spec/requirements/*.toml`), the CCSDS proformas'
//! supported items and the PUS tailoring (when present), the decisions' IDs, and the rows of the
//! paper's tables as `spec/` transcribes them.

use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use toml::Value;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    Implemented,
    NotImplemented,
    Informative,
}

/// One requirement: `source` groups them on the page (`paper`, a PICS book, `PUS tailoring`).
#[derive(Debug, Clone, Deserialize)]
pub struct Req {
    pub id: String,
    #[serde(default)]
    pub section: u32,
    #[serde(default)]
    pub kind: String,
    #[serde(default)]
    pub text: String,
    pub spec: Option<String>,
    pub status: Status,
    pub why: Option<String>,
    #[serde(skip)]
    pub source: String,
}

#[derive(Deserialize)]
struct ReqFile {
    req: Vec<Req>,
}

fn read(path: &Path) -> Option<String> {
    std::fs::read_to_string(path).ok()
}

fn parse<T: for<'de> Deserialize<'de>>(path: &Path) -> Option<T> {
    let text = read(path)?;
    Some(toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}

fn toml_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    files.sort();
    files
}

/// Every table of `value` (at any depth) that has a string `id`: the items of a proforma or of
/// the tailoring, whatever the arrays are named.
fn id_tables(value: &Value, out: &mut Vec<toml::Table>) {
    match value {
        Value::Table(t) => {
            if t.get("id").is_some_and(Value::is_str) && t.contains_key("supported") {
                out.push(t.clone());
            }
            t.values().for_each(|v| id_tables(v, out));
        }
        Value::Array(a) => a.iter().for_each(|v| id_tables(v, out)),
        _ => {}
    }
}

fn str_of<'a>(t: &'a toml::Table, key: &str) -> &'a str {
    t.get(key).and_then(Value::as_str).unwrap_or("")
}

/// The items of one proforma or tailoring file as requirements (every item; `supported = "Y"`
/// ones are implemented, the others not), their IDs prefixed by `prefix`.
fn supported_items(path: &Path, source: &str, prefix: &str) -> Vec<Req> {
    let Some(value) = parse::<Value>(path) else {
        return Vec::new();
    };
    let mut tables = Vec::new();
    id_tables(&value, &mut tables);
    // The file as the page names it, from the repository's root.
    let shown = path.to_string_lossy().replace('\\', "/");
    let spec = format!(
        "spec/{}",
        shown.rsplit_once("/spec/").map_or("", |(_, p)| p)
    );
    tables
        .iter()
        .map(|t| {
            let id = str_of(t, "id");
            let supported = str_of(t, "supported");
            Req {
                id: if id.starts_with(prefix) {
                    id.to_string()
                } else {
                    format!("{prefix}{id}")
                },
                section: 0,
                kind: "item".to_string(),
                text: [str_of(t, "feature"), str_of(t, "name")].concat(),
                spec: Some(spec.clone()),
                status: if supported == "Y" {
                    Status::Implemented
                } else {
                    Status::NotImplemented
                },
                why: Some(format!("supported = {supported}: {}", str_of(t, "why")))
                    .filter(|_| supported != "Y"),
                source: source.to_string(),
            }
        })
        .collect()
}

/// Every requirement of every source present in the tree.
pub fn requirements(root: &Path) -> Vec<Req> {
    let mut reqs = Vec::new();
    for path in toml_files(&root.join("spec/requirements")) {
        let file: ReqFile = parse(&path).expect("listed");
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        reqs.extend(file.req.into_iter().map(|r| Req {
            source: stem.clone(),
            ..r
        }));
    }
    for path in toml_files(&root.join("spec/ccsds/pics")) {
        let value: Value = parse(&path).expect("listed");
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let book = value
            .get("book")
            .and_then(|b| b.get("id"))
            .and_then(Value::as_str);
        let book = book.unwrap_or(&stem).to_string();
        reqs.extend(supported_items(
            &path,
            &format!("PICS {book}"),
            &format!("{book}/"),
        ));
    }
    let tailoring = root.join("spec/ccsds/pus-tailoring.toml");
    reqs.extend(supported_items(&tailoring, "PUS tailoring", "PUS/"));
    reqs
}

/// IDs that may be cited without being requirements: the decisions, `D:<id>`.
pub fn other_known_ids(root: &Path) -> Vec<String> {
    #[derive(Deserialize)]
    struct Decisions {
        decision: Vec<Decision>,
    }
    #[derive(Deserialize)]
    struct Decision {
        id: String,
    }
    let d: Decisions = parse(&root.join("spec/decisions.toml")).expect("spec/decisions.toml");
    d.decision
        .into_iter()
        .map(|d| format!("D:{}", d.id))
        .collect()
}

/// Unique IDs, statuses with their reason, the paper's IDs in their form.
pub fn check_requirements(reqs: &[Req]) -> Vec<String> {
    let mut problems = Vec::new();
    let mut seen = BTreeSet::new();
    for r in reqs {
        if !seen.insert(r.id.as_str()) {
            problems.push(format!("{}: listed twice", r.id));
        }
        if r.status != Status::Implemented && r.why.as_deref().is_none_or(str::is_empty) {
            problems.push(format!("{}: {:?} without `why`", r.id, r.status));
        }
        if r.source == "paper" {
            let form = match r.kind.as_str() {
                "statement" => r.id.starts_with(&format!("P{}.", r.section)),
                "table-row" => r.id.starts_with('T') && r.id.contains('/'),
                _ => false,
            };
            if !form || r.text.is_empty() {
                problems.push(format!(
                    "{}: kind `{}`, section {}, text or ID form wrong",
                    r.id, r.kind, r.section
                ));
            }
        }
    }
    problems
}

fn keys(path: &Path, array: &str, key: &str, keep: impl Fn(&Value) -> bool) -> BTreeSet<String> {
    let value: Value = parse(path).unwrap_or_else(|| panic!("{}", path.display()));
    let rows = value
        .get(array)
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    rows.iter()
        .filter(|r| keep(r))
        .filter_map(|r| match r.get(key)? {
            Value::String(s) => Some(s.clone()),
            other => Some(other.to_string()),
        })
        .collect()
}

/// The row keys of Tables 1-8 as `spec/` transcribes them: the keys `T<n>/<key>` must name.
pub fn table_rows(root: &Path) -> BTreeMap<u32, BTreeSet<String>> {
    let spec = root.join("spec");
    let all = |_: &Value| true;
    let paper_fault = |r: &Value| {
        !r.get("table8")
            .and_then(Value::as_str)
            .unwrap_or("none")
            .starts_with("none")
    };
    let modes: Value = parse(&spec.join("modes.toml")).expect("spec/modes.toml");
    let table7 = modes
        .get("table7")
        .and_then(Value::as_table)
        .expect("[table7]");
    BTreeMap::from([
        (1, keys(&spec.join("commands.toml"), "table1", "kind", all)),
        (
            2,
            keys(&spec.join("packets/command.toml"), "field", "name", all),
        ),
        (
            3,
            keys(&spec.join("packets/heartbeat.toml"), "field", "name", all),
        ),
        (
            4,
            keys(
                &spec.join("packets/internal-heartbeat.toml"),
                "field",
                "name",
                all,
            ),
        ),
        (
            5,
            keys(&spec.join("motion/states.toml"), "state", "letter", all),
        ),
        (
            6,
            keys(
                &spec.join("motion/primitives.toml"),
                "primitive",
                "number",
                all,
            ),
        ),
        (
            7,
            table7.keys().filter(|k| *k != "columns").cloned().collect(),
        ),
        (
            8,
            keys(&spec.join("faults.toml"), "fault", "name", paper_fault),
        ),
    ])
}
