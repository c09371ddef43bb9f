//! The coding standard's rules that no lint enforces (`docs/coding-standard.md`), read off the
//! syntax of every `src/**.rs` file with `syn`, outside `#[cfg(test)]` and `#[test]` items:
//!
//! * R3: no `assert!`, `assert_eq!`, `assert_ne!` or `debug_assert*!` in code that ships, except
//!   in a `const` item (evaluated by the compiler: a failure stops the build, never a run);
//! * R6: no `allow` of a lint, and every `expect` of one carries a `reason`;
//! * the lint record, `docs/evidence/lint-record.md`: every exception (file, item, lints,
//!   reason), generated here and checked fresh (`MMIC_REGENERATE=1 cargo test --test
//!   coding_standard` writes it).
//!
//! The bodies of `macro_rules!` definitions and of macro invocations are token streams, not
//! syntax: their lint attributes are read off the tokens (each needs a reason), but an
//! `assert!` there is not seen (the macros' bodies are reviewed as text).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use syn::punctuated::Punctuated;
use syn::visit::{self, Visit};
use syn::{Attribute, Expr, Lit, Meta, Token};

/// The macros that panic when their condition fails at run time.
const ASSERTS: [&str; 6] = [
    "assert",
    "assert_eq",
    "assert_ne",
    "debug_assert",
    "debug_assert_eq",
    "debug_assert_ne",
];

/// One lint exception of shipped code.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Exception {
    file: String,
    item: String,
    kind: String,
    lints: Vec<String>,
    reason: Option<String>,
}

/// What one file shows: the exceptions and the broken rules.
#[derive(Default)]
struct Scan {
    file: String,
    items: Vec<String>,
    in_const: usize,
    exceptions: Vec<Exception>,
    broken: Vec<String>,
}

/// `attrs` mark an item that is compiled only for tests.
fn test_only(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("test")
            || (a.path().is_ident("cfg")
                && a.parse_args::<Meta>()
                    .is_ok_and(|m| m.path().is_ident("test")))
    })
}

/// The lints and the reason of `allow(…)` / `expect(…)`'s arguments.
fn lints_and_reason(list: &syn::MetaList) -> (Vec<String>, Option<String>) {
    let parsed = list.parse_args_with(Punctuated::<Meta, Token![,]>::parse_terminated);
    let mut lints = Vec::new();
    let mut reason = None;
    for meta in parsed.into_iter().flatten() {
        match meta {
            Meta::Path(p) => lints.push(path_text(&p)),
            Meta::NameValue(nv) if nv.path.is_ident("reason") => {
                if let Expr::Lit(l) = &nv.value
                    && let Lit::Str(s) = &l.lit
                {
                    reason = Some(s.value());
                }
            }
            other => lints.push(path_text(other.path())),
        }
    }
    (lints, reason)
}

fn path_text(p: &syn::Path) -> String {
    p.segments
        .iter()
        .map(|s| s.ident.to_string())
        .collect::<Vec<_>>()
        .join("::")
}

/// The `allow`/`expect` lists of `attr`, also inside `cfg_attr(…)`.
fn lint_lists(attr: &Meta) -> Vec<(String, syn::MetaList)> {
    let Meta::List(list) = attr else {
        return Vec::new();
    };
    if list.path.is_ident("allow") || list.path.is_ident("expect") {
        return vec![(path_text(&list.path), list.clone())];
    }
    if list.path.is_ident("cfg_attr") {
        let inner = list.parse_args_with(Punctuated::<Meta, Token![,]>::parse_terminated);
        // The first is the predicate; the rest are attributes.
        return inner
            .into_iter()
            .flatten()
            .skip(1)
            .flat_map(|m| lint_lists(&m))
            .collect();
    }
    Vec::new()
}

impl Scan {
    fn item_name(&self) -> String {
        if self.items.is_empty() {
            "(module)".to_string()
        } else {
            self.items.join("::")
        }
    }

    fn attributes(&mut self, attrs: &[Attribute]) {
        for a in attrs {
            for (kind, list) in lint_lists(&a.meta) {
                let (lints, reason) = lints_and_reason(&list);
                let item = self.item_name();
                if kind == "allow" {
                    self.broken.push(format!(
                        "{}: {item}: `allow({})`: write `expect(…, reason = \"…\")` (R6)",
                        self.file,
                        lints.join(", ")
                    ));
                } else if reason.is_none() {
                    self.broken.push(format!(
                        "{}: {item}: `expect({})` without a reason (R6)",
                        self.file,
                        lints.join(", ")
                    ));
                }
                self.exceptions.push(Exception {
                    file: self.file.clone(),
                    item,
                    kind,
                    lints,
                    reason,
                });
            }
        }
    }

