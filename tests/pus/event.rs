//! ST\[5\] events: `Event::parse` reads back exactly what `Event::to_bytes` writes, in the
//! event's severity, and refuses everything else by name.
//!
//! The domain is enumerated: every event the gateway can report (every fault in every mode,
//! every mode change, every pair × attempt × result, every non-empty cleared fault map), and
//! every one-octet change of each event that is not a cleared map (so every ID, every mode,
//! pair, attempt and result byte, every padding octet) in every subservice 0..=255.

use mmic::bolter::BolterPair;
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::pus::event::{AttemptResult, Event, EventError, EVENT_LEN};

const RESULTS: [AttemptResult; 4] = [
    AttemptResult::Done,
    AttemptResult::Failed,
    AttemptResult::GaveUp,
    AttemptResult::Interrupted,
];

/// Every event but the cleared maps.
fn events() -> Vec<Event> {
    let mut v = Vec::new();
    for fault in Fault::ALL {
        for mode in Mode::ALL {
            v.push(Event::Fault { fault, mode });
        }
    }
    for from in Mode::ALL {
        for to in Mode::ALL {
            v.push(Event::ModeChanged { from, to });
        }
    }
    for board in [1u8, 2, 255] {
        for reason in 0..mmic::pus::event::LINK_STOPPED_REASONS.len() as u8 {
            v.push(Event::LinkStopped { board, reason });
        }
    }
    for pair in BolterPair::ALL {
        for attempt in 1..=3 {
            for result in RESULTS {
                v.push(Event::Attempt {
                    pair,
                    attempt,
                    result,
                });
            }
        }
    }
    v
}

// req: PUS/ST[5].1, PUS/ST[5].2, PUS/ST[5].3, PUS/ST[5].4
#[test]
fn every_event_round_trips_in_its_severity_only() {
    let cleared = (1..=Faults::DEFINED).map(|bits| {
        let f = Faults::from_wire((bits as u16).to_le_bytes()).expect("defined bits");
        Event::Cleared(f)
    });
    let mut n = 0;
    for e in events().into_iter().chain(cleared) {
        let b = e.to_bytes();
        for s in 0..=255u8 {
            let got = Event::parse(s, &b);
            if s == e.severity() {
                assert_eq!(got, Ok(e));
            } else {
                assert!(got.is_err(), "{e:?} accepted as TM(5,{s})");
            }
        }
        n += 1;
    }
    assert_eq!(n, 15 * 3 + 9 + 3 * 7 + 4 * 3 * 4 + 32_767);
}

#[test]
fn every_one_octet_change_is_refused_or_is_exactly_another_event() {
    let (mut accepted, mut refused) = (0u32, 0u32);
    for e in events() {
        let b = e.to_bytes();
        for i in 0..EVENT_LEN {
            for v in 0..=255u8 {
                let mut c = b;
                c[i] = v;
                for s in 1..=4u8 {
                    match Event::parse(s, &c) {
                        Ok(x) => {
                            assert_eq!((x.to_bytes(), x.severity()), (c, s), "{c:02x?}");
                            accepted += 1;
                        }
                        Err(_) => refused += 1,
                    }
                }
            }
        }
    }
    // Both happen: a test that only ever refuses (or accepts) would say nothing.
    assert!(
        accepted > 1_000 && refused > 100_000,
        "{accepted} {refused}"
    );
}

#[test]
fn refusals_name_the_check() {
    let mode = Event::ModeChanged {
        from: Mode::Standby,
        to: Mode::Operational,
    };
    let b = mode.to_bytes();
    assert_eq!(Event::parse(5, &b), Err(EventError::Subservice(5)));
    assert_eq!(
        Event::parse(1, &b[..5]),
        Err(EventError::Length {
            expected: 6,
            found: 5
        })
    );
    assert_eq!(
        Event::parse(1, &[0, 9, 0, 0, 0, 0]),
        Err(EventError::UnknownId(9))
    );
    // Bit 15 names no fault.
    assert_eq!(
        Event::parse(4, &[1, 15, 1, 0, 0, 0]),
        Err(EventError::UnknownId(0x010F))
    );
    assert_eq!(
        Event::parse(1, &[0, 1, b[2], 7, 0, 0]),
        Err(EventError::Field {
            id: 1,
            field: "to",
            found: 7
        })
    );
    assert_eq!(
        Event::parse(1, &[0, 1, b[2], b[3], 0, 1]),
        Err(EventError::Padding { id: 1 })
    );
    assert_eq!(
        Event::parse(4, &[0, 5, 0, 1, 0, 0]),
        Err(EventError::Field {
            id: 5,
            field: "board",
            found: 0
        })
    );
    assert_eq!(
        Event::parse(4, &[0, 5, 1, 7, 0, 0]),
        Err(EventError::Field {
            id: 5,
            field: "reason",
            found: 7
        })
    );
    assert_eq!(
        Event::parse(1, &[0, 2, 1, 4, 0, 0]),
        Err(EventError::Field {
            id: 2,
            field: "attempt",
            found: 4
        })
    );
    assert_eq!(
        Event::parse(1, &[0, 3, 0, 0, 0, 0]),
        Err(EventError::Field {
            id: 3,
            field: "faults",
            found: 0
        })
    );
}

/// A security event (ID 0x02xx) reads back with its count and SPI, and one whose count of
/// refused frames is 0 is refused by that field's name: the link reports only what it refused.
// req: PUS/ST[5].4
#[test]
fn a_security_event_with_no_refused_frame_is_refused() {
    let e = Event::Security {
        reason: 1,
        refused: 3,
        spi: 0x0101,
    };
    let b = e.to_bytes();
    assert_eq!(Event::parse(e.severity(), &b), Ok(e));
    let mut none = b;
    (none[2], none[3]) = (0, 0);
    assert_eq!(
        Event::parse(e.severity(), &none),
        Err(EventError::Field {
            id: 0x0201,
            field: "refused",
            found: 0
        })
    );
}
