//! CFDP's refusals and faults one by one: each bad PDU, bad file or failing store an entity
//! or a transaction meets, with the error or the condition code it must give, and the
//! emitters' refusals of what a PDU cannot carry.

use mmic::cfdp::codes::{
    ChecksumType, ConditionCode, DirectiveCode, FileStatus, TransactionStatus,
};
use mmic::cfdp::directive::{
    AckRepr, EofRepr, FileDataRepr, FinishedRepr, MetadataRepr, NakRepr, PduRepr, PromptFor,
    Segments,
};
use mmic::cfdp::entity::{
    Config, Entity, Event, FaultHandler, FaultHandlers, Filestore, HandleError, MemoryStore, Put,
    PutError, Receiver, Sender, StoreError, TransactionId,
};
use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
use mmic::cfdp::received::Received;
use mmic::cfdp::tlv::Tlvs;
use mmic::cfdp::PduError;

const ID: TransactionId = TransactionId {
    source: 0x15,
    seq: 9,
};

fn header(mode: Mode) -> PduHeader {
    PduHeader {
        pdu_type: PduType::Directive,
        direction: Direction::TowardReceiver,
        mode,
        crc: false,
        segmentation: false,
        lengths: Lengths::MISSION,
        data_len: 0,
        source: ID.source,
        seq: ID.seq,
        dest: 0x42,
    }
}

fn bytes(repr: &PduRepr<'_>, mode: Mode) -> Vec<u8> {
    let mut out = vec![0u8; 600];
    let n = repr.emit(&header(mode), &mut out).unwrap();
    out.truncate(n);
    out
}

fn metadata(size: u32, checksum: ChecksumType, dest: &[u8]) -> PduRepr<'_> {
    PduRepr::Metadata(MetadataRepr {
        closure_requested: false,
        checksum,
        file_size: size,
        source: b"s",
        dest,
        options: Tlvs::EMPTY,
    })
}

fn data(offset: u32, data: &[u8]) -> PduRepr<'_> {
    PduRepr::FileData(FileDataRepr { offset, data })
}

fn eof(condition: ConditionCode, checksum: u32, size: u32) -> PduRepr<'static> {
    PduRepr::Eof(EofRepr {
        condition,
        checksum,
        file_size: size,
        fault_location: None,
    })
}