    /// Visits a named item's inside with its name on the stack, unless it is test-only.
    fn named(&mut self, name: String, attrs: &[Attribute], inside: impl FnOnce(&mut Self)) {
        if test_only(attrs) {
            return;
        }
        self.items.push(name);
        self.attributes(attrs);
        inside(self);
        self.items.pop();
    }
}

impl Scan {
    /// Lint attributes inside a macro's tokens (a `macro_rules!` body or an invocation's input),
    /// which are not syntax until expanded: each one an exception with a reason. An `allow` is
    /// taken there, with its reason: one expansion of a macro may meet the lint where another
    /// does not, so an `expect` could not hold for all.
    fn macro_body(&mut self, tokens: proc_macro2::TokenStream) {
        use proc_macro2::TokenTree;
        let mut prev_hash = false;
        for tt in tokens {
            if let TokenTree::Group(g) = &tt {
                let is_attr = prev_hash && g.delimiter() == proc_macro2::Delimiter::Bracket;
                if let Some(meta) = is_attr
                    .then(|| syn::parse2::<Meta>(g.stream()).ok())
                    .flatten()
                {
                    for (kind, list) in lint_lists(&meta) {
                        let (lints, reason) = lints_and_reason(&list);
                        if reason.is_none() {
                            self.broken.push(format!(
                                "{}: {}: `{kind}({})` in a macro without a reason (R6)",
                                self.file,
                                self.item_name(),
                                lints.join(", ")
                            ));
                        }
                        self.exceptions.push(Exception {
                            file: self.file.clone(),
                            item: format!("{} (macro)", self.item_name()),
                            kind,
                            lints,
                            reason,
                        });
                    }
                } else {
                    self.macro_body(g.stream());
                }
            }
            prev_hash = matches!(&tt, TokenTree::Punct(p) if p.as_char() == '#');
        }
    }
}

impl<'ast> Visit<'ast> for Scan {
    fn visit_file(&mut self, f: &'ast syn::File) {
        self.attributes(&f.attrs);
        visit::visit_file(self, f);
    }
    fn visit_item_mod(&mut self, i: &'ast syn::ItemMod) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            visit::visit_item_mod(s, i)
        });
    }
    fn visit_item_fn(&mut self, i: &'ast syn::ItemFn) {
        self.named(i.sig.ident.to_string(), &i.attrs, |s| {
            visit::visit_item_fn(s, i)
        });
    }
    fn visit_impl_item_fn(&mut self, i: &'ast syn::ImplItemFn) {
        self.named(i.sig.ident.to_string(), &i.attrs, |s| {
            visit::visit_impl_item_fn(s, i)
        });
    }
    fn visit_trait_item_fn(&mut self, i: &'ast syn::TraitItemFn) {
        self.named(i.sig.ident.to_string(), &i.attrs, |s| {
            visit::visit_trait_item_fn(s, i)
        });
    }
    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        let ty = &i.self_ty;
        let name = format!("impl {}", quote::quote!(#ty).to_string().replace(' ', ""));
        self.named(name, &i.attrs, |s| visit::visit_item_impl(s, i));
    }
    fn visit_item_struct(&mut self, i: &'ast syn::ItemStruct) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            visit::visit_item_struct(s, i)
        });
    }
    fn visit_item_enum(&mut self, i: &'ast syn::ItemEnum) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            visit::visit_item_enum(s, i)
        });
    }
    fn visit_item_const(&mut self, i: &'ast syn::ItemConst) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            s.in_const += 1;
            visit::visit_item_const(s, i);
            s.in_const -= 1;
        });
    }
    fn visit_impl_item_const(&mut self, i: &'ast syn::ImplItemConst) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            s.in_const += 1;
            visit::visit_impl_item_const(s, i);
            s.in_const -= 1;
        });
    }
    fn visit_item_macro(&mut self, i: &'ast syn::ItemMacro) {
        let name = i
            .ident
            .as_ref()
            .map_or_else(|| format!("{}!", path_text(&i.mac.path)), |n| n.to_string());
        self.named(name, &i.attrs, |s| visit::visit_item_macro(s, i));
    }
    fn visit_item_static(&mut self, i: &'ast syn::ItemStatic) {
        self.named(i.ident.to_string(), &i.attrs, |s| {
            visit::visit_item_static(s, i)
        });
    }
    fn visit_local(&mut self, l: &'ast syn::Local) {
        self.attributes(&l.attrs);
        visit::visit_local(self, l);
    }
    fn visit_expr(&mut self, e: &'ast Expr) {
        // Attributes on an expression (`#[expect(…)] x as u8`): an exception as well.
        let attrs: &[Attribute] = match e {
            Expr::Cast(c) => &c.attrs,
            Expr::Binary(b) => &b.attrs,
            Expr::Index(i) => &i.attrs,
            Expr::Block(b) => &b.attrs,
            _ => &[],
        };
        self.attributes(attrs);
        visit::visit_expr(self, e);
    }
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.macro_body(m.tokens.clone());
        let name = m.path.segments.last().map(|s| s.ident.to_string());
        if self.in_const == 0 && name.as_deref().is_some_and(|n| ASSERTS.contains(&n)) {
            self.broken.push(format!(
                "{}: {}: `{}!` in shipped code: a typed error instead (R3)",
                self.file,
                self.item_name(),
                name.unwrap_or_default()
            ));
        }
        visit::visit_macro(self, m);
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src/") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every file of `src/` scanned, in path order.
fn scan_src() -> (Vec<Exception>, Vec<String>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    files.sort();
    let (mut exceptions, mut broken) = (Vec::new(), Vec::new());
    for path in files {
        let text = std::fs::read_to_string(&path).expect("read a source file");
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path.strip_prefix(root).expect("under the root");
        let mut scan = Scan {
            file: name.display().to_string(),
            ..Scan::default()
        };
        scan.visit_file(&file);
        exceptions.extend(scan.exceptions);
        broken.extend(scan.broken);
    }
    (exceptions, broken)
}

