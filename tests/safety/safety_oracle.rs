//! Random event sequences: the supervisor against a small oracle written directly from
//! spec/modes.toml (its tables drive the oracle; src/safety/policy.rs is not used here).

use mmic::arbitrary::for_each_variant_class;
use mmic::command::{Command, PowerTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::estimate::InitialStateError;
use mmic::refusal::Refusal;
use mmic::safety::supervisor::{Answer, Incoming, Input, Supervisor};
use mmic::units::{HipAngle, Module, PulseWidth, Side};
use proptest::prelude::*;

use crate::common;
use std::collections::{BTreeMap, BTreeSet};

#[derive(serde::Deserialize)]
struct Spec {
    accepts: BTreeMap<String, Vec<String>>,
    power: BTreeMap<String, toml::Value>,
    fault: Vec<FaultRow>,
}

#[derive(serde::Deserialize)]
struct FaultRow {
    name: String,
    mode: String,
    deferred: bool,
    kind: String,
}

fn spec() -> Spec {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/spec/modes.toml");
    toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn module_name(m: Module) -> String {
    format!("{m:?}").chars().fold(String::new(), |mut s, c| {
        if c.is_uppercase() && !s.is_empty() {
            s.push('_');
        }
        s.push(c.to_ascii_lowercase());
        s
    })
}

/// The oracle: the rules of spec/modes.toml, one by one.
struct Oracle {
    spec: Spec,
    mode: &'static str,
    enabled: BTreeSet<String>,
    latched: BTreeSet<String>,
    pending: bool,
    stopped: bool,
}

fn mode_name(m: Mode) -> &'static str {
    m.name()
}

impl Oracle {
    fn new() -> Oracle {
        let all = Module::ALL.iter().map(|m| module_name(*m)).collect();
        Oracle {
            spec: spec(),
            mode: "standby",
            enabled: all,
            latched: BTreeSet::new(),
            pending: false,
            stopped: false,
        }
    }

    fn row(&self, name: &str) -> &FaultRow {
        self.spec.fault.iter().find(|r| r.name == name).unwrap()
    }

    fn go(&mut self, mode: &'static str) {
        if mode != "operational" {
            self.pending = false;
        }
        if mode != self.mode {
            // [rules] paused: any mode change drops the paused motion.
            self.stopped = false;
        }
        self.mode = mode;
    }

    fn raise(&mut self, faults: &BTreeSet<String>, in_motion: bool) {
        self.latched.extend(faults.iter().cloned());
        if self.mode != "operational" || faults.is_empty() {
            return;
        }
        let rows: Vec<&FaultRow> = faults.iter().map(|f| self.row(f)).collect();
        if rows.iter().any(|r| r.mode == "safed") {
            self.go("safed");
        } else if rows.iter().any(|r| r.mode == "standby" && !r.deferred) || !in_motion {
            // An immediate Standby fault, or a deferred one with no motion running.
            self.go("standby");
        } else {
            self.pending = true;
        }
    }

    fn powered(&self) -> BTreeSet<String> {
        let allowed: BTreeSet<String> = self.spec.power[self.mode]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        self.enabled.intersection(&allowed).cloned().collect()
    }

    fn step(
        &mut self,
        faults: &BTreeSet<String>,
        c: Option<Incoming>,
        in_motion: bool,
        hip: bool,
        init: Option<&str>,
    ) -> (Option<Answer>, bool) {
        let mut go_home = false;
        let mode_before = self.mode;
        self.raise(faults, in_motion);
        if self.pending && !in_motion && self.mode == "operational" {
            self.go("standby");
        }
        let answer = c.map(|inc| {
            let cm = match inc {
                Incoming::Malformed(r) => return Answer::Refused(r),
                Incoming::Command(cm) => cm,
            };
            let kind = cm.kind().name();
            if !self.spec.accepts[self.mode].iter().any(|k| k == kind) {
                return Answer::Refused(Refusal::NotAllowedInMode);
            }
            let moving = [
                "arm",
                "gripper",
                "hip",
                "bolter",
                "primitive",
                "reconfiguration",
            ]
            .contains(&kind);
            if self.stopped && moving {
                return Answer::Refused(Refusal::Stopped);
            }
            match cm {
                // [rules] stop: a motion in progress is kept until Reset.
                // (A fault that changed the mode this tick already ended the motion.)
                Command::Stop => {
                    self.stopped |= in_motion && self.mode != "standby" && self.mode == mode_before
                }
                // [rules] reset: refused with nothing to resume.
                Command::Reset if !self.stopped => {
                    return Answer::Refused(Refusal::NothingToResume)
                }
                Command::Reset => self.stopped = false,
                Command::SystemFault => {
                    self.raise(&["assembly_system".to_string()].into(), in_motion)
                }
                Command::ClearFaults => self.latched.retain(|f| faults.contains(f)),
                Command::Mode(Mode::Operational) if self.mode != "operational" => {
                    if faults.iter().any(|f| self.row(f).kind == "condition") {
                        return Answer::Refused(Refusal::FaultConditionHolds);
                    }
                    self.go("operational");
                    self.enabled = Module::ALL.iter().map(|m| module_name(*m)).collect();
                    if hip {
                        go_home = true;
                    } else {
                        self.raise(&["hip_mismatch".to_string()].into(), in_motion);
                    }
                }
                Command::Mode(m) => self.go(mode_name(m)),
                // The Table 8 fault a reconfiguration met on arrival, latched, and the refusal
                // of the same name.
                Command::Reconfigure(_) if init.is_some() => {
                    let f = init.unwrap_or_default();
                    self.raise(&[f.to_string()].into(), in_motion);
                    let r = Refusal::ALL.into_iter().find(|r| r.name() == f);
                    return Answer::Refused(r.expect("a refusal named after the fault"));
                }
                Command::Power { target, on } => {
                    let names: Vec<String> = match target {
                        PowerTarget::All => Module::ALL.iter().map(|m| module_name(*m)).collect(),
                        PowerTarget::Module(m) => vec![module_name(m)],
                    };
                    for n in names {
                        if on {
                            self.enabled.insert(n);
                        } else {
                            self.enabled.remove(&n);
                        }
                    }
                }
                _ => {}
            }
            Answer::Accepted(cm)
        });
        (answer, go_home)
    }
}

fn commands() -> Vec<Option<Incoming>> {
    let mut v = vec![
        None,
        None,
        None,
        Some(Incoming::Malformed(Refusal::UnknownCommand)),
    ];
    for_each_variant_class(PulseWidth::CENTER, HipAngle::new(9000).unwrap(), |c| {
        v.push(Some(Incoming::Command(c)))
    });
    // Weight mode changes up so that sequences visit every mode often.
    for m in Mode::ALL {
        for _ in 0..6 {
            v.push(Some(Incoming::Command(Command::Mode(m))));
        }
    }
    v
}

/// A reconfiguration's check on arrival, by the fault it meets (spec/modes.toml names): mostly
/// none.
const INIT: [Option<&str>; 5] = [
    None,
    None,
    None,
    Some("initial_state_mismatch"),
    Some("arm_not_contracted"),
];

proptest! {
    #![proptest_config(common::prop::config(2000))]

    // req: T7/*, T8/*
    #[test]
    fn supervisor_agrees_with_the_spec_oracle(
        seq in prop::collection::vec((any::<u16>(), any::<prop::sample::Index>(), any::<bool>(), prop::bool::weighted(0.9), prop::sample::select(INIT.to_vec()), prop::bool::weighted(0.15)), 1..60)
    ) {
        let cmds = commands();
        let mut sut = Supervisor::new();
        let mut oracle = Oracle::new();
        for (raw, idx, in_motion, hip, init, faulty) in seq {
            // Faults are rare: mostly none, sometimes a random subset.
            let raw = if faulty { raw & Faults::DEFINED as u16 } else { 0 };
            let faults = Faults::from_wire([raw as u8, (raw >> 8) as u8]).unwrap();
            let names: BTreeSet<String> = faults.iter().map(|f| f.name().to_string()).collect();
            let c = *idx.get(&cmds);
            let initial_state = match init {
                None => Ok(()),
                Some("arm_not_contracted") => Err(InitialStateError::ArmNotContracted(Side::A)),
                Some(_) => Err(InitialStateError::Mismatch),
            };
            let out = sut.step(&Input { faults, command: c, in_motion, hip_at_home: hip, initial_state });
            let (answer, go_home) = oracle.step(&names, c, in_motion, hip, init);
            prop_assert_eq!(out.mode.name(), oracle.mode);
            prop_assert_eq!(out.answer, answer);
            prop_assert_eq!(out.go_home, go_home);
            prop_assert_eq!(out.standby_pending, oracle.pending);
            let latched: BTreeSet<String> = out.faults.iter().map(|f| f.name().to_string()).collect();
            prop_assert_eq!(latched, oracle.latched.clone());
            let powered: BTreeSet<String> = out.powered.iter().map(module_name).collect();
            prop_assert_eq!(powered, oracle.powered());
        }
    }
}

// req: P7.8
#[test]
fn oracle_module_names_match_spec() {
    let names: Vec<String> = Module::ALL.iter().map(|m| module_name(*m)).collect();
    assert_eq!(
        names,
        [
            "hip",
            "arm_a",
            "arm_b",
            "gripper_a",
            "gripper_b",
            "bolter_a",
            "bolter_b"
        ]
    );
    assert_eq!(Fault::ALL.len(), spec().fault.len());
}