/// A receiving transaction fed `pdus` at time 0: its event.
fn receive<S: Filestore>(mode: Mode, pdus: &[PduRepr<'_>], store: &mut S) -> Option<Event> {
    let cfg = Config::mission(0x42);
    let mut r = Receiver::<4>::new(ID, mode, 0);
    for p in pdus {
        r.handle(0, &cfg, p, store);
    }
    r.take_event()
}

fn condition(e: Option<Event>) -> (ConditionCode, bool) {
    match e {
        Some(Event::Received {
            condition,
            delivered,
            ..
        }) => (condition, delivered),
        other => panic!("{other:?}"),
    }
}

/// The modular checksum of "abcd".
const ABCD: u32 = u32::from_be_bytes(*b"abcd");

// req: 727.0-B-5/CFDP-23, 727.0-B-5/CFDP-40
#[test]
fn a_receiver_ends_each_bad_transfer_with_its_condition() {
    let m = Mode::Acknowledged;
    let mut s = MemoryStore::<4, 64>::new();
    let cases: Vec<(Vec<PduRepr<'_>>, ConditionCode)> = vec![
        (
            vec![metadata(4, ChecksumType::from_bits(3), b"f")],
            ConditionCode::UnsupportedChecksumType,
        ),
        (
            vec![metadata(4, ChecksumType::MODULAR, &[b'n'; 65])],
            ConditionCode::FilestoreRejection,
        ),
        (
            vec![data(0, b"abcdef"), metadata(4, ChecksumType::MODULAR, b"f")],
            ConditionCode::FileSizeError,
        ),
        (
            vec![data(u32::MAX - 1, b"abcd")],
            ConditionCode::FileSizeError,
        ),
        (
            vec![metadata(4, ChecksumType::MODULAR, b"f"), data(2, b"abc")],
            ConditionCode::FileSizeError,
        ),
        (
            vec![eof(ConditionCode::CancelRequestReceived, 0, 4)],
            ConditionCode::CancelRequestReceived,
        ),
        (
            vec![
                metadata(4, ChecksumType::MODULAR, b"f"),
                eof(ConditionCode::NoError, ABCD, 5),
            ],
            ConditionCode::FileSizeError,
        ),
        (
            vec![data(0, b"abcdef"), eof(ConditionCode::NoError, 0, 4)],
            ConditionCode::FileSizeError,
        ),
        (
            vec![
                metadata(4, ChecksumType::MODULAR, b"f"),
                data(0, b"abcd"),
                eof(ConditionCode::NoError, ABCD ^ 1, 4),
            ],
            ConditionCode::FileChecksumFailure,
        ),
        // A store too small for the file.
        (vec![data(0, &[7u8; 65])], ConditionCode::FilestoreRejection),
    ];
    for (pdus, want) in cases {
        assert_eq!(
            condition(receive(m, &pdus, &mut s)),
            (want, false),
            "{pdus:?}"
        );
        assert_eq!(s.incoming(), 0, "{pdus:?}: the incoming file discarded");
    }
    // The null checksum: any EOF checksum is taken.
    let pdus = [
        metadata(4, ChecksumType::NULL, b"f"),
        data(0, b"abcd"),
        eof(ConditionCode::NoError, 0, 4),
    ];
    assert_eq!(
        condition(receive(m, &pdus, &mut s)),
        (ConditionCode::NoError, true)
    );
    assert_eq!(s.get(b"f"), Some(&b"abcd"[..]));
}

/// A store that refuses to name a file, or keeps no octet it is given.
struct Failing {
    inner: MemoryStore<4, 64>,
    commit: bool,
    keep: bool,
}

impl Filestore for Failing {
    fn read(&mut self, name: &[u8], offset: u32, buf: &mut [u8]) -> Result<usize, StoreError> {
        self.inner.read(name, offset, buf)
    }
    fn size(&mut self, name: &[u8]) -> Result<u32, StoreError> {
        self.inner.size(name)
    }
    fn write_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        data: &[u8],
    ) -> Result<(), StoreError> {
        if self.keep {
            self.inner.write_incoming(id, offset, data)
        } else {
            self.inner.write_incoming(id, 0, &[])
        }
    }
    fn read_incoming(
        &mut self,
        id: TransactionId,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<usize, StoreError> {
        self.inner.read_incoming(id, offset, buf)
    }
    fn commit(&mut self, id: TransactionId, name: &[u8]) -> Result<(), StoreError> {
        if self.commit {
            self.inner.commit(id, name)
        } else {
            Err(StoreError::Full {
                needed: 4,
                capacity: 0,
            })
        }
    }
    fn discard(&mut self, id: TransactionId) {
        self.inner.discard(id);
    }
    fn discard_all_incoming(&mut self) {
        self.inner.discard_all_incoming();
    }
}

#[test]
fn a_store_that_fails_ends_the_transfer_never_with_a_wrong_file() {
    let pdus = [
        metadata(4, ChecksumType::MODULAR, b"f"),
        data(0, b"abcd"),
        eof(ConditionCode::NoError, ABCD, 4),
    ];
    let mut refuses = Failing {
        inner: MemoryStore::new(),
        commit: false,
        keep: true,
    };
    let got = condition(receive(Mode::Acknowledged, &pdus, &mut refuses));
    assert_eq!(got, (ConditionCode::FilestoreRejection, false));
    let mut loses = Failing {
        inner: MemoryStore::new(),
        commit: true,
        keep: false,
    };
    let got = condition(receive(Mode::Acknowledged, &pdus, &mut loses));
    assert_eq!(got, (ConditionCode::FileChecksumFailure, false));
    assert_eq!(loses.inner.get(b"f"), None);
}

// req: 727.0-B-5/CFDP-16, 727.0-B-5/CFDP-17
#[test]
fn a_receiver_answers_prompts_and_ends_once() {
    let cfg = Config::mission(0x42);
    let mut s = MemoryStore::<4, 64>::new();
    let mut r = Receiver::<4>::new(ID, Mode::Acknowledged, 0);
    r.handle(0, &cfg, &data(0, b"ab"), &mut s);
    let mut segs = [(0, 0); 4];
    // The immediate NAK asks for the Metadata.
    assert!(
        matches!(r.poll(0, &cfg, &mut segs), Some(PduRepr::Nak(n)) if n.segments.iter().next() == Some((0, 0)))
    );
    r.handle(1, &cfg, &PduRepr::Prompt(PromptFor::KeepAlive), &mut s);
    assert_eq!(
        r.poll(1, &cfg, &mut segs),
        Some(PduRepr::KeepAlive { progress: 2 })
    );
    r.handle(2, &cfg, &PduRepr::Prompt(PromptFor::Nak), &mut s);
    assert!(matches!(r.poll(2, &cfg, &mut segs), Some(PduRepr::Nak(_))));
    assert_eq!(r.poll(2, &cfg, &mut segs), None);
    // Class 1 without closure: ended at once, its ticks change nothing.
    let mut one = Receiver::<4>::new(ID, Mode::Unacknowledged, 0);
    one.handle(
        0,
        &cfg,
        &eof(ConditionCode::CancelRequestReceived, 0, 0),
        &mut s,
    );
    assert!(one.take_event().is_some());
    one.tick(1_000_000, &cfg, &mut s);
    assert!(one.is_ended());
    assert_eq!(one.take_event(), None);
}

// req: 727.0-B-5/CFDP-23
#[test]
fn a_sender_reads_its_file_as_it_goes_and_says_when_it_cannot() {
    let cfg = Config {
        checksum: ChecksumType::NULL,
        file_data: 4,
        ..Config::mission(0x15)
    };
    let mut store = MemoryStore::<4, 64>::new();
    store.put(b"s", b"abcdefgh").unwrap();
    let put = Put::new(b"s", b"d", Mode::Acknowledged).unwrap();
    let mut tx = Sender::<4>::new(ID, 0x42, put.clone(), 8, 0);
    let mut buf = [0u8; 64];
    let mut pdus = Vec::new();
    while let Some(p) = tx.poll(0, &cfg, &mut store, &mut buf) {
        pdus.push(format!("{p:?}"));
    }
    // Metadata, two file data PDUs, the EOF with the null checksum's 0.
    assert_eq!(pdus.len(), 4);
    assert!(pdus[3].contains("checksum: 0"), "{}", pdus[3]);
    // A NAK for octets 1..7: sent again in pieces of at most 4.
    let segs = [(1, 7)];
    tx.handle(
        1,
        &PduRepr::Nak(NakRepr {
            start: 0,
            end: 8,
            segments: Segments::Pairs(&segs),
        }),
    );
    let first = tx
        .poll(1, &cfg, &mut store, &mut buf)
        .map(|p| format!("{p:?}"));
    assert!(first.is_some_and(|p| p.contains("offset: 1")));
    let second = tx
        .poll(1, &cfg, &mut store, &mut buf)
        .map(|p| format!("{p:?}"));
    assert!(second.is_some_and(|p| p.contains("offset: 5")));
    // The file gone from the store: the transfer ends with a filestore rejection.
    let mut empty = MemoryStore::<4, 64>::new();
    let mut gone = Sender::<4>::new(ID, 0x42, put, 8, 0);
    assert!(matches!(
        gone.poll(0, &cfg, &mut empty, &mut buf),
        Some(PduRepr::Metadata(_))
    ));
    assert_eq!(gone.poll(0, &cfg, &mut empty, &mut buf), None);
    assert_eq!(
        gone.take_event(),
        Some(Event::Sent {
            id: ID,
            condition: ConditionCode::FilestoreRejection
        })
    );
    // Its handler cancels: the receiver is told by an EOF with the condition.
    assert_eq!(
        gone.poll(0, &cfg, &mut empty, &mut buf),
        Some(PduRepr::Eof(EofRepr {
            condition: ConditionCode::FilestoreRejection,
            checksum: 0,
            file_size: 0,
            fault_location: Some(0x15),
        }))
    );
    assert_eq!(gone.poll(0, &cfg, &mut empty, &mut buf), None);
}

/// A fault's handler (727.0-B-5 §4.8): cancel tells the peer under the positive ACK
/// procedure, then ends (acknowledged, or abandoned at the limit); abandon sends nothing. The
/// fault is reported once, at once, either way.
// req: 727.0-B-5/CFDP-35
#[test]
fn fault_handlers_cancel_with_a_notice_or_abandon_in_silence() {
    let cancel = Config {
        ack_timeout_ms: 10,
        ack_limit: 2,
        ..Config::mission(0x15)
    };
    let abandon = Config {
        handlers: FaultHandlers::CANCEL
            .with(ConditionCode::FilestoreRejection, FaultHandler::Abandon),
        ..cancel
    };
    let c = ConditionCode::FilestoreRejection;
    assert_eq!(abandon.handlers.handler(c), FaultHandler::Abandon);
    let undone = abandon.handlers.with(c, FaultHandler::Cancel);
    assert_eq!(undone, FaultHandlers::CANCEL, "set back to cancel");
    let put = Put::new(b"s", b"d", Mode::Acknowledged).unwrap();
    let mut buf = [0u8; 64];
    let mut empty = MemoryStore::<4, 64>::new();
    let notice = |at| {
        Some(PduRepr::Eof(EofRepr {
            condition: ConditionCode::FilestoreRejection,
            checksum: 0,
            file_size: 0,
            fault_location: Some(at),
        }))
    };
    let fault = Some(Event::Sent {
        id: ID,
        condition: ConditionCode::FilestoreRejection,
    });
    // Cancel, never acknowledged: the notice at 0, again at 10, abandoned at 20.
    let mut tx = Sender::<4>::new(ID, 0x42, put.clone(), 8, 0);
    tx.poll(0, &cancel, &mut empty, &mut buf); // the Metadata
    assert_eq!(tx.poll(0, &cancel, &mut empty, &mut buf), None);
    assert_eq!(tx.take_event(), fault);
    assert_eq!(tx.poll(0, &cancel, &mut empty, &mut buf), notice(0x15));
    assert_eq!(tx.poll(5, &cancel, &mut empty, &mut buf), None);
    tx.tick(10, &cancel);
    assert_eq!(tx.poll(10, &cancel, &mut empty, &mut buf), notice(0x15));
    assert!(!tx.is_ended());
    tx.tick(20, &cancel);
    assert!(tx.is_ended(), "the positive ACK limit: abandoned");
    assert_eq!(tx.take_event(), None, "reported once");
    // Cancel, acknowledged: ended at the ACK; a Finished from the receiver is acknowledged.
    let mut tx = Sender::<4>::new(ID, 0x42, put.clone(), 8, 0);
    tx.poll(0, &cancel, &mut empty, &mut buf);
    tx.poll(0, &cancel, &mut empty, &mut buf);
    assert_eq!(tx.poll(0, &cancel, &mut empty, &mut buf), notice(0x15));
    let ack = AckRepr {
        of: DirectiveCode::Eof,
        condition: ConditionCode::FilestoreRejection,
        status: TransactionStatus::Terminated,
    };
    tx.handle(3, &PduRepr::Ack(ack));
    assert_eq!(tx.take_event(), fault);
    assert!(tx.is_ended());
    // Abandon: nothing after the Metadata; ended at once.
    let mut tx = Sender::<4>::new(ID, 0x42, put, 8, 0);
    tx.poll(0, &abandon, &mut empty, &mut buf);
    assert_eq!(tx.poll(0, &abandon, &mut empty, &mut buf), None);
    assert_eq!(tx.take_event(), fault);
    assert_eq!(tx.poll(0, &abandon, &mut empty, &mut buf), None);
    assert!(tx.is_ended());
    // A receiver: cancel owes the Finished PDU (class 2), abandon does not.
    for (cfg, finished) in [(cancel, true), (abandon, false)] {
        let mut r = Receiver::<4>::new(ID, Mode::Acknowledged, 0);
        let mut s = Failing {
            inner: MemoryStore::new(),
            commit: false,
            keep: true,
        };
        for p in [
            metadata(4, ChecksumType::MODULAR, b"f"),
            data(0, b"abcd"),
            eof(ConditionCode::NoError, ABCD, 4),
        ] {
            r.handle(0, &cfg, &p, &mut s);
        }
        assert_eq!(
            condition(r.take_event()),
            (ConditionCode::FilestoreRejection, false)
        );
        let mut sent = Vec::new();
        let mut segments = [(0, 0); 4];
        while let Some(p) = r.poll(0, &cfg, &mut segments) {
            sent.push(format!("{p:?}"));
        }
        let has_finished = sent.iter().any(|p| p.starts_with("Finished"));
        assert_eq!(has_finished, finished, "{sent:?}");
    }
}

#[test]
fn an_entity_refuses_by_reason_and_counts() {
    let mut robot = Entity::<1, 4, 4>::new(Config::mission(0x42), 1);
    let mut s = MemoryStore::<4, 64>::new();
    let m = Mode::Acknowledged;
    assert!(matches!(
        robot.handle(0, &[1, 2, 3], &mut s),
        Err(HandleError::Pdu(_))
    ));
    let mut other = bytes(&metadata(4, ChecksumType::MODULAR, b"f"), m);
    other[11] = 0x43; // for entity 0x43
    assert_eq!(
        robot.handle(0, &other, &mut s),
        Err(HandleError::NotOurs {
            local: 0x42,
            found: 0x43
        })
    );
    let ack = AckRepr {
        of: DirectiveCode::Eof,
        condition: ConditionCode::NoError,
        status: TransactionStatus::Active,
    };
    let mut to_sender = bytes(&PduRepr::Ack(ack), m);
    to_sender[5] = 0x42; // from the robot's own transactions: none
    assert_eq!(
        robot.handle(0, &to_sender, &mut s),
        Err(HandleError::Unknown(TransactionId {
            source: 0x42,
            seq: 9
        }))
    );
    robot
        .handle(
            0,
            &bytes(&metadata(4, ChecksumType::MODULAR, b"f"), m),
            &mut s,
        )
        .unwrap();
    let mut second = bytes(&metadata(4, ChecksumType::MODULAR, b"g"), m);
    second[9] = 10; // transaction 10: no room
    assert_eq!(
        robot.handle(0, &second, &mut s),
        Err(HandleError::Full { capacity: 1 })
    );
    let c = robot.counters();
    assert_eq!(
        (c.malformed, c.not_ours, c.unknown, c.full, c.ended),
        (1, 1, 1, 1, 0)
    );
    // Too short a buffer: nothing taken, nothing lost.
    let mut prompt = bytes(&PduRepr::Prompt(PromptFor::KeepAlive), m);
    prompt[9] = 9;
    robot.handle(0, &prompt, &mut s).unwrap();
    assert_eq!(robot.poll(0, &mut s, &mut [0u8; 64]), None);
    assert!(robot.poll(0, &mut s, &mut [0u8; 512]).is_some());
    assert_eq!(robot.config().local, 0x42);
}

// req: 727.0-B-5/CFDP-32
#[test]
fn late_pdus_of_ended_transactions_start_nothing_and_the_ids_are_kept_in_a_ring() {
    let cfg = Config::mission(0x42);
    let mut robot = Entity::<1, 4, 4>::new(cfg, 1);
    let mut s = MemoryStore::<4, 64>::new();
    let m = Mode::Unacknowledged;
    let mut buf = [0u8; 512];
    for seq in 0..20u8 {
        let mut cancel = bytes(&eof(ConditionCode::CancelRequestReceived, 0, 0), m);
        cancel[9] = seq;
        robot.handle(0, &cancel, &mut s).unwrap();
        while robot.poll(0, &mut s, &mut buf).is_some() {}
        assert!(robot.take_event().is_some());
        assert_eq!(robot.active(), 0);
        assert_eq!(
            robot.handle(0, &cancel, &mut s),
            Err(HandleError::Ended(TransactionId {
                source: 0x15,
                seq: u64::from(seq)
            }))
        );
    }
    assert_eq!(robot.counters().ended, 20);
}

// req: 727.0-B-5/CFDP-32
#[test]
fn puts_are_refused_without_room_file_or_sequence_numbers() {
    let mut s = MemoryStore::<4, 64>::new();
    s.put(b"s", b"abc").unwrap();
    let put = || Put::new(b"s", b"d", Mode::Acknowledged).unwrap();
    let mut g = Entity::<1, 4, 4>::new(Config::mission(0x15), 7);
    let missing = Put::new(b"t", b"d", Mode::Acknowledged).unwrap();
    assert_eq!(
        g.put(0, 0x42, missing, &mut s),
        Err(PutError::Store(StoreError::NotFound))
    );
    assert_eq!(
        g.put(0, 0x42, put(), &mut s),
        Ok(TransactionId {
            source: 0x15,
            seq: 7
        })
    );
    assert_eq!(g.next_seq(), 8);
    assert_eq!(
        g.put(0, 0x42, put(), &mut s),
        Err(PutError::Full { capacity: 1 })
    );
    let one = Config {
        lengths: Lengths { entity: 2, seq: 1 },
        ..Config::mission(0x15)
    };
    let mut last = Entity::<1, 4, 4>::new(one, 256);
    assert_eq!(
        last.put(0, 0x42, put(), &mut s),
        Err(PutError::SeqExhausted { octets: 1 })
    );
    assert!(Put::new(&[b'x'; 65], b"d", Mode::Acknowledged).is_none());
}

#[test]
fn emitters_refuse_what_a_pdu_cannot_carry() {
    let h = header(Mode::Acknowledged);
    let mut out = vec![0u8; 70_000];
    let big = vec![0u8; 70_000];
    assert!(matches!(
        data(0, &big).emit(&h, &mut out),
        Err(PduError::TooLarge { octets: 2, .. })
    ));
    let ack = AckRepr {
        of: DirectiveCode::Metadata,
        condition: ConditionCode::NoError,
        status: TransactionStatus::Active,
    };
    assert_eq!(
        PduRepr::Ack(ack).emit(&h, &mut out),
        Err(PduError::AckOf { found: 7 })
    );
    let message = [0x02, 0x00];
    let finished = FinishedRepr {
        condition: ConditionCode::NoError,
        data_complete: true,
        status: FileStatus::Retained,
        responses: Tlvs::parse(&message).unwrap(),
        fault_location: None,
    };
    assert_eq!(
        PduRepr::Finished(finished).emit(&h, &mut out),
        Err(PduError::TlvType { found: 2 })
    );
    let long = [b'n'; 300];
    assert!(matches!(
        metadata(4, ChecksumType::MODULAR, &long).emit(&h, &mut out),
        Err(PduError::TooLarge { octets: 1, .. })
    ));
    let at = EofRepr {
        condition: ConditionCode::NakLimitReached,
        checksum: 0,
        file_size: 0,
        fault_location: Some(0x1_0000),
    };
    assert_eq!(
        PduRepr::Eof(at).emit(&h, &mut out),
        Err(PduError::TooLarge {
            value: 0x1_0000,
            octets: 2
        })
    );
    // The small views' own answers.
    assert!(Segments::Pairs(&[]).is_empty());
    assert!(Tlvs::EMPTY.is_empty());
    assert_eq!(Received::<2>::default(), Received::<2>::new());
}

#[test]
fn the_memory_store_refuses_by_reason() {
    let mut s = MemoryStore::<1, 8>::new();
    assert_eq!(
        s.put(&[b'n'; 65], b""),
        Err(StoreError::Name { len: 65, max: 64 })
    );
    assert_eq!(
        s.put(b"a", &[0; 9]),
        Err(StoreError::Full {
            needed: 9,
            capacity: 8
        })
    );
    s.put(b"a", b"x").unwrap();
    assert_eq!(
        s.write_incoming(ID, 0, b"y"),
        Err(StoreError::Full {
            needed: 1,
            capacity: 0
        })
    );
    assert_eq!(
        s.commit(ID, &[b'n'; 65]),
        Err(StoreError::Name { len: 65, max: 64 })
    );
}

/// A transaction of the same source that started earlier but ends later (its EOF delayed past a
/// restart of the sender, which then sent a corrected file under the same name) never replaces
/// the later one's file: the store refuses it as stale, the receiver ends it with filestore
/// rejection. Another source's transaction, or an operator's put, still replaces it.
// req: 727.0-B-5/CFDP-40
#[test]
fn a_late_older_transaction_never_replaces_a_newer_file() {
    let newer = TransactionId {
        seq: ID.seq + 1,
        ..ID
    };
    let mut s = MemoryStore::<4, 64>::new();
    s.write_incoming(newer, 0, b"new").unwrap();
    s.commit(newer, b"f").unwrap();
    s.write_incoming(ID, 0, b"old").unwrap();
    assert_eq!(s.commit(ID, b"f"), Err(StoreError::Stale { id: ID, newer }));
    assert_eq!(s.get(b"f"), Some(&b"new"[..]));
    // The same through a receiver: the older transaction's whole file, checked, refused.
    let pdus = [
        metadata(4, ChecksumType::MODULAR, b"f"),
        data(0, b"abcd"),
        eof(ConditionCode::NoError, ABCD, 4),
    ];
    let e = receive(Mode::Acknowledged, &pdus, &mut s);
    assert_eq!(condition(e), (ConditionCode::FilestoreRejection, false));
    assert_eq!(s.get(b"f"), Some(&b"new"[..]));
    assert_eq!(s.incoming(), 0, "the refused file is discarded");
    // Another source's transaction replaces it; so does an operator.
    let other = TransactionId { source: 9, seq: 0 };
    s.write_incoming(other, 0, b"other").unwrap();
    s.commit(other, b"f").unwrap();
    assert_eq!(s.get(b"f"), Some(&b"other"[..]));
    s.put(b"f", b"op").unwrap();
    s.write_incoming(ID, 0, b"again").unwrap();
    s.commit(ID, b"f").unwrap();
    assert_eq!(s.get(b"f"), Some(&b"again"[..]));
}

/// At boot the shell discards every incoming file: no receiver is left to finish them.
#[test]
fn incoming_files_are_discarded_at_boot_and_named_ones_kept() {
    let mut s = MemoryStore::<4, 64>::new();
    s.put(b"kept", b"k").unwrap();
    s.write_incoming(ID, 0, b"half").unwrap();
    s.write_incoming(TransactionId { seq: 9, ..ID }, 0, b"h")
        .unwrap();
    s.discard_all_incoming();
    assert_eq!(s.incoming(), 0);
    assert_eq!(s.get(b"kept"), Some(&b"k"[..]));
}
