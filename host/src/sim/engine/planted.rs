//! The bugs the engine can be told to have, for the fault swarm's own tests.

/// A bug the engine's shells can be told to have, so that a test can show the fault swarm
/// finds it (`mmic swarm --plant-bug double-exec`). None is ever on in a plain run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlantedBug {
    /// No bug.
    #[default]
    None,
    /// Board A's WiFi task hands a copy of a command the WiFi link duplicated to the control
    /// task with its sequence number cleared (an unsequenced command, which board A runs
    /// whatever its log says: the paper's scheme): a double execution on a duplicated packet.
    DoubleExec,
    /// Board A restarts without its exactly-once log (as if the shell never read flash back):
    /// a command resent after a restart runs again.
    LogNotRestored,
}

impl std::str::FromStr for PlantedBug {
    type Err = String;
    fn from_str(s: &str) -> Result<PlantedBug, String> {
        match s {
            "none" => Ok(PlantedBug::None),
            "double-exec" => Ok(PlantedBug::DoubleExec),
            "log-not-restored" => Ok(PlantedBug::LogNotRestored),
            _ => Err(format!(
                "{s:?} is no planted bug: none, double-exec or log-not-restored"
            )),
        }
    }
}
