//! The opsUI ⇄ server board serial line on a real device ("RS232 over USB", Section 3): its
//! settings, read from spec/boards.toml `[ops_line]` (decision `opsui-serial-line`: 115,200
//! baud, 8 data bits, no parity, 1 stop bit, no flow control), and the device opened with them.
//! Both of the host's ends of the line use it: the opsUI (`mmic opsui --serial`,
//! [`crate::opsui`]) and the simulator's server board (`mmic sim --opsui-serial`,
//! [`crate::sim::opsline`]).
//!
//! The line carries the paper's packets as they are (14-byte commands one way, 66-byte
//! heartbeats the other); each end finds them with the library's deframer, and counts what it
//! drops.

use crate::error::CliError;
use serde::Deserialize;
use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};
use std::io::ErrorKind;
use std::time::Duration;

/// spec/boards.toml `[ops_line]`.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineSettings {
    /// Bits per second.
    pub baud: u32,
    /// 5..=8.
    pub data_bits: u8,
    /// `none`, `odd` or `even`.
    pub parity: String,
    /// 1 or 2.
    pub stop_bits: u8,
    /// `none`, `software` or `hardware`.
    pub flow_control: String,
}

#[derive(Deserialize)]
struct BoardsFile {
    ops_line: LineSettings,
}

impl LineSettings {
    /// The line's settings as spec/boards.toml gives them (compiled in).
    pub fn spec() -> Result<LineSettings, String> {
        toml::from_str::<BoardsFile>(crate::spec::BOARDS_TOML)
            .map(|f| f.ops_line)
            .map_err(|e| format!("spec/boards.toml [ops_line]: {e}"))
    }

    /// As `115200 8N1, no flow control`.
    pub fn describe(&self) -> String {
        let parity = self
            .parity
            .chars()
            .next()
            .unwrap_or('?')
            .to_ascii_uppercase();
        let flow = match self.flow_control.as_str() {
            "none" => "no",
            f => f,
        };
        format!(
            "{} {}{parity}{}, {flow} flow control",
            self.baud, self.data_bits, self.stop_bits
        )
    }

    /// The builder for `device` with these settings; a setting serialport has no value for is
    /// refused, naming it.
    pub fn builder(&self, device: &str) -> Result<serialport::SerialPortBuilder, String> {
        let data_bits = match self.data_bits {
            5 => DataBits::Five,
            6 => DataBits::Six,
            7 => DataBits::Seven,
            8 => DataBits::Eight,
            n => return Err(format!("data_bits = {n}: 5..=8")),
        };
        let parity = match self.parity.as_str() {
            "none" => Parity::None,
            "odd" => Parity::Odd,
            "even" => Parity::Even,
            p => return Err(format!("parity = {p:?}: none, odd or even")),
        };
        let stop_bits = match self.stop_bits {
            1 => StopBits::One,
            2 => StopBits::Two,
            n => return Err(format!("stop_bits = {n}: 1 or 2")),
        };
        let flow = match self.flow_control.as_str() {
            "none" => FlowControl::None,
            "software" => FlowControl::Software,
            "hardware" => FlowControl::Hardware,
            f => return Err(format!("flow_control = {f:?}: none, software or hardware")),
        };
        Ok(serialport::new(device, self.baud)
            .data_bits(data_bits)
            .parity(parity)
            .stop_bits(stop_bits)
            .flow_control(flow)
            .timeout(READ_TIMEOUT))
    }
}

/// How long a read waits for bytes before it returns none: short, so that one thread can both
/// poll the line and keep its clock (the opsUI's answer window is 700 ms).
pub const READ_TIMEOUT: Duration = Duration::from_millis(1);

/// Opens `device` with spec/boards.toml's settings (exclusively: a second opener is refused).
pub fn open(device: &str) -> Result<(Box<dyn SerialPort>, LineSettings), CliError> {
    let err = |why: String| CliError::SerialOpen {
        device: device.to_string(),
        why,
    };
    let settings = LineSettings::spec().map_err(err)?;
    let port = settings
        .builder(device)
        .map_err(|e| err(format!("spec/boards.toml [ops_line]: {e}")))?
        .open()
        .map_err(|e| err(e.to_string()))?;
    Ok((port, settings))
}

/// What a read of the line came to.
pub enum Read {
    /// This many bytes.
    Bytes(usize),
    /// None within [`READ_TIMEOUT`] (or the call was interrupted): the line is idle.
    Idle,
    /// The line is gone: end of file, hang-up (the other end of a pseudo-terminal closed, a USB
    /// adapter unplugged), or an I/O error; why, in words.
    Lost(String),
}

/// One read of the line into `buf`.
pub fn read(port: &mut dyn std::io::Read, buf: &mut [u8]) -> Read {
    match port.read(buf) {
        Ok(0) => Read::Lost("end of file (the other end closed)".into()),
        Ok(n) => Read::Bytes(n),
        Err(e)
            if matches!(
                e.kind(),
                ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
            ) =>
        {
            Read::Idle
        }
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            Read::Lost("hang-up (the other end closed)".into())
        }
        Err(e) => Read::Lost(e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: P3.3, D:opsui-serial-line
    #[test]
    fn the_spec_gives_the_decided_line() {
        let s = LineSettings::spec().unwrap();
        assert_eq!(s.describe(), "115200 8N1, no flow control");
        assert!(s.builder("/dev/null").is_ok());
    }

    // req: D:opsui-serial-line
    #[test]
    fn a_setting_serialport_cannot_take_is_named() {
        let mut s = LineSettings::spec().unwrap();
        s.parity = "mark".into();
        assert!(s.builder("/dev/null").unwrap_err().contains("parity"));
    }
}
