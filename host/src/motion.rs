//! `mmic plan` and `mmic map`: the motion library's plans and map, as text and JSON.

use crate::error::CliError;
use mmic::motion::{figure9, map, route, State};
use serde::Serialize;

#[derive(Serialize)]
struct PlanJson {
    from: String,
    to: String,
    primitives: Vec<u8>,
}

#[derive(Serialize)]
struct MoveJson {
    from: String,
    to: String,
    primitive: u8,
}

#[derive(Serialize)]
struct MapJson {
    moves: Vec<MoveJson>,
    /// The geometric model's turns between two right-angle states, no moves of the robot.
    turns_without_hip: Vec<MoveJson>,
}

/// A state from its Table 5 letter (either case).
pub fn state(s: &str) -> Result<State, CliError> {
    let mut chars = s.chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) => State::from_letter(c.to_ascii_lowercase()),
        _ => None,
    }
    .ok_or_else(|| CliError::UnknownState {
        text: s.to_string(),
    })
}

/// `{"from":"a","to":"m","primitives":[4,1]}`.
pub fn plan_json(from: State, to: State) -> String {
    let p = route::lookup(from, to);
    let prims: Vec<u8> = p.primitives().iter().map(|p| p.number()).collect();
    let v = PlanJson {
        from: from.letter().to_string(),
        to: to.letter().to_string(),
        primitives: prims,
    };
    serde_json::to_string(&v).unwrap_or_default()
}

/// One line per primitive: number, name, and the state it reaches.
pub fn plan_text(from: State, to: State) -> String {
    let p = route::lookup(from, to);
    let mut s = format!("{from} -> {to}: {} primitive(s)", p.len());
    for (prim, st) in p.primitives().iter().zip(p.states()) {
        s += &format!("\n  {} {:<12} -> {st}", prim.number(), prim.name());
    }
    s
}

/// `{"moves":[{"from":"a","to":"d","primitive":4}, ...],"turns_without_hip":[...]}`: the map's
/// 60 moves, and the model's 12 turns the hip cannot make, in the same form.
pub fn map_json() -> String {
    let json = |(f, t, p): (State, State, mmic::motion::Primitive)| MoveJson {
        from: f.letter().to_string(),
        to: t.letter().to_string(),
        primitive: p.number(),
    };
    let moves = map::moves().map(json).collect();
    let turns_without_hip = mmic::motion::geometry::model_moves()
        .filter(|&(f, t, _, _)| mmic::motion::geometry::turns_without_hip(f, t))
        .map(|(f, t, _, p)| json((f, t, p)))
        .collect();
    serde_json::to_string(&MapJson {
        moves,
        turns_without_hip,
    })
    .unwrap_or_default()
}

/// The Figure 9 grid as text, followed by its legend.
pub fn map_text() -> String {
    let mut s = String::new();
    let _ = figure9::render(&mut s);
    s.push('\n');
    s + &map_legend()
}

/// What the grid's codes mean ([`figure9::write_legend`]).
pub fn map_legend() -> String {
    let mut s = String::new();
    let _ = figure9::write_legend(&mut s);
    s
}