#[test]
fn shipped_code_keeps_the_rules_no_lint_checks() {
    let (_, broken) = scan_src();
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// The lint record as the page `docs/evidence/lint-record.md` holds it.
fn record(exceptions: &[Exception]) -> String {
    let mut page = String::from(
        "# Lint record: every exception to the coding standard's lints in `src/`\n\n\
         Generated by `tests/coding_standard.rs` from the source (regenerate with\n\
         `MMIC_REGENERATE=1 cargo test --test coding_standard`; CI fails when it is stale). The\n\
         lints and the rules behind them: `docs/coding-standard.md`. Code under `#[cfg(test)]`\n\
         is not shipped and not listed.\n\n",
    );
    let count: usize = exceptions.len();
    let _ = writeln!(page, "{count} exceptions.\n");
    if exceptions.is_empty() {
        return page;
    }
    page.push_str("| file | item | lints | reason |\n|---|---|---|---|\n");
    for e in exceptions {
        let _ = writeln!(
            page,
            "| `{}` | `{}` | {} | {} |",
            e.file,
            e.item,
            e.lints
                .iter()
                .map(|l| format!("`{l}`"))
                .collect::<Vec<_>>()
                .join(", "),
            e.reason.as_deref().unwrap_or("(none)").replace('|', "\\|")
        );
    }
    page
}

#[test]
fn the_lint_record_is_fresh() {
    let (mut exceptions, _) = scan_src();
    exceptions.sort();
    let page = record(&exceptions);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/evidence/lint-record.md");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
        std::fs::write(&path, &page).expect("write the lint record");
    }
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    assert_eq!(
        on_disk, page,
        "docs/evidence/lint-record.md is stale: MMIC_REGENERATE=1 cargo test --test coding_standard"
    );
}

/// The scanner itself: it finds what it must and passes what it may.
#[test]
fn the_scanner_sees_an_assert_an_allow_and_a_bare_expect_but_not_test_code() {
    let src = r#"
        const _: () = assert!(1 < 2);
        #[allow(clippy::as_conversions)]
        fn a(x: u16) -> u8 { assert!(x < 256); x as u8 }
        #[cfg_attr(not(test), expect(clippy::indexing_slicing))]
        fn b(v: &[u8]) -> u8 { v[0] }
        #[cfg_attr(not(test), expect(clippy::as_conversions, reason = "in range"))]
        fn c(x: f32) -> i32 { x as i32 }
        #[cfg(test)]
        mod tests { #[allow(dead_code)] fn t() { assert_eq!(1, 1); } }
        #[test]
        fn u() { assert!(true); }
        macro_rules! m { () => { #[allow(unused_imports)] use x::*; #[allow(dead_code, reason = "r")] fn f() {} } }
    "#;
    let mut scan = Scan {
        file: "x.rs".into(),
        ..Scan::default()
    };
    scan.visit_file(&syn::parse_file(src).expect("parses"));
    assert_eq!(
        scan.broken,
        [
            "x.rs: a: `allow(clippy::as_conversions)`: write `expect(…, reason = \"…\")` (R6)",
            "x.rs: a: `assert!` in shipped code: a typed error instead (R3)",
            "x.rs: b: `expect(clippy::indexing_slicing)` without a reason (R6)",
            "x.rs: m: `allow(unused_imports)` in a macro without a reason (R6)",
        ]
    );
    let kept: Vec<_> = scan
        .exceptions
        .iter()
        .map(|e| (e.item.as_str(), e.kind.as_str(), e.reason.as_deref()))
        .collect();
    assert_eq!(
        kept,
        [
            ("a", "allow", None),
            ("b", "expect", None),
            ("c", "expect", Some("in range")),
            ("m (macro)", "allow", None),
            ("m (macro)", "allow", Some("r")),
        ]
    );
}
