//! The workspace's proptest configuration (tests/common/prop.rs): committed regression seeds
//! are replayed, a new failure is printed and never written into the tree, and case counts
//! scale with `PROPTEST_CASES`.

use proptest::test_runner::{FailurePersistence, PersistedSeed, TestCaseError, TestRunner};

use crate::common::prop::{config, scaled, scaled_by, CommittedRegressions};

#[test]
fn committed_seeds_are_replayed() {
    let seeds = CommittedRegressions.load_persisted_failures2(Some("tests/control/control_hip.rs"));
    let committed =
        std::fs::read_to_string("tests/control/control_hip.proptest-regressions").unwrap();
    let lines = committed.lines().filter(|l| l.starts_with("cc ")).count();
    assert!(lines >= 2);
    assert_eq!(seeds.len(), lines, "every committed seed is loaded");
}

#[test]
fn a_new_failure_is_not_written_into_the_tree() {
    let beside = "tests/wire/proptest_config.proptest-regressions";
    assert!(!std::path::Path::new(beside).exists());
    // Directly: saving prints, writes nothing.
    let seed: PersistedSeed = "cc 611db20704156869ee0852447abcf5a5c7587fbe761e3b4a5486aa2e67eeb212"
        .parse()
        .unwrap();
    let mut p = CommittedRegressions;
    p.save_persisted_failure2(Some(file!()), seed, &"shrunken");
    assert!(!std::path::Path::new(beside).exists());
    // Through a failing property under the workspace config: the failure is reported, the
    // tree is unchanged.
    let mut runner = TestRunner::new(config(16));
    let r = runner.run(&(0u32..1000), |v| {
        if v >= 10 {
            Err(TestCaseError::fail(format!("{v} >= 10")))
        } else {
            Ok(())
        }
    });
    assert!(r.is_err(), "the property fails");
    assert!(!std::path::Path::new(beside).exists());
}

#[test]
fn case_counts_scale_with_proptest_cases() {
    // The rule with the variable's value passed in: setting it here would race with the
    // other tests' threads, which read it.
    assert_eq!(scaled_by(200, None), 200);
    assert_eq!(scaled_by(200, Some("not a number")), 200);
    assert_eq!(
        scaled_by(200, Some("25600")),
        20_000,
        "100x proptest's default: 100x each test's count"
    );
    assert_eq!(scaled_by(2048, Some(" 25600 ")), 204_800);
    assert_eq!(scaled_by(200, Some("1")), 1, "never zero");
    // And what the tests use reads the variable through it.
    let env = std::env::var("PROPTEST_CASES").ok();
    assert_eq!(scaled(200), scaled_by(200, env.as_deref()));
    assert_eq!(config(2048).cases, scaled_by(2048, env.as_deref()));
}
