//! Tables 5 and 6 as transcribed by hand in spec/motion/states.toml and primitives.toml equal
//! src/pose (letters, names, numbering, order); Section 6's and Section 9's statements on how
//! many primitives a reconfiguration takes, against the counts the model gives
//! (spec/motion/reconfigurations.toml, spec/decisions.toml `single-primitive-reconfigurations`,
//! spec/motion/model.md), each count computed here from the plan table.

use mmic::motion::{route, Primitive, State, StateKind};
use serde::Deserialize;

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(crate::ROOT)
}

fn text(rel: &str) -> String {
    let p = root().join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The paper's text with its whitespace squashed, where it is beside the repository (on the
/// development machines, not in CI's clone).
fn paper() -> Option<String> {
    let raw = std::fs::read_to_string(root().join("../shared/reference/mmic-i-firmware-paper.txt"));
    raw.ok()
        .map(|p| p.split_whitespace().collect::<Vec<_>>().join(" "))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct States {
    paper_table: String,
    caption: String,
    count: usize,
    kinds: Vec<String>,
    final_kind: String,
    state: Vec<StateRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StateRow {
    letter: char,
    name: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Primitives {
    paper_table: String,
    caption: String,
    fwd_side: String,
    back_side: String,
    along_one_direction: Vec<u8>,
    with_hip_rotation: Vec<u8>,
    primitive: Vec<PrimitiveRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PrimitiveRow {
    number: u8,
    name: String,
}

// req: T5/*, P6.1
#[test]
fn table5_as_transcribed_is_the_codes_states() {
    let t: States = toml::from_str(&text("spec/motion/states.toml")).unwrap();
    assert_eq!(t.paper_table, "Table 5");
    assert_eq!(t.count, t.state.len());
    assert_eq!(State::ALL.len(), t.state.len(), "the number of states");
    for (s, row) in State::ALL.iter().zip(&t.state) {
        assert_eq!(
            (s.letter(), s.name()),
            (row.letter, row.name.as_str()),
            "{s}"
        );
        // The kind is the name's last word (Section 6: a match, a stretch or a turn).
        let word = row.name.rsplit(' ').next().unwrap();
        assert!(t.kinds.iter().any(|k| k == word), "{}: {word}", row.name);
        let kind = match s.kind() {
            StateKind::Matched => "match",
            StateKind::Stretch => "stretch",
            StateKind::Turn => "turn",
        };
        assert_eq!(kind, word, "{s}");
        assert_eq!(s.is_matched(), word == t.final_kind, "{s}: a final state");
    }
    // The table as printed: its caption and "letter name" rows, in order, in the paper's text.
    if let Some(paper) = paper() {
        assert!(paper.contains(&format!("{}. {}", t.paper_table, t.caption)));
        let rows: Vec<String> = t
            .state
            .iter()
            .map(|r| format!("{} {}", r.letter, r.name))
            .collect();
        assert!(paper.contains(&format!("state name {}", rows.join(" "))));
    }
}

// req: T6/*, P6.6
#[test]
fn table6_as_transcribed_is_the_codes_primitives() {
    let t: Primitives = toml::from_str(&text("spec/motion/primitives.toml")).unwrap();
    assert_eq!(t.paper_table, "Table 6");
    assert_eq!(
        Primitive::ALL.len(),
        t.primitive.len(),
        "the number of primitives"
    );
    for (p, row) in Primitive::ALL.iter().zip(&t.primitive) {
        assert_eq!(
            (p.number(), p.name()),
            (row.number, row.name.as_str()),
            "{p}"
        );
        assert_eq!(Primitive::from_number(row.number), Some(*p));
        // "fwd" moves side A, "back" side B (the project's reading: fwd-back-reading).
        let side = if row.name.starts_with("fwd") {
            &t.fwd_side
        } else {
            assert!(row.name.starts_with("back"), "{}", row.name);
            &t.back_side
        };
        let moves: Vec<_> = mmic::pose::geometry::model_moves()
            .filter(|m| m.3 == *p)
            .collect();
        assert!(!moves.is_empty(), "{p}");
        for m in moves {
            assert_eq!(format!("{:?}", m.2), *side, "{p}: {} -> {}", m.0, m.1);
        }
        // Table 6's caption: the first four along one direction, the last four with the hip.
        let turn = row.name.contains("Turn");
        assert_eq!(t.with_hip_rotation.contains(&row.number), turn, "{p}");
        assert_eq!(t.along_one_direction.contains(&row.number), !turn, "{p}");
    }
    if let Some(paper) = paper() {
        assert!(paper.contains(&format!("{}. {}", t.paper_table, t.caption)));
        let rows: Vec<String> = t
            .primitive
            .iter()
            .map(|r| format!("{} {}", r.number, r.name))
            .collect();
        assert!(paper.contains(&format!("Primitive {}", rows.join(" "))));
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Reconfigurations {
    decision: String,
    paper: PaperFacts,
    model: Model,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PaperFacts {
    section6: String,
    section6_final_states: String,
    section6_search: String,
    section9: String,
    fewest_primitives: usize,
    most_primitives: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Model {
    matched_to_matched: [usize; 3],
    any_to_matched: [usize; 3],
    transitional_to_matched: [usize; 3],
    all_pairs: [usize; 3],
}

/// The chosen plans between distinct states `from` and `to` for which `pick` holds, counted by
/// their number of primitives: [one, two, three], and how many pairs there are.
fn histogram(pick: impl Fn(State, State) -> bool) -> ([usize; 3], usize) {
    let mut h = [0; 3];
    let mut pairs = 0;
    for from in State::ALL {
        for to in State::ALL {
            if from == to || !pick(from, to) {
                continue;
            }
            let n = route::lookup(from, to).len();
            assert!((1..=3).contains(&n), "{from} -> {to}: {n}");
            h[n - 1] += 1;
            pairs += 1;
        }
    }
    (h, pairs)
}

/// The sentence spec/ writes for a set of pairs: "84 pairs from any state to a matched target:
/// 18 of one primitive, 42 of two, 24 of three".
fn sentence(pairs: usize, what: &str, h: [usize; 3]) -> String {
    format!(
        "{pairs} {what}: {} of one primitive, {} of two, {} of three",
        h[0], h[1], h[2]
    )
}

/// Section 6: "some others do not require an intermediate state. For the latter case, the
/// reconfiguration requires a single motion primitive." Between two matched states the model
/// has none such; from any state to a matched target (what a reconfiguration command may ask)
/// it has. The counts are computed here, and spec/motion/reconfigurations.toml, the decision
/// and spec/motion/model.md must state exactly these.
// req: P6.9
#[test]
fn single_primitive_reconfigurations_are_counted_as_spec_says() {
    let r: Reconfigurations = toml::from_str(&text("spec/motion/reconfigurations.toml")).unwrap();
    let matched = histogram(|f, t| f.is_matched() && t.is_matched());
    let any = histogram(|_, t| t.is_matched());
    let transitional = histogram(|f, t| !f.is_matched() && t.is_matched());
    let all = histogram(|_, _| true);
    assert_eq!(matched.0, r.model.matched_to_matched, "matched to matched");
    assert_eq!(
        any.0, r.model.any_to_matched,
        "any state to a matched target"
    );
    assert_eq!(
        transitional.0, r.model.transitional_to_matched,
        "transitional state to a matched target"
    );
    assert_eq!(all.0, r.model.all_pairs, "all pairs");

    // Section 9: "between one and three" over every reconfiguration a command may ask;
    // Section 6's three cases (no, one, two intermediate states) all occur there.
    let lengths = |h: [usize; 3]| (1..=3).filter(|n| h[n - 1] > 0).collect::<Vec<_>>();
    let any_lengths = lengths(any.0);
    assert_eq!(any_lengths.first(), Some(&r.paper.fewest_primitives));
    assert_eq!(any_lengths.last(), Some(&r.paper.most_primitives));
    assert_eq!(any_lengths.len(), 3, "Section 6's three cases");
    // Every single-primitive reconfiguration starts in a transitional state: between matched
    // states the third case does not exist in the model.
    assert_eq!(any.0[0], transitional.0[0]);

    let sentences = [
        sentence(
            matched.1,
            "ordered pairs of distinct matched states",
            matched.0,
        ),
        sentence(any.1, "pairs from any state to a matched target", any.0),
        sentence(
            transitional.1,
            "pairs from a transitional state to a matched target",
            transitional.0,
        ),
    ];
    let decisions: toml::Table = toml::from_str(&text("spec/decisions.toml")).unwrap();
    let decision = decisions["decision"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["id"].as_str() == Some(&r.decision))
        .unwrap_or_else(|| panic!("no decision {}", r.decision));
    let decision = decision["decision"].as_str().unwrap();
    let model = text("spec/motion/model.md")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    for s in &sentences {
        assert!(
            decision.contains(s.as_str()),
            "decision {}: {s:?}",
            r.decision
        );
        assert!(model.contains(s.as_str()), "spec/motion/model.md: {s:?}");
    }
    // The 30 pairs between matched states are the plan-length table's too.
    let lengths_txt = text("spec/motion/plan-lengths.txt");
    assert!(lengths_txt.contains(&format!(
        "30 ordered pairs of distinct matched states: {} of two primitives, {} of three",
        matched.0[1], matched.0[2]
    )));

    // The quotes are the paper's words.
    if let Some(paper) = paper() {
        let p = &r.paper;
        for q in [
            &p.section6,
            &p.section6_final_states,
            &p.section6_search,
            &p.section9,
        ] {
            assert!(paper.contains(q.as_str()), "not in the paper: {q:?}");
        }
    }
}
