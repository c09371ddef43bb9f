//! Properties of the PUS services layer (`mmic::pus`): the parsers of application and source
//! data read every input one way or refuse it by a named check, and what they accept is the
//! canonical encoding of what they return.

use mmic::pus::event::{Event, EventError};
use mmic::pus::request::{Request, RequestError};
use mmic::pus::{function, housekeeping, verification};

/// Any service, subservice and application data: `Request::parse` refuses with a named check,
/// or returns a request whose canonical encoding is exactly the input (a function's
/// `function::encode` gives the same octets back). Returns whether it was accepted.
pub fn check_request(service: u8, subservice: u8, data: &[u8]) -> bool {
    match Request::parse(service, subservice, data) {
        Err(e) => {
            assert!(RequestError::NAMES.contains(&e.name()), "{e}");
            assert!(e.code() >= 0x0301 && e.code() <= 0x0306, "{e}");
            false
        }
        Ok(Request::Function(c)) => {
            assert_eq!((service, subservice), (8, 1));
            let mut buf = [0u8; function::MAX_LEN];
            let n = function::encode(&c, &mut buf).expect("an accepted command encodes");
            assert_eq!(
                &buf[..n],
                data,
                "{c:?} is read from other octets than it encodes to"
            );
            true
        }
        Ok(Request::AreYouAlive) => {
            assert!((service, subservice) == (17, 1) && data.is_empty());
            true
        }
        Ok(r) => {
            assert_eq!(service, 3, "{r:?}");
            true
        }
    }
}

/// Any source data of TM(3,25): refused, or read into a heartbeat whose report is exactly it.
pub fn check_housekeeping(data: &[u8]) -> bool {
    match housekeeping::parse(data) {
        Err(_) => false,
        Ok(hb) => {
            let mut buf = [0u8; housekeeping::REPORT_LEN];
            housekeeping::emit(&hb, &mut buf);
            assert_eq!(&buf[..], data);
            true
        }
    }
}

/// Any source data of a TM(1,x): refused, or read into a report that writes it back exactly.
pub fn check_verification(subservice: u8, data: &[u8]) -> bool {
    match verification::Report::parse(subservice, data) {
        Err(_) => false,
        Ok(r) => {
            assert_eq!(r.subservice(), subservice);
            let mut buf = [0u8; verification::FAILURE_LEN];
            let n = r.emit(&mut buf);
            assert_eq!(&buf[..n], data);
            true
        }
    }
}

/// Any source data of a TM(5,x): refused with the error's numbers (a subservice outside 1..=4,
/// a length other than the event's six octets, a severity other than the event's own, or a
/// named field), or read into an event of exactly that severity that writes it back exactly.
pub fn check_event(subservice: u8, data: &[u8]) -> bool {
    match Event::parse(subservice, data) {
        Err(EventError::Subservice(s)) => {
            assert_eq!(s, subservice);
            assert!(!(1..=4).contains(&s));
            false
        }
        Err(EventError::Length { expected, found }) => {
            assert_eq!((expected, found), (mmic::pus::event::EVENT_LEN, data.len()));
            false
        }
        Err(EventError::Severity { found, .. }) => {
            assert_eq!(found, subservice);
            false
        }
        Err(e) => {
            assert_eq!(data.len(), mmic::pus::event::EVENT_LEN, "{e}");
            false
        }
        Ok(e) => {
            assert_eq!(e.severity(), subservice);
            assert_eq!(&e.to_bytes()[..], data);
            true
        }
    }
}
