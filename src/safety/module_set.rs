//! A set of modules, for power switching.
// req: P7.3, P7.8

use crate::units::Module;

/// A set of [`Module`]s (bit i = `Module::ALL[i]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModuleSet(u8);

impl ModuleSet {
    /// No module.
    pub const EMPTY: ModuleSet = ModuleSet(0);
    /// Every module.
    pub const ALL: ModuleSet = ModuleSet(0x7f);
    /// What Safed mode may power: the hip and both arms (Table 7: "hold hip/arms position only").
    pub const HIP_AND_ARMS: ModuleSet =
        ModuleSet(1 << Module::Hip.index() | 1 << Module::ArmA.index() | 1 << Module::ArmB.index());

    /// The set plus `m`.
    pub const fn with(self, m: Module) -> ModuleSet {
        ModuleSet(self.0 | 1 << m.index())
    }

    /// The set minus `m`.
    pub const fn without(self, m: Module) -> ModuleSet {
        ModuleSet(self.0 & !(1 << m.index()))
    }

    /// Whether `m` is in the set.
    pub const fn contains(self, m: Module) -> bool {
        self.0 & 1 << m.index() != 0
    }

    /// Intersection.
    pub const fn intersect(self, o: ModuleSet) -> ModuleSet {
        ModuleSet(self.0 & o.0)
    }

    /// Whether every module of `self` is in `o`.
    pub const fn is_subset(self, o: ModuleSet) -> bool {
        self.0 & !o.0 == 0
    }

    /// Whether the set is empty.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Raw bits (bit i = `Module::ALL[i]`).
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Set from raw bits; bit 7 is ignored.
    pub const fn from_bits(b: u8) -> ModuleSet {
        ModuleSet(b & 0x7f)
    }

    /// The modules in the set.
    pub fn iter(self) -> impl Iterator<Item = Module> {
        Module::ALL.into_iter().filter(move |m| self.contains(*m))
    }
}

#[cfg(test)]
mod tests {
    use super::ModuleSet;
    use crate::units::Module;

    /// Every set against its members: bits, from_bits (the 8th bit dropped), subset,
    /// intersection, with/without, and the hip-and-arms constant.
    // req: P7.8
    #[test]
    fn every_set_agrees_with_its_members() {
        let members = |s: ModuleSet| Module::ALL.map(|m| s.contains(m));
        // Every pair of sets. Under Miri (.ci/miri), some 100x slower, every 15th byte (0, 15,
        // …, 255: the 8th bit set and clear) against every 9th set (0, 9, …, 126): 18 × 15 pairs.
        #[cfg(miri)]
        let (step_b, step_c) = (15, 9);
        #[cfg(not(miri))]
        let (step_b, step_c) = (1, 1);
        for b in (0..=u8::MAX).step_by(step_b) {
            let s = ModuleSet::from_bits(b);
            assert_eq!(s.bits(), b & 0x7f);
            for (i, m) in Module::ALL.into_iter().enumerate() {
                assert_eq!(s.contains(m), b & (1 << i) != 0);
                assert!(s.with(m).contains(m) && !s.without(m).contains(m));
            }
            assert_eq!(s.is_empty(), b & 0x7f == 0);
            for c in (0..0x80u8).step_by(step_c) {
                let o = ModuleSet::from_bits(c);
                let subset = members(s).iter().zip(members(o)).all(|(x, y)| !x || y);
                assert_eq!(s.is_subset(o), subset, "{b:#x} {c:#x}");
                assert_eq!(s.intersect(o).bits(), b & c & 0x7f);
            }
        }
        let hip_and_arms = [Module::Hip, Module::ArmA, Module::ArmB];
        for m in Module::ALL {
            assert_eq!(
                ModuleSet::HIP_AND_ARMS.contains(m),
                hip_and_arms.contains(&m)
            );
        }
        assert_eq!(ModuleSet::ALL.iter().count(), 7);
    }
}
