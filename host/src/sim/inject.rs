//! Fault injection: each of Table 8's ten faults, a sensor that stops answering (the ADC of
//! either side, the hip encoder: the project's sensor loss), and the operator's Stop and
//! Reset, and the restart of a node (board A, board B, the server board, the ground), at a simulated time
//! (`mmic sim --inject NAME@SECONDS`).
//!
//! A fault acts physically where it can, so that the firmware has to detect it the way the
//! robot would: a jammed fastener, a dead contraction switch, an obstacle on a bolter, a
//! gripper or the arm, an encoder that reads off, a sagging battery, a cut A–B line. The rest
//! come from the ground: a reconfiguration command that carries a wrong initial state, and
//! the System fault, Stop and Reset commands of Table 1, sent out of band through the plan
//! runner ([`mmic::node::ground::plan_runner::PlanRunner::interject`]).
//!
//! ```
//! use mmic_host::sim::inject::{Injection, Scheduled};
//! let s: Scheduled = "low-battery@25.5".parse().unwrap();
//! assert_eq!(s.at_ms, 25_500);
//! assert_eq!(s.injection.name(), "low-battery");
//! assert!("low-batery@3".parse::<Scheduled>().unwrap_err().to_string().contains("valid names: bolting-failure, "));
//! assert_eq!(Injection::ALL.len(), 15);
//! assert_eq!("reboot-server@12".parse::<Scheduled>().unwrap().at_ms, 12_000);
//! ```

use super::SimConfig;
use mmic::command::Command;
use mmic::faults::Table8;
use std::str::FromStr;

/// Something `--inject` can do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Injection {
    /// A Table 8 fault, made to happen.
    Fault(Table8),
    /// A sensor stops answering from then on (no Table 8 row: the firmware's sensor loss).
    Silent(Device),
    /// The operator's Stop (Table 1: emergency stop of the current motion), out of band.
    Stop,
    /// The operator's Reset (Table 1: after a stop, resume motion), out of band.
    Reset,
    /// A node of every robot restarts (a power cycle: RAM and RTC memory lost, flash kept;
    /// spec/decisions.toml `restart-*`), down for [`BOOT_MS`].
    Reboot(Node),
}

/// A node that can restart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    /// Board A (keeps its exactly-once log and boot count: decision `restart-board-a`).
    A,
    /// Board B (keeps nothing: decision `restart-board-b`).
    B,
    /// The server board (keeps the gateway's newest TC key per source and the SDLS counters:
    /// decision `restart-server`).
    Server,
    /// The ground (keeps the plan's position and its link's numbering, and with SDLS its
    /// counters: decision `restart-ground`). One ground for every robot of a run.
    Ground,
}

impl Node {
    /// Every node, in the order of the per-node counts (`restarts`).
    pub const ALL: [Node; 4] = [Node::A, Node::B, Node::Server, Node::Ground];
}

/// How long a restarting node is down before its first tick, ms: the ESP32's boot (ROM
/// bootloader, second-stage bootloader, image check, WiFi bring-up on the server board and
/// board A) takes some hundreds of ms.
pub const BOOT_MS: u32 = 300;

/// A sensor that can fall silent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Device {
    /// Side A's ADS7828 (every voltage and current of side A).
    AdcA,
    /// Side B's ADS7828.
    AdcB,
    /// The hip encoder (side A).
    Encoder,
}

impl Injection {
    /// Every injection: Table 8's rows in the table's order, the silent sensors, then Stop
    /// and Reset.
    pub const ALL: [Injection; 15] = [
        Injection::Fault(Table8::BoltingFailure),
        Injection::Fault(Table8::ArmNotContracted),
        Injection::Fault(Table8::BolterOvercurrent),
        Injection::Fault(Table8::GripperOvercurrent),
        Injection::Fault(Table8::LocomotionOvercurrent),
        Injection::Fault(Table8::HipMismatch),
        Injection::Fault(Table8::InitialStateMismatch),
        Injection::Fault(Table8::InternalCommLoss),
        Injection::Fault(Table8::LowBattery),
        Injection::Fault(Table8::AssemblySystem),
        Injection::Silent(Device::AdcA),
        Injection::Silent(Device::AdcB),
        Injection::Silent(Device::Encoder),
        Injection::Stop,
        Injection::Reset,
    ];

