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

/// The moves the robot can make, decided here from the joints, not from the library's rule:
/// the moving arm turns from `u` to `v` about `u × v`, and the only rotary joint, the hip, turns
/// about an axis perpendicular to the holding arm `w` (the hip axis is perpendicular to both
/// arms). So a move is the robot's when it is straight (`u × v = 0`) or `(u × v) · w = 0`.
pub(crate) fn robot_moves_oracle() -> Vec<(State, State, Primitive)> {
    use mmic::motion::geometry::{arm_direction, cross, model_moves};
    model_moves()
        .filter(|&(f, t, side, _)| {
            let hold = if side == Side::A { Side::B } else { Side::A };
            let axis = cross(arm_direction(f, side), arm_direction(t, side));
            let w = arm_direction(f, hold);
            (0..3)
                .map(|i| i32::from(axis[i]) * i32::from(w[i]))
                .sum::<i32>()
                == 0
        })
        .map(|(f, t, _, p)| (f, t, p))
        .collect()
}

// req: P6.9
#[test]
fn sixty_moves_each_with_its_inverse() {
    let moves: Vec<_> = map::moves().collect();
    assert_eq!(moves.len(), 60);
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

/// Table 6's caption: the turns "include a rotation of the hip". The model's 72 moves include
/// 12 turns between two right-angle states (e↔f, e↔k, f↔i, g↔i, g↔j, j↔k), in which the moving
/// arm would turn about the holding arm; the map is exactly the model's moves the joints make.
// req: P6.9
#[test]
fn the_map_is_the_models_moves_the_hip_can_make() {
    use mmic::motion::geometry::{model_moves, turns_without_hip};
    let oracle = robot_moves_oracle();
    assert_eq!(map::moves().collect::<Vec<_>>(), oracle);
    let hipless: Vec<(char, char)> = model_moves()
        .filter(|&(f, t, _, p)| !oracle.contains(&(f, t, p)))
        .map(|(f, t, _, _)| (f.letter(), t.letter()))
        .collect();
    let mut expected = vec![];
    for (x, y) in [
        ('e', 'f'),
        ('e', 'k'),
        ('f', 'i'),
        ('g', 'i'),
        ('g', 'j'),
        ('j', 'k'),
    ] {
        expected.extend([(x, y), (y, x)]);
    }
    expected.sort();
    assert_eq!(hipless, expected);
    for (f, t, _, p) in model_moves() {
        let robot = oracle.contains(&(f, t, p));
        assert_eq!(turns_without_hip(f, t), !robot, "{f} -> {t}");
        assert_eq!(
            mmic::motion::geometry::robot_move(f, t).is_some(),
            robot,
            "{f} -> {t}"
        );
        // Every turn the robot makes has arms in line at one end: the hip turns between 180°
        // and a right angle.
        if robot && p.number() >= 5 {
            assert!(f.kind() != StateKind::Turn || t.kind() != StateKind::Turn);
        }
    }
}

/// Section 6: moves between matched and stretched states use primitives 1-4, moves from or to a
/// turn state primitives 4-8 (the paper's ranges, which share 4).
// req: P6.7
#[test]
fn straight_moves_use_primitives_1_to_4_and_turns_4_to_8() {
    let mut seen = [0u32; 2];
    for (from, to, p) in map::moves() {
        let turn = from.kind() == StateKind::Turn || to.kind() == StateKind::Turn;
        let range = if turn { 4..=8 } else { 1..=4 };
        assert!(range.contains(&p.number()), "{from} -> {to} by {p}");
        seen[usize::from(turn)] += 1;
    }
    assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
}

/// Floyd–Warshall over the moves the joints make ([`robot_moves_oracle`]): the oracle.
fn all_pairs() -> [[u32; 15]; 15] {
    let inf = 99;
    let mut d = [[inf; 15]; 15];
    for i in 0..15 {
        d[i][i] = 0;
    }
    for (f, t, _) in robot_moves_oracle() {
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

/// Every shortest state sequence from `f` to `t`, by brute force over the oracle's moves.
fn all_shortest(f: State, t: State, len: u32) -> Vec<Vec<State>> {
    let moves = robot_moves_oracle();
    let mut out = Vec::new();
    let mut stack = vec![(f, Vec::new())];
    while let Some((at, path)) = stack.pop() {
        if path.len() as u32 == len {
            if at == t {
                out.push(path);
            }
            continue;
        }
        for &(a, b, _) in &moves {
            if a == at {
                let mut p = path.clone();
                p.push(b);
                stack.push((b, p));
            }
        }
    }
    out
}

// req: P6.10, P6.11, P6.4
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
                assert!(
                    !mmic::motion::geometry::turns_without_hip(at, next),
                    "{f} -> {t}: step {k} turns without the hip"
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
        [0, 60, 102, 48],
        "plan lengths over the 210 ordered pairs"
    );
    // Four plans between matched states took a turn without the hip while the map had those
    // moves (g -> j in b -> c, j -> g in c -> b, e -> f in n -> o, f -> e in o -> n); each has
    // a plan of the same length the robot can make.
    for (f, t) in [
        (State::B, State::C),
        (State::C, State::B),
        (State::N, State::O),
        (State::O, State::N),
    ] {
        assert_eq!(route::lookup(f, t).len(), 3, "{f} -> {t}");
    }
    assert_eq!(
        matched,
        [0, 0, 18, 12],
        "plan lengths between the 30 ordered pairs of matched states"
    );
    assert_eq!(route::TABLE_BYTES, 450);
}

// req: P6.9, P6.10
#[test]
fn rendered_grid_is_current_in_spec() {
    let mut grid = String::new();
    mmic::motion::figure9::render(&mut grid).unwrap();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/spec/motion/map.txt");
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &grid).unwrap();
        return;
    }
    assert_eq!(on_disk, grid, "spec/motion/map.txt is stale; regenerate with: MMIC_REGENERATE=1 cargo test -p mmic --test library motion::motion_map");
    // 60 move cells, 15 diagonal cells; the asterisks are exactly the moves no matched plan uses.
    let used = map::moves()
        .filter(|(f, t, _)| mmic::motion::figure9::used_between_matched(*f, *t))
        .count();
    assert_eq!(grid.matches('*').count(), 60 - used);
}

