//! The XTCE mission database's meaning, apart from its spelling: the generated XML read back
//! with quick-xml as a tree (element names, attributes in order, text with entities resolved and
//! whitespace trimmed; comments and layout dropped) equals the tree of the string-formatting
//! generator's last output (xtce-before-quick-xml.xml, written before the typed model and
//! quick-xml's writer replaced it, issue 26). And the ST\[1\] verifiers keep what fixed the YAMCS
//! races of issue 24: `java-expression` algorithms whose TM inputs are `instance="1"`.

use mmic_host::xtce;
use quick_xml::escape::resolve_predefined_entity;
use quick_xml::events::{BytesStart, Event};
use quick_xml::{Reader, XmlVersion};
use std::path::PathBuf;

/// An element: name, attributes (document order), trimmed text, children.
#[derive(Debug, PartialEq)]
struct Node {
    name: String,
    attrs: Vec<(String, String)>,
    text: String,
    children: Vec<Node>,
}

impl Node {
    fn of(e: &BytesStart) -> Node {
        let attrs = e
            .attributes()
            .map(|a| {
                let a = a.unwrap();
                let key = String::from_utf8(a.key.as_ref().to_vec()).unwrap();
                (
                    key,
                    a.normalized_value(XmlVersion::Implicit1_0)
                        .unwrap()
                        .into_owned(),
                )
            })
            .collect();
        Node {
            name: String::from_utf8(e.name().as_ref().to_vec()).unwrap(),
            attrs,
            text: String::new(),
            children: Vec::new(),
        }
    }

    fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// Every element under this one (itself included) named `name`, depth first.
    fn all<'a>(&'a self, name: &str, out: &mut Vec<&'a Node>) {
        if self.name == name {
            out.push(self);
        }
        self.children.iter().for_each(|c| c.all(name, out));
    }

    fn find(&self, name: &str) -> Vec<&Node> {
        let mut out = Vec::new();
        self.all(name, &mut out);
        out
    }
}

/// The root element of `xml`, as a tree.
fn tree(xml: &str) -> Node {
    let mut reader = Reader::from_str(xml);
    let mut open: Vec<Node> = vec![Node::of(&BytesStart::new("document"))];
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) => open.push(Node::of(&e)),
            Event::Empty(e) => open.last_mut().unwrap().children.push(Node::of(&e)),
            Event::End(_) => {
                let mut done = open.pop().unwrap();
                done.text = done.text.trim().to_string();
                open.last_mut().unwrap().children.push(done);
            }
            Event::Text(t) => open.last_mut().unwrap().text += &t.decode().unwrap(),
            Event::GeneralRef(r) => {
                let name = r.decode().unwrap();
                let c = resolve_predefined_entity(&name).unwrap_or_else(|| panic!("&{name};"));
                open.last_mut().unwrap().text += c;
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let mut document = open.pop().unwrap();
    assert!(open.is_empty(), "unclosed elements");
    assert_eq!(document.children.len(), 1, "one root element");
    document.children.pop().unwrap()
}

fn before_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/cli/xtce-before-quick-xml.xml")
}

#[test]
fn the_xtce_tree_is_the_string_generators() {
    let now = xtce::generate().unwrap();
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(before_path(), &now).unwrap();
    }
    let before = std::fs::read_to_string(before_path()).unwrap();
    let (now, before) = (tree(&now), tree(&before));
    assert_eq!(now.find("SequenceContainer").len(), 13);
    assert!(
        now == before,
        "the XTCE means something else than tests/cli/xtce-before-quick-xml.xml; if the \
         database changed on purpose, regenerate with `MMIC_REGENERATE=1 cargo test -p mmic-host \
         --test cli xtce`"
    );
}

/// The comparison sees what matters and only that: layout, comments and escaping spelled
/// otherwise are equal; a changed value, a dropped attribute or two swapped elements are not.
#[test]
fn the_xtce_tree_comparison_sees_meaning_not_layout() {
    let a = tree("<a x=\"it's\"><b>1 &amp;&amp; 2</b><!-- c --><c /></a>");
    let same = tree("<a x='it&apos;s'>\n  <b> 1 &amp;&amp; 2 </b>\n  <c/>\n</a>\n");
    assert_eq!(a, same);
    for other in [
        "<a x=\"its\"><b>1 &amp;&amp; 2</b><c /></a>",
        "<a><b>1 &amp;&amp; 2</b><c /></a>",
        "<a x=\"it's\"><c /><b>1 &amp;&amp; 2</b></a>",
        "<a x=\"it's\"><b>1 &amp; 2</b><c /></a>",
    ] {
        assert_ne!(a, tree(other), "{other}");
    }
}

/// Every ST\[1\] verifier is a `java-expression` algorithm reading the command's APID argument
/// and sequence count at instance 0 (they are not TM) and every TM parameter at instance 1 (never
/// the last value cache, issue 24), within a window from the command's release; only the
/// failure verifier leaves a time-out alone and returns the failure code.
#[test]
fn the_st1_verifiers_are_java_algorithms_with_tm_inputs_of_instance_1() {
    let x = tree(&xtce::generate().unwrap());
    let sets = x.find("VerifierSet");
    assert_eq!(sets.len(), 1, "only pus-tc has verifiers");
    let stages: Vec<(&str, Option<&str>)> = sets[0]
        .children
        .iter()
        .map(|v| (v.name.as_str(), v.attr("name")))
        .collect();
    assert_eq!(
        stages,
        [
            ("AcceptedVerifier", None),
            ("ExecutionVerifier", Some("Started")),
            ("CompleteVerifier", None),
            ("FailedVerifier", None),
        ]
    );
    for v in &sets[0].children {
        let text = v.find("AlgorithmText");
        assert_eq!(text.len(), 1);
        assert_eq!(text[0].attr("language"), Some("java-expression"));
        let inputs = v.find("InputParameterInstanceRef");
        let failed = v.name == "FailedVerifier";
        assert_eq!(inputs.len(), if failed { 8 } else { 7 }, "{}", v.name);
        for i in inputs {
            let tm = i.attr("parameterRef").unwrap().starts_with("/MMIC/");
            assert_eq!(i.attr("instance"), tm.then_some("1"), "{i:?}");
        }
        let window = v.find("CheckWindow");
        assert_eq!(
            window[0].attr("timeWindowIsRelativeTo"),
            Some("commandRelease")
        );
        let on_timeout = v.find("AncillaryData");
        assert_eq!(on_timeout.len(), usize::from(!failed), "{}", v.name);
        assert_eq!(
            text[0]
                .text
                .contains("VerificationResult(true, null, failure_code.getEngValue())"),
            failed
        );
    }
}
