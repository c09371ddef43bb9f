//! One proptest configuration for every property test of the workspace.
//!
//! * **Committed regression seeds are read, never written.** Each test file's seeds live
//!   beside it (`tests/<file>.proptest-regressions`) and are replayed before new cases. A new
//!   failure is printed with the line to commit; nothing in the tree changes during a run, so a
//!   CI checkout stays clean and a failure does not turn into a failure of every later run.
//!   A person commits the seed.
//! * **Case counts scale with `PROPTEST_CASES`.** Each test names its own count (what a
//!   `cargo test` in CI can afford); when `PROPTEST_CASES` is set, every count is multiplied by
//!   `PROPTEST_CASES / 256` (proptest's own default is 256 cases), so `PROPTEST_CASES=25600`
//!   runs every property test at 100× its count in one run.

use proptest::test_runner::{Config, FailurePersistence, FileFailurePersistence, PersistedSeed};
use std::any::Any;

/// proptest's default case count, the unit `PROPTEST_CASES` is measured against here.
pub const PROPTEST_DEFAULT_CASES: u32 = 256;

/// `cases` scaled by `PROPTEST_CASES / 256` when that variable is set (at least 1).
pub fn scaled(cases: u32) -> u32 {
    scaled_by(cases, std::env::var("PROPTEST_CASES").ok().as_deref())
}

/// `cases` scaled by `proptest_cases / 256` (at least 1), or as it is when the variable is
/// unset or not a number: [`scaled`] with the variable's value passed in, so that a test can
/// check the rule without changing the process's environment under the other tests' threads.
pub fn scaled_by(cases: u32, proptest_cases: Option<&str>) -> u32 {
    match proptest_cases.and_then(|v| v.trim().parse::<u64>().ok()) {
        Some(env) => {
            let n = cases as u64 * env / PROPTEST_DEFAULT_CASES as u64;
            n.clamp(1, u32::MAX as u64) as u32
        }
        None => cases,
    }
}

/// The configuration every `proptest!` block of the workspace uses: `cases` (scaled, see the
/// module docs) and the read-only committed regressions.
pub fn config(cases: u32) -> Config {
    Config {
        cases: scaled(cases),
        failure_persistence: Some(Box::new(CommittedRegressions)),
        ..Config::default()
    }
}

/// Replays the seeds committed in `<test file>.proptest-regressions` beside the test's source
/// and prints a new failure's seed instead of appending it to that file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommittedRegressions;

/// Where the committed seeds of a test file are: `tests/x.rs` → `tests/x.proptest-regressions`.
const BESIDE_THE_SOURCE: FileFailurePersistence =
    FileFailurePersistence::WithSource("proptest-regressions");

impl FailurePersistence for CommittedRegressions {
    fn load_persisted_failures2(&self, source_file: Option<&'static str>) -> Vec<PersistedSeed> {
        BESIDE_THE_SOURCE.load_persisted_failures2(source_file)
    }

    fn save_persisted_failure2(
        &mut self,
        source_file: Option<&'static str>,
        seed: PersistedSeed,
        shrunken_value: &dyn std::fmt::Debug,
    ) {
        let file = source_file
            .map(|s| {
                format!(
                    "{}",
                    std::path::Path::new(s)
                        .with_extension("proptest-regressions")
                        .display()
                )
            })
            .unwrap_or_else(|| "the test's .proptest-regressions file".to_string());
        eprintln!(
            "proptest: new failing case (not written to the tree). To replay it in every run, \
             commit this line to {file}:\n{seed} # shrinks to {shrunken_value:?}"
        );
    }

    fn box_clone(&self) -> Box<dyn FailurePersistence> {
        Box::new(*self)
    }

    fn eq(&self, other: &dyn FailurePersistence) -> bool {
        other.as_any().downcast_ref::<Self>().is_some()
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