/// The geometric model's single moves computed at run time over all 225 ordered pairs (the
/// map itself is built at compile time, which coverage does not see): 72 moves, the map's 60
/// where the map has them and 12 turns without a hip rotation, each reaching its target.
// req: P6.9
#[test]
fn single_moves_at_run_time_are_the_models_72() {
    let mut model = 0;
    for f in State::ALL {
        for t in State::ALL {
            let m = single_move(f, t);
            if let Some((_, p)) = m {
                model += 1;
                assert!(map::reaches(p, t), "{f} -> {t} by {p}");
            }
            if let Some(p) = map::primitive(f, t) {
                assert_eq!(m.map(|(_, q)| q), Some(p), "{f} -> {t}");
            }
        }
    }
    assert_eq!(model, 72);
}

/// A writer that takes `room` octets, then fails (a full buffer, a closed console).
struct Fails {
    room: usize,
    got: String,
}

impl std::fmt::Write for Fails {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        if s.len() > self.room {
            return Err(std::fmt::Error);
        }
        self.room -= s.len();
        self.got.push_str(s);
        Ok(())
    }
}

/// The legend names every primitive by its Table 6 name, and a writer's failure at any octet
/// of the grid or the legend is the caller's error, never a shorter text reported as whole.
// req: P6.9
#[test]
fn legend_names_the_primitives_and_a_failing_writer_is_an_error() {
    use mmic::motion::figure9::{render, write_legend};
    let mut legend = String::new();
    write_legend(&mut legend).unwrap();
    for p in Primitive::ALL {
        assert!(
            legend.contains(&format!(" {} {}", p.number(), p.name())),
            "{legend}"
        );
    }
    assert!(legend.ends_with('\n'));
    let mut grid = String::new();
    render(&mut grid).unwrap();
    type Write = fn(&mut Fails) -> std::fmt::Result;
    for (name, whole, write) in [
        ("legend", legend.len(), (|w| write_legend(w)) as Write),
        ("grid", grid.len(), (|w| render(w)) as Write),
    ] {
        for room in 0..whole {
            let mut w = Fails {
                room,
                got: String::new(),
            };
            assert_eq!(write(&mut w), Err(std::fmt::Error), "{name}, room {room}");
        }
        let mut w = Fails {
            room: whole,
            got: String::new(),
        };
        assert_eq!(write(&mut w), Ok(()), "{name}");
        assert_eq!(w.got.len(), whole);
    }
}

/// spec/motion/ambiguous-primitives.txt: the (state, primitive) pairs with two targets.
fn render_ambiguous() -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "# (state, primitive) pairs whose primitive reaches two states in the reconfiguration map\n\
         # (Figure 9 as derived in spec/motion/model.md): the primitive number alone does not say\n\
         # which move is meant, so a primitive command carries its final state (command packet\n\
         # byte 8; spec/decisions.toml: primitive-final-state). Rows in Table 5, then Table 6 order.\n\
         # Generated by tests/motion/motion_map.rs from src/pose/map.rs; regenerate:\n\
         # MMIC_REGENERATE=1 cargo test -p mmic --test library motion::motion_map\n\
         #\n\
         # from               primitive      targets\n",
    );
    for (from, p, first, second) in map::ambiguous() {
        let _ = writeln!(
            s,
            "{:<20} {:<14} {first}, {second}",
            from.to_string(),
            p.to_string()
        );
    }
    s
}

