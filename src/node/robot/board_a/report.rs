//! What board A reports: the fault conditions it detects each tick (operational and idle
//! overcurrent, low battery, lost link to board B, lost sensors: Table 8) and the heartbeat
//! that answers a command (Table 4).

use super::interface::Inputs;
use super::BoardA;
use crate::faults::{Fault, Faults};
use crate::safety::detect;
use crate::wire::heartbeat::{BolterAttempt, HeartbeatRepr};

impl BoardA {
    /// Section 7's idle check: side A's currents against the at-rest limits, side B as board B
    /// judged its own (Table 4 bytes 38–40).
    pub(super) fn idle_faults(&self, inp: &Inputs) -> Faults {
        let b = detect::Over {
            locomotion: self.b.arm_over_idle,
            gripper: self.b.gripper_over_idle,
            bolter: self.b.bolter_over_idle,
        };
        detect::idle_overcurrent(&self.cfg.safety, &inp.electrical, b)
    }

    /// The fault conditions holding now: operational overcurrent (side A from its currents,
    /// side B as board B judged it: Table 4 bytes 41–43), low battery, lost communication with
    /// board B. The idle overcurrent check is not one: it runs at the start and the end of a
    /// reconfiguration only ([`IdleCheck`]).
    pub(super) fn detect(&mut self, now: u32, inp: &Inputs) -> Faults {
        let e_b = self.b.electrical_b;
        let b_over = detect::Over {
            locomotion: self.b.arm_overcurrent,
            gripper: self.b.gripper_overcurrent,
            bolter: self.b.bolter_overcurrent,
        };
        let mut conditions = Faults::EMPTY;
        if inp.lost.any() {
            conditions = conditions.with(Fault::SensorLoss);
        }
        // Side A's currents and voltages are judged only while the ADC answers: a stale
        // average (or none) says nothing of now, and sensor loss already stops the robot.
        if !inp.lost.adc {
            conditions = conditions.union(detect::operational_overcurrent(
                &self.cfg.safety,
                &inp.electrical,
                b_over,
            ));
            // Side B's battery only once B has reported it (Table 4 bytes 12-13).
            let v_bat_b = self.b_heard.then_some(e_b.v_bat);
            if self
                .battery
                .update(&self.cfg.safety, now, inp.electrical.v_bat, v_bat_b)
            {
                conditions = conditions.with(Fault::LowBattery);
            }
        }
        // Board B restarted: what A had told it is gone (decision `restart-board-b`).
        if self.comm.lost(&self.cfg.safety) || core::mem::take(&mut self.b_restarted) {
            conditions = conditions.with(Fault::InternalCommLoss);
        }
        conditions
    }

    /// The heartbeat answering this tick's command (Table 4): both sides' modules, the
    /// electrical readings, the state, the bolting, the faults and the command's outcome.
    pub(super) fn heartbeat(&self, inp: &Inputs, faults: &Faults) -> HeartbeatRepr {
        let (last_seq, _) = self.log.last();
        let o = self.motion.coord.order();
        HeartbeatRepr {
            board: self.cfg.board,
            hip_target: self.motion.targets.hip,
            hip_now: self.hip_seen,
            arm_a_target: self.arm.target(),
            arm_a_now: self.arm.now(),
            arm_b_target: self.b.arm_b_target,
            arm_b_now: self.b.arm_b_now,
            gripper_a_target: self.gripper.target(),
            gripper_a_now: self.gripper.now(),
            gripper_b_target: self.b.gripper_b_target,
            gripper_b_now: self.b.gripper_b_now,
            electrical_a: inp.electrical,
            electrical_b: self.b.electrical_b,
            target_state: self.target_state,
            command_complete: self.complete,
            active_bolter: o.map(|(_, o)| o.pair),
            bolter_attempt: match (o, BolterAttempt::new(self.motion.coord.attempt())) {
                (Some(_), Ok(a)) => a,
                _ => BolterAttempt::NONE,
            },
            faults: *faults,
            refusal: self.refusal,
            mode: self.sup.mode(),
            last_seq,
            boot: self.boot,
        }
    }
}
