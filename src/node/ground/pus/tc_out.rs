//! A telecommand the ground's PUS link sends, and its bytes: a TC(8,1) function, or TC(17,1)
//! for a heartbeat request, every acknowledgement flag set.

use crate::ccsds::primary::{Apid, SeqCount};
use crate::ccsds::tc::TcRepr;
use crate::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use crate::ccsds::EmitError;
use crate::command::Command;
use crate::pus::function::{self, FunctionError};
use crate::pus::request::{ST_FUNCTION, ST_TEST};
use crate::pus::verification::RequestId;

/// A telecommand to send: its key and the command it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TcOut {
    /// APID and sequence count.
    pub request: RequestId,
    /// Source ID.
    pub source_id: u16,
    /// The command: a TC(8,1) function, or TC(17,1) for [`Command::Heartbeat`].
    pub command: Command,
}

/// Why a telecommand could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TcOutError {
    /// The command is no function.
    #[error("{0}")]
    Function(FunctionError),
    /// The buffer is too short.
    #[error("{0}")]
    Emit(EmitError),
}

impl TcOut {
    /// Service and subservice: (8, 1), or (17, 1) for a heartbeat request.
    pub const fn service(&self) -> (u8, u8) {
        match self.command {
            Command::Heartbeat => (ST_TEST, 1),
            _ => (ST_FUNCTION, 1),
        }
    }

    /// Writes the telecommand (every acknowledgement flag set); returns its length (at most
    /// [`MAX_TC_LEN`](super::MAX_TC_LEN)).
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, TcOutError> {
        let mut data = [0u8; function::MAX_LEN];
        let n = match self.command {
            Command::Heartbeat => 0,
            c => function::encode(&c, &mut data).map_err(TcOutError::Function)?,
        };
        let (service, subservice) = self.service();
        TcRepr {
            apid: Apid::new(self.request.apid).unwrap_or_default(),
            seq_count: SeqCount::new(self.request.seq_count).unwrap_or_default(),
            header: TcSecondaryHeader {
                ack: AckFlags::ALL,
                service,
                subservice,
                source_id: self.source_id,
            },
            app_data: data.get(..n).unwrap_or(&[]),
        }
        .emit(out)
        .map_err(TcOutError::Emit)
    }
}