    /// The name `--inject` takes and the summary's `faults` use: the Table 8 row's name
    /// (`mmic::faults::Table8::name`) with dashes, as command-line words are spelt.
    pub fn name(self) -> String {
        match self {
            Injection::Fault(r) => r.name().replace('_', "-"),
            Injection::Silent(Device::AdcA) => "adc-a-silent".to_string(),
            Injection::Silent(Device::AdcB) => "adc-b-silent".to_string(),
            Injection::Silent(Device::Encoder) => "encoder-silent".to_string(),
            Injection::Stop => "stop".to_string(),
            Injection::Reset => "reset".to_string(),
            Injection::Reboot(Node::A) => "reboot-a".to_string(),
            Injection::Reboot(Node::B) => "reboot-b".to_string(),
            Injection::Reboot(Node::Server) => "reboot-server".to_string(),
            Injection::Reboot(Node::Ground) => "reboot-ground".to_string(),
        }
    }

    /// The restarts, one per node. Not in [`Injection::ALL`] (the faults the swarm's main
    /// stream draws from): the swarm draws restarts from a stream of their own.
    pub const REBOOTS: [Injection; 4] = [
        Injection::Reboot(Node::A),
        Injection::Reboot(Node::B),
        Injection::Reboot(Node::Server),
        Injection::Reboot(Node::Ground),
    ];

    /// Every valid name, comma-separated (for error messages and `--help`).
    pub fn names() -> String {
        Injection::ALL
            .iter()
            .chain(&Injection::REBOOTS)
            .map(|i| i.name())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// What the simulator does to make it happen.
    pub fn effect(self) -> &'static str {
        match self {
            Injection::Fault(r) => match r {
                Table8::BoltingFailure => "a jammed fastener: from then on no fastener locks",
                Table8::ArmNotContracted => {
                    "arm A's contraction switch dies: from then on it never closes (seen at the next contraction, or when the next reconfiguration arrives)"
                }
                Table8::BolterOvercurrent => {
                    "an obstacle on bolter A: its current rises by 2.6 A for 0.5 s"
                }
                Table8::GripperOvercurrent => {
                    "an obstacle on gripper A: its current jumps to 2.5 A for 0.5 s"
                }
                Table8::LocomotionOvercurrent => {
                    "an obstacle on arm A: its current jumps to 3.5 A for 0.5 s"
                }
                Table8::HipMismatch => {
                    "the hip encoder reads 30 deg off from then on (checked on entering Operational)"
                }
                Table8::InitialStateMismatch => {
                    "the next reconfiguration the ground sends carries a wrong initial state"
                }
                Table8::InternalCommLoss => "the A-B serial line is cut, both ways",
                Table8::LowBattery => "the battery sags below 10 V from then on",
                Table8::AssemblySystem => "the ground sends the System fault command",
            },
            Injection::Silent(Device::AdcA) => {
                "side A's ADC stops answering: sensor loss after 0.5 s (Safed)"
            }
            Injection::Silent(Device::AdcB) => {
                "side B's ADC stops answering: B falls silent, internal comm loss (Safed)"
            }
            Injection::Silent(Device::Encoder) => {
                "the hip encoder stops answering: hip stopped at once, sensor loss after 0.5 s"
            }
            Injection::Stop => "the ground sends Stop",
            Injection::Reset => "the ground sends Reset",
            Injection::Reboot(Node::A) => {
                "board A restarts: down 300 ms, then Standby with its exactly-once log from flash"
            }
            Injection::Reboot(Node::B) => "board B restarts: down 300 ms, then as at power-on",
            Injection::Reboot(Node::Server) => {
                "the server board restarts: down 300 ms, then its gateway with the kept TC keys and SDLS counters"
            }
            Injection::Reboot(Node::Ground) => {
                "the ground restarts: down 300 ms, then the plan from where it stood, numbering past every number given out; a step open at the crash ends the plan"
            }
        }
    }

    /// The command the ground sends out of band for it, if it is one.
    pub fn command(self) -> Option<Command> {
        match self {
            Injection::Fault(Table8::AssemblySystem) => Some(Command::SystemFault),
            Injection::Stop => Some(Command::Stop),
            Injection::Reset => Some(Command::Reset),
            Injection::Fault(_) | Injection::Silent(_) | Injection::Reboot(_) => None,
        }
    }

