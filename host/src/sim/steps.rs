//! The steps a simulation runs: the plan's steps with the line each came from, and the
//! built-in demo plan.

use mmic::node::ground::plan_runner::PlanStep;

/// A step of the plan with where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct SimStep {
    /// Line in the plan file (1-based).
    pub line: usize,
    /// The line's text.
    pub text: String,
    /// The step.
    pub step: PlanStep,
}

/// The built-in demo plan's text (host/plans/demo.plan).
pub const DEMO_PLAN: &str = include_str!("../../plans/demo.plan");

/// The demo plan's steps.
pub fn demo_steps() -> Vec<SimStep> {
    match crate::plan::parse(DEMO_PLAN) {
        Ok(p) => steps_of(&p),
        // The demo is checked by a test; an empty plan here would show up at once.
        Err(_) => Vec::new(),
    }
}

/// A parsed plan's steps for the simulator.
pub fn steps_of(p: &crate::plan::Plan) -> Vec<SimStep> {
    p.steps
        .iter()
        .map(|s| SimStep {
            line: s.line,
            text: s.text.clone(),
            step: match s.action {
                crate::plan::Action::Command(c) => {
                    mmic::node::ground::plan_runner::PlanStep::Command(c)
                }
                crate::plan::Action::Wait { ms } => {
                    mmic::node::ground::plan_runner::PlanStep::Wait { ms }
                }
            },
        })
        .collect()
}
