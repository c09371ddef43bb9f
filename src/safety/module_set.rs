//! A set of modules, for power switching.

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
        ModuleSet(1 << Module::Hip as u8 | 1 << Module::ArmA as u8 | 1 << Module::ArmB as u8);

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