    /// Whether the ground acts on it (a command out of band, or the next reconfiguration
    /// misstated) rather than the plant or a link.
    pub fn by_ground(self) -> bool {
        self.command().is_some() || self == Injection::Fault(Table8::InitialStateMismatch)
    }
}

impl std::fmt::Display for Injection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

/// An injection at a simulated time: `NAME@SECONDS`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Scheduled {
    /// What.
    pub injection: Injection,
    /// When, simulated ms.
    pub at_ms: u32,
}

/// Why an injection was not taken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InjectError {
    /// No `@` between the name and the time.
    #[error("{text:?}: expected NAME@SECONDS (e.g. low-battery@25), found no '@'")]
    MissingAt {
        /// What was given.
        text: String,
    },
    /// The name is not one of [`Injection::ALL`].
    #[error("unknown injection {name:?} in {text:?}; valid names: {valid}")]
    UnknownName {
        /// The name given.
        name: String,
        /// The whole value.
        text: String,
        /// Every valid name.
        valid: String,
    },
    /// The time is not a number.
    #[error("{seconds:?} in {text:?} is not a number of simulated seconds (e.g. 25 or 12.5)")]
    BadSeconds {
        /// The time given.
        seconds: String,
        /// The whole value.
        text: String,
    },
    /// The time is negative, not finite, or beyond the simulator's u32 millisecond clock.
    #[error("{seconds} s in {text:?} is out of range: 0 to {max} simulated seconds")]
    OutOfRange {
        /// The time given, s.
        seconds: f64,
        /// The whole value.
        text: String,
        /// The largest time, s.
        max: f64,
    },
    /// A plant or link fault given twice: it lasts (or its pulse is) from its one time.
    #[error(
        "{name} is injected twice (at {first_s} s and {second_s} s); it acts once, from its \
         time on (only stop, reset and assembly-system may repeat)"
    )]
    Twice {
        /// The injection.
        name: String,
        /// The first time, s.
        first_s: f64,
        /// The second time, s.
        second_s: f64,
    },
}

impl FromStr for Injection {
    type Err = InjectError;

    fn from_str(name: &str) -> Result<Injection, InjectError> {
        Injection::ALL
            .into_iter()
            .chain(Injection::REBOOTS)
            .find(|i| i.name() == name)
            .ok_or_else(|| InjectError::UnknownName {
                name: name.to_string(),
                text: name.to_string(),
                valid: Injection::names(),
            })
    }
}

impl FromStr for Scheduled {
    type Err = InjectError;

    fn from_str(text: &str) -> Result<Scheduled, InjectError> {
        let (name, seconds) = text
            .rsplit_once('@')
            .ok_or_else(|| InjectError::MissingAt {
                text: text.to_string(),
            })?;
        let injection = name.trim().parse::<Injection>().map_err(|e| match e {
            InjectError::UnknownName { name, valid, .. } => InjectError::UnknownName {
                name,
                text: text.to_string(),
                valid,
            },
            other => other,
        })?;
        let s: f64 = seconds
            .trim()
            .parse()
            .map_err(|_| InjectError::BadSeconds {
                seconds: seconds.to_string(),
                text: text.to_string(),
            })?;
        Scheduled::at_seconds(injection, s)
    }
}

impl Scheduled {
    /// `injection` at `seconds` of simulated time (rounded to the ms); refused when negative,
    /// not finite, or past the simulator's u32 millisecond clock.
    pub fn at_seconds(injection: Injection, seconds: f64) -> Result<Scheduled, InjectError> {
        let max = u32::MAX as f64 / 1000.0;
        if !seconds.is_finite() || !(0.0..=max).contains(&seconds) {
            return Err(InjectError::OutOfRange {
                seconds,
                text: format!("{injection}@{seconds}"),
                max: max.floor(),
            });
        }
        Ok(Scheduled {
            injection,
            at_ms: (seconds * 1000.0).round() as u32,
        })
    }
}

/// Sets `slot` to `at_ms`, refusing a second time for the same injection.
fn once(slot: &mut Option<u32>, s: Scheduled) -> Result<(), InjectError> {
    match *slot {
        Some(first) => Err(InjectError::Twice {
            name: s.injection.name(),
            first_s: first as f64 / 1000.0,
            second_s: s.at_ms as f64 / 1000.0,
        }),
        None => {
            *slot = Some(s.at_ms);
            Ok(())
        }
    }
}

