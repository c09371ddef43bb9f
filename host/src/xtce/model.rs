//! The typed XTCE 1.2 model: only the constructs the mission database uses, each a Rust type,
//! so that building the database (telemetry.rs, commands.rs) and writing it (write.rs) are
//! apart. Element and attribute names are XTCE's; the writer keeps every attribute's position.

/// The whole `SpaceSystem`: telemetry, then commands.
#[derive(Debug, Clone, PartialEq)]
pub struct SpaceSystem {
    /// `name` (parameters are `/NAME/param` in YAMCS).
    pub name: &'static str,
    /// The XML comment before the root element (generated-file notice, packet format).
    pub preamble: &'static str,
    /// `TelemetryMetaData`.
    pub telemetry: Telemetry,
    /// `CommandMetaData`.
    pub commands: Commands,
}

/// `TelemetryMetaData`: parameter types, parameters and the containers that place them.
#[derive(Debug, Clone, PartialEq)]
pub struct Telemetry {
    /// `ParameterTypeSet`, in output order.
    pub types: Vec<DataType>,
    /// `ParameterSet`.
    pub parameters: Vec<Parameter>,
    /// `ContainerSet`.
    pub containers: Vec<Container>,
}

/// `CommandMetaData`: argument types and meta-commands.
#[derive(Debug, Clone, PartialEq)]
pub struct Commands {
    /// `ArgumentTypeSet`, in output order.
    pub types: Vec<DataType>,
    /// `MetaCommandSet`: the abstract `pus-tc` first, then every concrete command.
    pub meta_commands: Vec<MetaCommand>,
}

/// Whether a data type is a parameter's or an argument's: XTCE names the element after it
/// (`IntegerParameterType`, `EnumeratedArgumentType`, ...) but the content is the same.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// In `ParameterTypeSet`.
    Parameter,
    /// In `ArgumentTypeSet`.
    Argument,
}

/// A parameter or argument type. Every one is unsigned and integer-encoded on the wire.
#[derive(Debug, Clone, PartialEq)]
pub enum DataType {
    /// `Integer{Parameter,Argument}Type`.
    Integer(IntegerType),
    /// `Enumerated{Parameter,Argument}Type`.
    Enumerated(EnumeratedType),
}

/// An unsigned integer type.
#[derive(Debug, Clone, PartialEq)]
pub struct IntegerType {
    /// Parameter or argument type.
    pub role: Role,
    /// `name`.
    pub name: String,
    /// `shortDescription`, if any.
    pub description: Option<String>,
    /// `UnitSet`, if any.
    pub unit: Option<Unit>,
    /// `IntegerDataEncoding sizeInBits`.
    pub bits: usize,
    /// `ValidRange` (inclusive), if any: YAMCS refuses a command argument outside it.
    pub range: Option<(u32, u32)>,
}

/// A unit: its symbol and, if given, its `description`.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    /// The element's text.
    pub symbol: String,
    /// `description`.
    pub description: Option<&'static str>,
}

/// An enumerated type: integer values with labels.
#[derive(Debug, Clone, PartialEq)]
pub struct EnumeratedType {
    /// Parameter or argument type.
    pub role: Role,
    /// `name`.
    pub name: String,
    /// `shortDescription`.
    pub description: String,
    /// `IntegerDataEncoding sizeInBits`.
    pub bits: usize,
    /// `EnumerationList`: (value, label).
    pub values: Vec<(u32, String)>,
}

/// A telemetry parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// `name`.
    pub name: String,
    /// `parameterTypeRef`.
    pub type_ref: String,
    /// `shortDescription`.
    pub description: String,
}

/// A `SequenceContainer`: the parameters it holds in order, and which packets it matches.
#[derive(Debug, Clone, PartialEq)]
pub struct Container {
    /// `name`.
    pub name: String,
    /// `abstract="true"`: only a base for others (the TM header).
    pub is_abstract: bool,
    /// `shortDescription`.
    pub description: String,
    /// `EntryList`: parameter names.
    pub entries: Vec<String>,
    /// `BaseContainer` and its restriction, if it derives from one.
    pub base: Option<BaseContainer>,
}

/// The container a `SequenceContainer` continues, and when it applies.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseContainer {
    /// `containerRef`.
    pub container: String,
    /// `RestrictionCriteria`.
    pub restriction: Restriction,
}

/// A container's `RestrictionCriteria`.
#[derive(Debug, Clone, PartialEq)]
pub enum Restriction {
    /// `ComparisonList`: all must hold.
    All(Vec<Comparison>),
    /// `BooleanExpression`: all of `all` and at least one of `any` (YAMCS has no
    /// set-membership test; a list of subservices needs the OR).
    AllAndAny {
        /// `ANDedConditions`' conditions.
        all: Vec<Comparison>,
        /// `ORedConditions`' conditions.
        any: Vec<Comparison>,
    },
}

/// One comparison of a parameter's raw value with a constant.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// `parameterRef`.
    pub parameter: String,
    /// The operator.
    pub op: Op,
    /// The raw (uncalibrated) value.
    pub value: u32,
}

/// A comparison operator, as XTCE writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// `==` (XTCE's default in a `Comparison`).
    Eq,
    /// `>=`.
    Ge,
    /// `<=`.
    Le,
}

