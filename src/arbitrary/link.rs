//! Strategies for the space data link's own value types (the frames' `Repr`s borrow their data
//! and are built from these in the tests of `tests/ccsds/tc_frame.rs`, as the packets' are from
//! the headers' strategies in `ccsds.rs`). The narrow fields (`SpacecraftId`, `Vcid`, `MapId`)
//! get theirs from the `ranged!` macro that declares them.

use crate::link::{ControlCommand, FrameKind};

impl proptest::arbitrary::Arbitrary for FrameKind {
    type Parameters = ();
    type Strategy = proptest::sample::Select<FrameKind>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        proptest::sample::select(&[FrameKind::Ad, FrameKind::Bd, FrameKind::Bc][..])
    }
}

impl proptest::arbitrary::Arbitrary for ControlCommand {
    type Parameters = ();
    type Strategy = proptest::strategy::BoxedStrategy<ControlCommand>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        use proptest::strategy::{Just, Strategy};
        // Each variant with equal weight; V(R) with its bounds over-weighted.
        proptest::prop_oneof![
            Just(ControlCommand::Unlock),
            proptest::prop_oneof![1 => Just(0u8), 1 => Just(255u8), 8 => proptest::arbitrary::any::<u8>()]
                .prop_map(ControlCommand::SetVr),
        ]
        .boxed()
    }
}
