//! The wired serial line between board A and board B in the realtime engine: a Unix stream
//! socket pair, read by the receiving node itself at its tick.
//!
//! The octets one board writes are in the socket's buffer when its write returns, so the other
//! board sees them at its first tick after that, however busy the host. Until issue 40 a reader
//! thread of its own deframed each line into a channel: on a loaded 2-core host (the wall-clock
//! tests run nine engines side by side) that thread could be kept off the cores for longer than
//! board B's 500 ms of silence at 10× (50 ms of wall time), and board A declared
//! `internal_comm_loss` with B's heartbeats waiting in the pipe (measured: 1 run in 3 of the
//! wall-clock checks, `host/tests/wall_clock.rs`, 2026-11-29). The paced clock (`super::clock`)
//! holds simulated time for a slow node, not for a slow thread between two nodes; with no such
//! thread there is nothing to hold.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//! use mmic_host::sim::serial_line;
//! use std::io::Write;
//!
//! let (mut tx, mut rx) = serial_line::pair().unwrap();
//! assert_eq!(rx.try_recv(), None);
//! let stop = CommandRepr { board: BoardNumber::ONE, command: Command::Stop, seq: 0 }.to_bytes();
//! tx.write_all(&stop[..5]).unwrap(); // half a packet: nothing yet
//! assert_eq!(rx.try_recv(), None);
//! tx.write_all(&stop[5..]).unwrap();
//! tx.write_all(&stop).unwrap();
//! assert_eq!(rx.try_recv(), Some(stop.to_vec())); // two packets, one at a time
//! assert_eq!(rx.try_recv(), Some(stop.to_vec()));
//! drop(tx);
//! assert_eq!(rx.try_recv(), None); // closed
//! ```

use mmic::wire::deframer::{Deframed, Deframer};
use std::collections::VecDeque;
use std::io::{ErrorKind, Read};
use std::os::unix::net::UnixStream;

/// A serial line's two ends: the writing one, and the receiving one read at the owner's tick.
pub fn pair() -> std::io::Result<(UnixStream, SerialRx)> {
    let (write, read) = UnixStream::pair()?;
    read.set_nonblocking(true)?;
    Ok((write, SerialRx::new(read)))
}

/// The receiving end of a serial line: the packets its deframer found, in order.
#[derive(Debug)]
pub struct SerialRx {
    stream: UnixStream,
    deframer: Deframer<256>,
    ready: VecDeque<Vec<u8>>,
}

impl SerialRx {
    /// A receiving end over `stream`, which must be non-blocking ([`pair`] makes it so).
    fn new(stream: UnixStream) -> SerialRx {
        SerialRx {
            stream,
            deframer: Deframer::new(),
            ready: VecDeque::new(),
        }
    }

    /// The next packet the line has delivered, if any: first reads all the line holds now.
    /// A closed line, like an idle one, delivers nothing more.
    pub fn try_recv(&mut self) -> Option<Vec<u8>> {
        let mut buf = [0u8; 256];
        loop {
            match self.stream.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    let ready = &mut self.ready;
                    self.deframer.feed(&buf[..n], |e| {
                        if let Deframed::Frame(f) = e {
                            ready.push_back(f.as_bytes().to_vec());
                        }
                    });
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(_) => break, // WouldBlock: nothing more for now
            }
        }
        self.ready.pop_front()
    }
}