// req: D:primitive-final-state
#[test]
fn ambiguous_primitives_are_published_and_each_is_a_match_or_a_stretch() {
    let text = render_ambiguous();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/spec/motion/ambiguous-primitives.txt"
    );
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic --test library motion::motion_map"
    );
    let pairs: Vec<_> = map::ambiguous().collect();
    assert_eq!(pairs.len(), 12);
    // No pair reaches three states; the list is every pair with two (checked from the map).
    for from in State::ALL {
        for p in Primitive::ALL {
            let to: Vec<State> = map::targets(from, p).collect();
            assert!(to.len() <= 2, "{from} by {p}: {to:?}");
            let listed = pairs.iter().find(|x| x.0 == from && x.1 == p);
            assert_eq!(
                listed.map(|x| vec![x.2, x.3]),
                (to.len() == 2).then_some(to),
                "{from} by {p}"
            );
        }
    }
    // Two from each turn state, by turn primitives; one target the match on the face the
    // holding side grips, the other the stretch onto the opposite face of that axis.
    for turn in State::ALL
        .into_iter()
        .filter(|s| s.kind() == StateKind::Turn)
    {
        assert_eq!(pairs.iter().filter(|x| x.0 == turn).count(), 2, "{turn}");
    }
    for &(from, p, first, second) in &pairs {
        assert!(p.number() >= 5, "{from} by {p}");
        let kinds = [first.kind(), second.kind()];
        assert!(
            kinds.contains(&StateKind::Matched) && kinds.contains(&StateKind::Stretch),
            "{from} by {p}: {first}, {second}"
        );
        let (side, _) = single_move(from, first).unwrap();
        assert_eq!(single_move(from, second).unwrap().0, side);
    }
}

/// The two readings of "The 'fwd' and 'back' in the primitive naming refers to towards which
/// side, A - fwd, B - back, the motion happens" (spec/decisions.toml: fwd-back-reading), applied
/// to the same 72 moves: (a) the side that moves (the model), (b) the direction of travel, fwd
/// when the moving gripper's displacement points towards A's end (along A's arm in the initial
/// state). The numbers below are the decision's evidence.
// req: P6.8
#[test]
fn fwd_back_readings_compared_on_every_move() {
    use mmic::motion::geometry::{arm_direction, faces, unit};
    let mut differ = 0;
    let (mut extensions_agree, mut contractions_differ) = (0, 0);
    let mut no_direction = Vec::new();
    let mut sides_of_turn_name_b = std::collections::BTreeMap::new();
    // Under (b): (from, fwd, straight, ccw), i.e. the Table 6 name, -> the states it reaches.
    let mut ends_b: std::collections::BTreeMap<(State, bool, bool, bool), Vec<State>> =
        Default::default();
    for (from, to, _, p) in mmic::motion::geometry::model_moves() {
        let (side, _) = single_move(from, to).unwrap();
        let pick = |s: State| match side {
            Side::A => faces(s).0,
            Side::B => faces(s).1,
        };
        let (f0, f1) = (pick(from), pick(to));
        let (u0, u1) = (unit(f0.axis, f0.sign), unit(f1.axis, f1.sign));
        let a = arm_direction(from, Side::A);
        let along_a: i32 = (0..3).map(|i| i32::from((u1[i] - u0[i]) * a[i])).sum();
        let fwd_a = side == Side::A;
        if along_a == 0 {
            // The gripper travels across the robot's axis: reading (b) names no direction.
            assert!(from.kind() == StateKind::Turn && to.kind() == StateKind::Turn);
            no_direction.push((from, to));
            continue;
        }
        let fwd_b = along_a > 0;
        differ += usize::from(fwd_a != fwd_b);
        match p.number() {
            3 | 4 => extensions_agree += usize::from(fwd_a == fwd_b),
            1 | 2 => contractions_differ += usize::from(fwd_a != fwd_b),
            _ => {
                sides_of_turn_name_b
                    .entry((fwd_b, p.name().ends_with("CCW")))
                    .or_insert_with(std::collections::BTreeSet::new)
                    .insert(side == Side::A);
            }
        }
        let straight = p.number() <= 4;
        let ccw = p.name().ends_with("CCW");
        ends_b
            .entry((from, fwd_b, straight, ccw && !straight))
            .or_default()
            .push(to);
    }
    // Extensions agree (the moving side leads), contractions swap 1 <-> 2 (the moving side
    // trails), and most turns change name.
    assert_eq!((extensions_agree, contractions_differ), (6, 6));
    assert_eq!(no_direction.len(), 6);
    assert_eq!(differ, 42, "of the 66 moves reading (b) names");
    // Under (b) a turn's name no longer says which side moves: each of fwdTurn/backTurn,
    // CW/CCW is done by side A in some moves and by side B in others.
    assert_eq!(sides_of_turn_name_b.len(), 4);
    assert!(sides_of_turn_name_b.values().all(|sides| sides.len() == 2));
    // And the ambiguity stays: 12 (state, name) pairs reach two states under (b) as well.
    assert_eq!(ends_b.values().filter(|to| to.len() == 2).count(), 12);
    assert!(ends_b.values().all(|to| to.len() <= 2));
}
