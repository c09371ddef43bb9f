//! The workspace's proptest configuration (tests/common/prop.rs): committed regression seeds
//! are replayed, a new failure is printed and never written into the tree, and case counts
//! scale with `PROPTEST_CASES`.

use proptest::test_runner::{FailurePersistence, PersistedSeed, TestCaseError, TestRunner};

use crate::common::prop::{config, scaled, CommittedRegressions};

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
    // This binary's only test that reads the variable; the others do not depend on it.
    let before = std::env::var("PROPTEST_CASES").ok();
    std::env::remove_var("PROPTEST_CASES");
    assert_eq!(scaled(200), 200);
    std::env::set_var("PROPTEST_CASES", "25600");
    assert_eq!(
        scaled(200),
        20_000,
        "100x proptest's default: 100x each test's count"
    );
    assert_eq!(config(2048).cases, 204_800);
    std::env::set_var("PROPTEST_CASES", "1");
    assert_eq!(scaled(200), 1, "never zero");
    match before {
        Some(v) => std::env::set_var("PROPTEST_CASES", v),
        None => std::env::remove_var("PROPTEST_CASES"),
    }
}
