//! Strategies for the CCSDS/PUS headers' own types (the packets' `Repr`s are built from them
//! in the tests of `tests/ccsds/`).

use crate::ccsds::cuc::Cuc;
use crate::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use crate::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};

impl proptest::arbitrary::Arbitrary for AckFlags {
    type Parameters = ();
    type Strategy = proptest::strategy::Map<core::ops::RangeInclusive<u8>, fn(u8) -> AckFlags>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        use proptest::strategy::Strategy;
        (0u8..=15).prop_map(AckFlags::from_bits)
    }
}

impl proptest::arbitrary::Arbitrary for TcSecondaryHeader {
    type Parameters = ();
    type Strategy = proptest::strategy::BoxedStrategy<TcSecondaryHeader>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        use proptest::arbitrary::any;
        use proptest::strategy::Strategy;
        (any::<AckFlags>(), any::<u8>(), any::<u8>(), any::<u16>())
            .prop_map(|(ack, service, subservice, source_id)| TcSecondaryHeader {
                ack,
                service,
                subservice,
                source_id,
            })
            .boxed()
    }
}

impl proptest::arbitrary::Arbitrary for TmSecondaryHeader {
    type Parameters = ();
    type Strategy = proptest::strategy::BoxedStrategy<TmSecondaryHeader>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        use proptest::arbitrary::any;
        use proptest::strategy::Strategy;
        (
            any::<TimeRefStatus>(),
            any::<u8>(),
            any::<u8>(),
            super::wire_u16(),
            any::<u16>(),
            any::<Cuc>(),
        )
            .prop_map(
                |(time_ref_status, service, subservice, counter, destination_id, time)| {
                    TmSecondaryHeader {
                        time_ref_status,
                        service,
                        subservice,
                        counter,
                        destination_id,
                        time,
                    }
                },
            )
            .boxed()
    }
}

impl proptest::arbitrary::Arbitrary for Cuc {
    type Parameters = ();
    type Strategy = proptest::strategy::BoxedStrategy<Cuc>;
    fn arbitrary_with((): ()) -> Self::Strategy {
        use proptest::strategy::Strategy;
        (proptest::arbitrary::any::<u32>(), super::wire_u16())
            .prop_map(|(coarse, fine)| Cuc { coarse, fine })
            .boxed()
    }
}
