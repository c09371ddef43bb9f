//! The reconfiguration map and plans, checked exhaustively against the numbers of the model
//! (spec/motion/model.md) and an all-pairs shortest-path oracle.
#![allow(clippy::needless_range_loop)] // Floyd–Warshall reads best with indices

use mmic::motion::geometry::single_move;
use mmic::motion::{map, route, Primitive, State, StateKind};
use mmic::units::Side;

fn inverse(p: Primitive) -> Primitive {
    use Primitive::*;
    match p {
        FwdContract => FwdExtend,
        FwdExtend => FwdContract,
        BackContract => BackExtend,
        BackExtend => BackContract,
        FwdTurnCw => FwdTurnCcw,
        FwdTurnCcw => FwdTurnCw,
        BackTurnCw => BackTurnCcw,
        BackTurnCcw => BackTurnCw,
    }
}

#[test]
fn seventy_two_moves_each_with_its_inverse() {
    let moves: Vec<_> = map::moves().collect();
    assert_eq!(moves.len(), 72);
    for &(f, t, p) in &moves {
        assert_eq!(map::primitive(t, f), Some(inverse(p)), "{f} -> {t} by {p}");
        let (side, q) = single_move(f, t).unwrap();
        assert_eq!(q, p);
        // fwd primitives move side A, back primitives side B (Table 6).
        assert_eq!(side == Side::A, p.name().starts_with("fwd"), "{f} -> {t}");
        // Primitives 1-4 exactly between a matched and a stretch state (Section 6).
        let kinds = [f.kind(), t.kind()];
        let matched_stretch =
            kinds.contains(&StateKind::Matched) && kinds.contains(&StateKind::Stretch);
        let on_one_axis = matched_stretch
            && mmic::motion::geometry::faces(f).0.axis == mmic::motion::geometry::faces(t).1.axis;
        assert_eq!(p.number() <= 4, on_one_axis, "{f} -> {t} by {p}");
    }
    // Every primitive is used.
    for p in Primitive::ALL {
        assert!(moves.iter().any(|m| m.2 == p), "{p} unused");
    }
}

/// Floyd–Warshall over the map: the oracle.
fn all_pairs() -> [[u32; 15]; 15] {
    let inf = 99;
    let mut d = [[inf; 15]; 15];
    for i in 0..15 {
        d[i][i] = 0;
    }
    for (f, t, _) in map::moves() {
        d[f.index()][t.index()] = 1;
    }
    for k in 0..15 {
        for i in 0..15 {
            for j in 0..15 {
                if d[i][k] + d[k][j] < d[i][j] {
                    d[i][j] = d[i][k] + d[k][j];
                }
            }
        }
    }
    d
}

/// Every shortest state sequence from `f` to `t`, by brute force.
fn all_shortest(f: State, t: State, len: u32) -> Vec<Vec<State>> {
    let mut out = Vec::new();
    let mut stack = vec![(f, Vec::new())];
    while let Some((at, path)) = stack.pop() {
        if path.len() as u32 == len {
            if at == t {
                out.push(path);
            }
            continue;
        }
        for (a, b, _) in map::moves() {
            if a == at {
                let mut p = path.clone();
                p.push(b);
                stack.push((b, p));
            }
        }
    }
    out
}

#[test]
fn plans_are_valid_shortest_tie_broken_and_table_equals_search() {
    let d = all_pairs();
    let mut histogram = [0u32; 4];
    let mut matched = [0u32; 4];
    for f in State::ALL {
        for t in State::ALL {
            let p = route::lookup(f, t);
            assert_eq!(
                route::search(f, t),
                p,
                "{f} -> {t}: table and search disagree"
            );
            assert_eq!(
                p.len() as u32,
                d[f.index()][t.index()],
                "{f} -> {t}: not shortest"
            );
            let mut at = f;
            for (k, prim) in p.primitives().iter().enumerate() {
                let next = p.states()[k];
                assert_eq!(
                    map::primitive(at, next),
                    Some(*prim),
                    "{f} -> {t}: step {k} invalid"
                );
                at = next;
            }
            assert_eq!(at, t);
            if f != t {
                let best = all_shortest(f, t, p.len() as u32)
                    .into_iter()
                    .min()
                    .unwrap();
                assert_eq!(p.states(), &best[..], "{f} -> {t}: tie-break");
                histogram[p.len()] += 1;
                if f.is_matched() && t.is_matched() {
                    matched[p.len()] += 1;
                }
            }
        }
    }
    assert_eq!(
        histogram,
        [0, 72, 126, 12],
        "plan lengths over the 210 ordered pairs"
    );
    assert_eq!(
        matched,
        [0, 0, 18, 12],
        "plan lengths between the 30 ordered pairs of matched states"
    );
    assert_eq!(route::TABLE_BYTES, 450);
}

#[test]
fn rendered_grid_is_current_in_spec() {
    let mut grid = String::new();
    map::render(&mut grid).unwrap();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/spec/motion/map.txt");
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &grid).unwrap();
        return;
    }
    assert_eq!(on_disk, grid, "spec/motion/map.txt is stale; regenerate with: MMIC_REGENERATE=1 cargo test --test motion motion_map");
    // 72 move cells, 15 diagonal cells; the asterisks are exactly the moves no matched plan uses.
    let used = map::moves()
        .filter(|(f, t, _)| map::used_between_matched(*f, *t))
        .count();
    assert_eq!(grid.matches('*').count(), 72 - used);
}
