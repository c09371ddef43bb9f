//! The ST\[1\] verifiers of `pus-tc`: each a `java-expression` algorithm (compiled by YAMCS with
//! its bundled Janino) that passes on a report of one of its subservices whose request ID is
//! the TC's (APID argument, sequence count the postprocessor published) and returns nothing on
//! any other packet.
//!
//! Not a `BooleanExpression`: YAMCS 5.12.8 gives each such verifier its own subscription in
//! `ParameterProcessorManager` and drops it on the timer thread when it matched, while the TM
//! thread may be dispatching the next packet to it: `sendToProcessor(null)` throws
//! (NullPointerException at ParameterProcessorManager.java:263) and every later verifier misses
//! that packet. The gateway sends TM(1,1), (1,3), (1,7) back to back, so `Started` lost its (1,3)
//! (issue 24). Algorithm verifiers get TM through the AlgorithmManager's one subscription, taken
//! at start and never dropped, and their per-command contexts are copy-on-write lists.
//!
//! The failure verifier returns `failure_code` of that report as the return value (the
//! command's error `Verifier Failed return: <code>`); a `ReturnParmRef` would read the last
//! value cache, which YAMCS updates only after the algorithms ran: the previous failure's code.

use super::model::{Algorithm, Input, Stage, Verifier};

/// How long each ST\[1\] stage may take after the command's release (ISO 8601 durations). All
/// windows are relative to the release: a window relative to the last verifier opens only once
/// that verifier passed, too late for reports sent together (TC(3,x): TM(1,1), (1,3), (1,7) at
/// once).
const ACCEPT_WINDOW: &str = "PT10S";
/// See [`ACCEPT_WINDOW`].
const START_WINDOW: &str = "PT30S";
/// See [`ACCEPT_WINDOW`].
const COMPLETE_WINDOW: &str = "PT300S";
/// See [`ACCEPT_WINDOW`].
const FAILED_WINDOW: &str = "PT600S";

/// The inputs every verifier reads: the command's APID argument and sequence count, and the
/// report's service, subservice and request ID.
const INPUTS: [(&str, &str); 7] = [
    ("/yamcs/cmd/arg/apid", "apid"),
    ("/yamcs/cmdHist/ccsds-seqcount", "seq_count"),
    ("/MMIC/service", "service"),
    ("/MMIC/subservice", "subservice"),
    ("/MMIC/req_type", "req_type"),
    ("/MMIC/req_apid", "req_apid"),
    ("/MMIC/req_seq_count", "req_seq_count"),
];

/// The failure verifier's extra input.
const FAILURE_CODE: (&str, &str) = ("/MMIC/failure_code", "failure_code");

/// The four verifiers: accepted (1,1), started (1,3), complete (1,7), each failing the command
/// when its window closes, and failed (`failure_subservices`, returning the failure code).
pub fn verifiers(failure_subservices: &[u32]) -> Vec<Verifier> {
    let stage = |stage, subservices: &[u32], window, fail_on_timeout| Verifier {
        stage,
        algorithm: algorithm(stage, subservices),
        window,
        fail_on_timeout,
    };
    vec![
        stage(Stage::Accepted, &[1], ACCEPT_WINDOW, true),
        stage(Stage::Started, &[3], START_WINDOW, true),
        stage(Stage::Complete, &[7], COMPLETE_WINDOW, true),
        stage(Stage::Failed, failure_subservices, FAILED_WINDOW, false),
    ]
}

/// The stage's algorithm: only the failure verifier returns the failure code.
fn algorithm(stage: Stage, subservices: &[u32]) -> Algorithm {
    let returns_code = stage == Stage::Failed;
    let numbers: Vec<String> = subservices.iter().map(u32::to_string).collect();
    Algorithm {
        name: format!("st1_{}", stage.word()),
        description: format!("TM(1,{}) with the TC's request ID", numbers.join("/")),
        language: "java-expression",
        text: text(subservices, returns_code),
        inputs: inputs(returns_code),
    }
}

/// The algorithm's Java. An input the packet at hand lacks keeps an earlier packet's value:
/// hence `service == 1`, which makes every request-ID field one of this packet (the
/// verification-report container).
fn text(subservices: &[u32], returns_code: bool) -> String {
    let matches = subservices
        .iter()
        .map(|s| format!("s == {s}"))
        .collect::<Vec<_>>()
        .join(" || ");
    let (code_present, result) = if returns_code {
        (
            " || failure_code == null",
            "new org.yamcs.commanding.VerificationResult(true, null, failure_code.getEngValue())",
        )
    } else {
        ("", "Boolean.TRUE")
    };
    format!(
        "if (apid == null || seq_count == null || service == null || subservice == null || req_type == null || req_apid == null || req_seq_count == null{code_present}) return null; \
         if (service.getEngValue().toLong() != 1 || req_type.getEngValue().toLong() != 1 || req_apid.getEngValue().toLong() != apid.getEngValue().toLong() || req_seq_count.getEngValue().toLong() != seq_count.getEngValue().toLong()) return null; \
         long s = subservice.getEngValue().toLong(); \
         if ({matches}) return {result}; \
         return null;",
    )
}

/// The algorithm's inputs. TM inputs are `instance="1"`: in 5.12.8 an input's instance 0 falls
/// back to the last value cache when the delivery at hand lacks it, and YAMCS re-reads every
/// input of the command's algorithms on each command-history update of the command, on the
/// thread that published it (e.g. `Acknowledge_Sent`, by the TC link, while the TM thread
/// handles the TM(1,1)): the cache's older values overwrote the report's between the
/// algorithm's update and its run, and `Accepted` missed its report. An instance above 0 never
/// reads the cache (`ProcessingContext.get`, PACKET_START_ACROSS_PACKETS) and, for a parameter
/// the delivery has once, is that value (`ParameterValueList.get(p, n)` returns the last one
/// found).
fn inputs(returns_code: bool) -> Vec<Input> {
    let code = returns_code.then_some(FAILURE_CODE);
    INPUTS
        .into_iter()
        .chain(code)
        .map(|(parameter, name)| Input {
            parameter,
            instance: parameter.starts_with("/MMIC/").then_some(1),
            name,
        })
        .collect()
}