impl Op {
    /// The operator's XTCE text.
    pub fn text(self) -> &'static str {
        match self {
            Op::Eq => "==",
            Op::Ge => ">=",
            Op::Le => "<=",
        }
    }
}

impl Comparison {
    /// `parameter op value`.
    pub fn new(parameter: &str, op: Op, value: u32) -> Self {
        Self {
            parameter: parameter.into(),
            op,
            value,
        }
    }
}

/// A `MetaCommand`: the abstract `pus-tc` (header arguments, verifiers) or a concrete TC
/// deriving from it.
#[derive(Debug, Clone, PartialEq)]
pub struct MetaCommand {
    /// `name`.
    pub name: String,
    /// `abstract="true"`.
    pub is_abstract: bool,
    /// `shortDescription`.
    pub description: String,
    /// `BaseMetaCommand` and its argument assignments (name, value), if it derives.
    pub base: Option<BaseMetaCommand>,
    /// `ArgumentList` (left out when empty).
    pub arguments: Vec<Argument>,
    /// `CommandContainer`.
    pub container: CommandContainer,
    /// An XML comment before the verifiers (why they are what they are).
    pub verifier_note: Option<&'static str>,
    /// `VerifierSet` (left out when empty).
    pub verifiers: Vec<Verifier>,
}

/// The meta-command a command derives from, with the base's arguments it fixes.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMetaCommand {
    /// `metaCommandRef`.
    pub meta_command: String,
    /// `ArgumentAssignment`s: (argumentName, argumentValue).
    pub assignments: Vec<(String, String)>,
}

/// A command argument.
#[derive(Debug, Clone, PartialEq)]
pub struct Argument {
    /// `name`.
    pub name: String,
    /// `argumentTypeRef`.
    pub type_ref: String,
    /// `initialValue` (the default when the operator gives none), if any.
    pub initial: Option<String>,
    /// `shortDescription`, if any.
    pub description: Option<String>,
}

/// A `CommandContainer`: the command's bits in order.
#[derive(Debug, Clone, PartialEq)]
pub struct CommandContainer {
    /// `name`.
    pub name: String,
    /// `EntryList`.
    pub entries: Vec<CommandEntry>,
    /// `BaseContainer containerRef`, if it continues another.
    pub base: Option<String>,
}

/// One entry of a command container.
#[derive(Debug, Clone, PartialEq)]
pub enum CommandEntry {
    /// `FixedValueEntry`: a constant.
    Fixed {
        /// `name`.
        name: &'static str,
        /// `binaryValue`: hexadecimal octets.
        hex: String,
        /// `sizeInBits`.
        bits: usize,
    },
    /// `ArgumentRefEntry`: an argument's value.
    Argument(String),
}

/// A command verifier: the ST\[1\] stage it stands for, checked by a custom algorithm within a
/// window from the command's release.
#[derive(Debug, Clone, PartialEq)]
pub struct Verifier {
    /// Which verifier element.
    pub stage: Stage,
    /// `CustomAlgorithm`: passes (or fails, for [`Stage::Failed`]) on the matching report.
    pub algorithm: Algorithm,
    /// `CheckWindow timeToStopChecking` (ISO 8601), relative to `commandRelease`.
    pub window: &'static str,
    /// `yamcs.onTimeout` FAIL: the command fails when the window closes without the report.
    pub fail_on_timeout: bool,
}

/// The ST\[1\] stages, as XTCE verifiers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// TM(1,1), `AcceptedVerifier`.
    Accepted,
    /// TM(1,3), an `ExecutionVerifier` named `Started`.
    Started,
    /// TM(1,7), `CompleteVerifier`.
    Complete,
    /// TM(1,2/4/8), `FailedVerifier`.
    Failed,
}

impl Stage {
    /// The verifier's element.
    pub fn element(self) -> &'static str {
        match self {
            Stage::Accepted => "AcceptedVerifier",
            Stage::Started => "ExecutionVerifier",
            Stage::Complete => "CompleteVerifier",
            Stage::Failed => "FailedVerifier",
        }
    }

    /// The verifier's `name`: only an `ExecutionVerifier` has one (YAMCS names the stage).
    pub fn name(self) -> Option<&'static str> {
        (self == Stage::Started).then_some("Started")
    }

    /// The stage's word in the algorithm's name (`st1_<word>`).
    pub fn word(self) -> &'static str {
        match self {
            Stage::Accepted => "accepted",
            Stage::Started => "started",
            Stage::Complete => "complete",
            Stage::Failed => "failed",
        }
    }
}

/// A `CustomAlgorithm`.
#[derive(Debug, Clone, PartialEq)]
pub struct Algorithm {
    /// `name`.
    pub name: String,
    /// `shortDescription`.
    pub description: String,
    /// `AlgorithmText language`.
    pub language: &'static str,
    /// `AlgorithmText`.
    pub text: String,
    /// `InputSet`.
    pub inputs: Vec<Input>,
}

/// An algorithm input: `InputParameterInstanceRef`.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// `parameterRef` (a qualified name).
    pub parameter: &'static str,
    /// `instance`, if not the default 0.
    pub instance: Option<u32>,
    /// `inputName`: the variable in the algorithm's text.
    pub name: &'static str,
}
