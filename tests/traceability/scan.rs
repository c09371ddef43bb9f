//! The text scan: `// req:` annotations, test functions and `src/`'s public items, line by line
//! (no parsing: an annotation is a comment, and the item it annotates is the next line that
//! declares one).

use std::path::Path;

/// What an annotation cites for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// The whole file's module (a `// req:` line among the header comments, then a blank line).
    Module,
    /// The item declared right below it; `test` when an attribute between is `#[test]`.
    Item {
        kind: String,
        name: String,
        test: bool,
    },
}

#[derive(Debug)]
pub struct Annotation {
    pub file: String,
    pub line: usize,
    pub ids: Vec<String>,
    pub target: Target,
}

/// A test function (`#[test]`), or a public item of `src/` (`pub` at the start of a line).
#[derive(Debug)]
pub struct Named {
    pub file: String,
    pub name: String,
}

#[derive(Debug, Default)]
pub struct Scan {
    pub annotations: Vec<Annotation>,
    pub tests: Vec<Named>,
    pub public: Vec<Named>,
    /// Annotations followed by no item: `file:line: what`.
    pub dangling: Vec<String>,
    /// Items' own annotations, `(file, item name)`: public items tracing through themselves.
    item_cited: Vec<(String, String)>,
}

impl Scan {
    /// Whether a public item of `src/` cites, or sits in a module that cites, anything.
    pub fn traces(&self, item: &Named) -> bool {
        self.item_cited
            .iter()
            .any(|(f, n)| *f == item.file && *n == item.name)
            || self
                .annotations
                .iter()
                .filter(|a| a.target == Target::Module)
                .any(|a| module_covers(&a.file, &item.file))
    }
}

/// Whether the module file `module` (`a/b.rs`, `a/b/mod.rs`) is `file`'s own or an ancestor's.
/// `src/lib.rs` covers only itself: citing there would trace the whole crate.
fn module_covers(module: &str, file: &str) -> bool {
    if module == file {
        return true;
    }
    let dir = module
        .strip_suffix("/mod.rs")
        .or_else(|| module.strip_suffix(".rs"))
        .filter(|_| module != "src/lib.rs");
    dir.is_some_and(|d| file.starts_with(&format!("{d}/")))
}

const KINDS: &[&str] = &[
    "fn",
    "struct",
    "enum",
    "mod",
    "const",
    "static",
    "trait",
    "type",
    "union",
    "impl",
    "macro_rules",
];

/// Words that may stand between an item keyword and the name (`const fn`, `unsafe impl`).
const QUALIFIERS: &[&str] = &["unsafe", "async", "extern", "crate"];

/// The item a line declares, `(kind, name)`: the first item keyword followed by a name.
pub fn declares(line: &str) -> Option<(String, String)> {
    let code = line.split("//").next().unwrap_or("");
    let words: Vec<&str> = code
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .collect();
    words.windows(2).find_map(|w| match w {
        [kind, name]
            if KINDS.contains(kind) && !KINDS.contains(name) && !QUALIFIERS.contains(name) =>
        {
            Some((kind.to_string(), name.to_string()))
        }
        _ => None,
    })
}

fn annotation_ids(line: &str) -> Option<Vec<String>> {
    let rest = line
        .trim_start()
        .strip_prefix("//")?
        .trim_start()
        .strip_prefix("req:")?;
    Some(
        rest.split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(str::to_string)
            .collect(),
    )
}

fn is_header(line: &str) -> bool {
    let t = line.trim();
    t.is_empty() || t.starts_with("#![") || (t.starts_with("//") && !t.starts_with("///"))
}

/// How far a line opens brackets: an attribute spans lines until its brackets close.
fn depth(line: &str) -> i32 {
    let count = |set: &[char]| line.chars().filter(|c| set.contains(c)).count() as i32;
    count(&['[', '(']) - count(&[']', ')'])
}

/// The target of the annotation on line `at`; `None` when it annotates nothing. Attributes (of
/// any number of lines) and comments may sit between the annotation and its item.
fn target(lines: &[&str], at: usize) -> Option<Target> {
    let header = lines.iter().take(at).all(|l| is_header(l));
    if header && lines.get(at + 1).is_some_and(|l| l.trim().is_empty()) {
        return Some(Target::Module);
    }
    let (mut test, mut open) = (false, 0);
    for line in lines.iter().skip(at + 1) {
        let t = line.trim();
        if open > 0 {
            open += depth(t);
        } else if t.starts_with("#[") {
            test |= t.starts_with("#[test]");
            open = depth(t);
        } else if !t.starts_with("//") {
            return declares(t).map(|(kind, name)| Target::Item { kind, name, test });
        }
    }
    None
}

/// Scans one file's text; `file` is its path from the repository's root.
pub fn scan_text(file: &str, text: &str) -> Scan {
    let lines: Vec<&str> = text.lines().collect();
    let mut scan = Scan::default();
    for (i, line) in lines.iter().enumerate() {
        if let Some(ids) = annotation_ids(line) {
            match target(&lines, i) {
                Some(target) => {
                    if let Target::Item { name, .. } = &target {
                        scan.item_cited.push((file.to_string(), name.clone()));
                    }
                    scan.annotations.push(Annotation {
                        file: file.to_string(),
                        line: i + 1,
                        ids,
                        target,
                    });
                }
                None => scan
                    .dangling
                    .push(format!("{file}:{}: annotates no item", i + 1)),
            }
        }
        if line.trim().starts_with("#[test]") {
            let name = lines.iter().skip(i + 1).take(12).find_map(|l| declares(l));
            if let Some((_, name)) = name {
                scan.tests.push(Named {
                    file: file.to_string(),
                    name,
                });
            }
        }
        let public =
            file.starts_with("src/") && line.starts_with("pub ") && !line.starts_with("pub use");
        if let Some((_, name)) = declares(line).filter(|(k, _)| public && k != "mod") {
            scan.public.push(Named {
                file: file.to_string(),
                name,
            });
        }
    }
    scan
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if path.is_dir() && name != "target" && !name.to_string_lossy().starts_with('.') {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Scans every `.rs` file under the given directories of `root`, in path order.
pub fn scan_tree(root: &Path, dirs: &[&str]) -> Scan {
    let mut files = Vec::new();
    for dir in dirs {
        rust_files(&root.join(dir), &mut files);
    }
    files.sort();
    let mut all = Scan::default();
    for path in files {
        let rel = path
            .strip_prefix(root)
            .expect("under the root")
            .to_string_lossy()
            .replace('\\', "/");
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let s = scan_text(&rel, &text);
        all.annotations.extend(s.annotations);
        all.tests.extend(s.tests);
        all.public.extend(s.public);
        all.dangling.extend(s.dangling);
        all.item_cited.extend(s.item_cited);
    }
    all
}