impl SimConfig {
    /// Schedules an injection: a plant or link fault is set in [`SimConfig::plant`] or
    /// [`SimConfig::cut_b_at`] (once each: a second time is refused); every injection is
    /// listed in [`SimConfig::injections`], where the ground acts on its own ones and logs
    /// each as an `inject` event when its time comes.
    pub fn inject(&mut self, s: Scheduled) -> Result<(), InjectError> {
        let p = &mut self.plant;
        match s.injection {
            Injection::Fault(r) => match r {
                Table8::BoltingFailure => once(&mut p.jammed_fastener_at, s)?,
                Table8::ArmNotContracted => once(&mut p.arm_switch_dead_at, s)?,
                Table8::BolterOvercurrent => once(&mut p.bolter_obstacle_at, s)?,
                Table8::GripperOvercurrent => once(&mut p.gripper_obstacle_at, s)?,
                Table8::LocomotionOvercurrent => once(&mut p.overcurrent_at, s)?,
                Table8::HipMismatch => once(&mut p.hip_encoder_offset_at, s)?,
                Table8::InternalCommLoss => once(&mut self.cut_b_at, s)?,
                Table8::LowBattery => once(&mut p.low_battery_at, s)?,
                Table8::InitialStateMismatch | Table8::AssemblySystem => {}
            },
            Injection::Silent(Device::AdcA) => once(&mut p.adc_silent_at[0], s)?,
            Injection::Silent(Device::AdcB) => once(&mut p.adc_silent_at[1], s)?,
            Injection::Silent(Device::Encoder) => once(&mut p.encoder_silent_at, s)?,
            Injection::Stop | Injection::Reset | Injection::Reboot(_) => {}
        }
        self.injections.push(s);
        self.injections.sort_by_key(|s| s.at_ms);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_parses_back_and_names_are_unique() {
        let mut seen = std::collections::BTreeSet::new();
        for i in Injection::ALL {
            assert_eq!(i.name().parse::<Injection>(), Ok(i));
            assert!(seen.insert(i.name()), "{i} twice");
            assert!(!i.effect().is_empty());
        }
        for i in Injection::REBOOTS {
            assert_eq!(i.name().parse::<Injection>(), Ok(i));
            assert!(seen.insert(i.name()), "{i} twice");
            assert!(!Injection::ALL.contains(&i));
        }
        // Every Table 8 row is injectable.
        for r in Table8::ALL {
            assert!(Injection::ALL.contains(&Injection::Fault(r)), "{r}");
        }
    }

    #[test]
    fn bad_values_name_the_bad_part() {
        let e = "stopp@3".parse::<Scheduled>().unwrap_err();
        assert!(matches!(&e, InjectError::UnknownName { name, .. } if name == "stopp"));
        assert!(e.to_string().contains(&Injection::names()), "{e}");
        let e = "stop".parse::<Scheduled>().unwrap_err();
        assert!(matches!(e, InjectError::MissingAt { .. }), "{e}");
        let e = "stop@soon".parse::<Scheduled>().unwrap_err();
        assert!(matches!(&e, InjectError::BadSeconds { seconds, .. } if seconds == "soon"));
        let e = "stop@-1".parse::<Scheduled>().unwrap_err();
        assert!(matches!(e, InjectError::OutOfRange { .. }), "{e}");
        let e = "stop@1e9".parse::<Scheduled>().unwrap_err();
        assert!(matches!(e, InjectError::OutOfRange { .. }), "{e}");
        let ok = "reset@0.25".parse::<Scheduled>().unwrap();
        assert_eq!((ok.injection, ok.at_ms), (Injection::Reset, 250));
    }

    #[test]
    fn plant_faults_are_taken_once_ground_commands_may_repeat() {
        let mut cfg = SimConfig::demo();
        for t in ["low-battery@10", "stop@5", "stop@8", "reset@9"] {
            cfg.inject(t.parse().unwrap()).unwrap();
        }
        assert_eq!(cfg.plant.low_battery_at, Some(10_000));
        let e = cfg.inject("low-battery@20".parse().unwrap()).unwrap_err();
        assert!(matches!(e, InjectError::Twice { .. }), "{e}");
        let times: Vec<u32> = cfg.injections.iter().map(|s| s.at_ms).collect();
        assert_eq!(times, [5_000, 8_000, 9_000, 10_000], "in time order");
    }
}
