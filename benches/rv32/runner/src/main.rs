//! The bare-metal RV32IMC runner: replays a trace (`mmic sim --record`) through
//! [`mmic_replay`] on QEMU's `virt` machine, and writes, through semihosting, the output stream
//! (to compare with the host's, `mmic replay --against`) and each call's cost: instructions per
//! phase from `minstret` (exact under `-icount shift=0`) and its stack depth from a painted
//! stack.
//!
//! `mmic-rv32 --parsers` counts the instructions of each host benchmark's packet parse instead.
//!
//! ```text
//! qemu-system-riscv32 -M virt -m 64M -bios none -nographic -icount shift=0 \
//!   -semihosting-config enable=on,target=native,arg=mmic-rv32,arg=TRACE,arg=OUT,arg=COST \
//!   -kernel target/riscv32imc-unknown-none-elf/release/mmic-rv32
//! ```
//!
//! This is a shell: file I/O, the instruction counter and the stack paint. The stack paint
//! writes and reads memory below the stack pointer, which needs `unsafe`; nothing else does.
#![no_std]
#![no_main]

use core::ffi::CStr;
use mmic_replay::cost::{Cost, COST_LEN};
use mmic_replay::trace::{Record, Trace};
use mmic_replay::{Call, Meter, Phase, Replay, Sink};
use riscv::register::minstret;
use semihosting::fs::File;
use semihosting::io::{Read, Write};
use semihosting::{eprintln, println};

/// The largest trace, bytes.
const TRACE_MAX: usize = 4 << 20;
/// How far below the replay loop's frame the stack is painted, bytes: a call that reaches the
/// bottom is reported, not measured.
const PAINT: usize = 32 * 1024;
/// The paint.
const PAINT_WORD: u32 = 0x5ac3_5ac3;

#[riscv_rt::entry]
fn main() -> ! {
    let code = match run() {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("mmic-rv32: {e}");
            1
        }
    };
    semihosting::process::exit(code)
}

/// A path argument as a C string, in `buf`.
fn c_path<'b>(arg: &str, buf: &'b mut [u8; 512]) -> Result<&'b CStr, &'static str> {
    let b = arg.as_bytes();
    let d = buf
        .get_mut(..b.len())
        .ok_or("a path is longer than 511 bytes")?;
    d.copy_from_slice(b);
    buf[b.len()] = 0;
    CStr::from_bytes_until_nul(&buf[..=b.len()]).map_err(|_| "a path holds a NUL byte")
}

/// A file written through a buffer (a semihosting call per 64 KiB, not per record).
struct Buffered {
    file: File,
    buf: [u8; 64 * 1024],
    len: usize,
    bytes: usize,
    failed: bool,
}

impl Buffered {
    fn flush(&mut self) {
        if self.len > 0 && self.file.write_all(&self.buf[..self.len]).is_err() {
            self.failed = true;
        }
        self.len = 0;
    }
}

impl Sink for Buffered {
    fn put(&mut self, mut bytes: &[u8]) {
        self.bytes += bytes.len();
        while !bytes.is_empty() {
            if self.len == self.buf.len() {
                self.flush();
            }
            let n = bytes.len().min(self.buf.len() - self.len);
            self.buf[self.len..self.len + n].copy_from_slice(&bytes[..n]);
            self.len += n;
            bytes = &bytes[n..];
        }
    }
}

fn run() -> Result<(), &'static str> {
    let args = semihosting::experimental::env::args::<1024>().map_err(|_| "no arguments")?;
    let mut it = &args;
    let _program = it.next();
    let mut next = || -> Result<&str, &'static str> {
        it.next()
            .ok_or("usage: mmic-rv32 TRACE OUT COST")?
            .map_err(|_| "an argument is not UTF-8")
    };
    let first = next()?;
    if first == "--parsers" {
        return parsers();
    }
    if first == "--sdls" {
        return sdls();
    }
    let (trace_path, out_path, cost_path) = (first, next()?, next()?);

    let mut p = [0u8; 512];
    let mut trace = [0u8; TRACE_MAX];
    let mut f = File::open(c_path(trace_path, &mut p)?).map_err(|_| "cannot open the trace")?;
    let mut n = 0;
    loop {
        let room = trace.get_mut(n..).unwrap_or(&mut []);
        if room.is_empty() {
            return Err("the trace is larger than 4 MiB");
        }
        match f.read(room) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(_) => return Err("cannot read the trace"),
        }
    }
    let t = Trace::parse(&trace[..n]).map_err(|_| "not a replay trace")?;
    let create = |path: &str, p: &mut [u8; 512]| -> Result<Buffered, &'static str> {
        Ok(Buffered {
            file: File::create(c_path(path, p)?).map_err(|_| "cannot create an output file")?,
            buf: [0; 64 * 1024],
            len: 0,
            bytes: 0,
            failed: false,
        })
    };
    let mut out = create(out_path, &mut p)?;
    let mut costs = create(cost_path, &mut p)?;
    let mut replay = Replay::new(&t.header);
    let records = drive(&t, &mut replay, &mut out, &mut costs)?;
    out.flush();
    costs.flush();
    if out.failed || costs.failed {
        return Err("cannot write an output file");
    }
    println!(
        "mmic-rv32: {records} records, {} output bytes, {} cost bytes",
        out.bytes, costs.bytes
    );
    Ok(())
}

/// `mmic-rv32 --parsers`: each host benchmark's parse, its instructions (the fewest of 16
/// runs; they are all equal under `-icount shift=0` once the caches of QEMU's translation are
/// warm), as Markdown rows.
fn parsers() -> Result<(), &'static str> {
    use mmic_replay::parsers::{Sample, SAMPLES};
    println!("| parser | RV32IMC instructions |\n|---|---|");
    for k in SAMPLES {
        let s = Sample::new(k);
        let mut best = u32::MAX;
        for _ in 0..16 {
            let a = minstret::read() as u32;
            let ok = s.parse();
            let b = minstret::read() as u32;
            if !ok {
                return Err("a benchmark packet was refused");
            }
            best = best.min(b.wrapping_sub(a));
        }
        println!("| {} | {best} |", k.name());
    }
    Ok(())
}

/// `mmic-rv32 --sdls`: SDLS on the server board, each operation's instructions (the fewest of
/// 16 runs) and stack, as Markdown rows: verifying a protected TC frame (YAMCS's first frame:
/// one 13-octet TC(17,1), 51 octets), refusing one with a flipped data bit (the MAC's cost)
/// and a replay (no cryptography), protecting a 256-octet TM frame. Each run starts from a
/// copy of the same association, made before the count starts; the key schedule is not part
/// of an operation (an association builds it once, when it is made). The key is a fixed test
/// pattern. Then checks that a dropped association's key schedule is all zeros.
fn sdls() -> Result<(), &'static str> {
    use mmic::ccsds::primary::{Apid, SeqCount};
    use mmic::ccsds::tc::TcRepr;
    use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
    use mmic::link::sdls::{frames, mission, Key256, SaTable, HEADER_LEN, MAC_LEN};
    use mmic::link::tc_frame::{self, MapId, SpacecraftId, TcContent, TcFrame, TcFrameRepr, Vcid};
    use mmic::link::tm_frame::{TmFrameParams, TM_FRAME_LEN};
    use mmic::units::BoardNumber;

    let one = BoardNumber::ONE;
    let key = || Key256::from_bytes([0x3c; 32]);
    let reserve = |t: &mut SaTable<1>| {
        let due: Option<(u16, u128)> = t.due().next();
        if let Some((spi, v)) = due {
            t.persisted(spi, v);
        }
    };
    let mut ground: SaTable<1> = SaTable::new();
    ground
        .add(mission::tc_sender(one, key(), None))
        .map_err(|_| "table")?;
    reserve(&mut ground);
    let mut robot: SaTable<1> = SaTable::new();
    robot
        .add(mission::tc_receiver(one, key(), None))
        .map_err(|_| "table")?;
    reserve(&mut robot);
    let mut packet = [0u8; 13];
    TcRepr {
        apid: Apid::new(0x101).map_err(|_| "apid")?,
        seq_count: SeqCount::new(0).map_err(|_| "seq")?,
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 17,
            subservice: 1,
            source_id: 0,
        },
        app_data: &[],
    }
    .emit(&mut packet)
    .map_err(|_| "packet")?;
    let repr = TcFrameRepr {
        spacecraft_id: SpacecraftId::of_board(one),
        vcid: Vcid::new(0).map_err(|_| "vcid")?,
        seq: 0,
        content: TcContent::Ad {
            map_id: MapId::new(0).ok(),
            data: &packet,
        },
    };
    let mut good = [0u8; 64];
    let n = frames::protect_tc(&mut ground, mission::tc_spi(one), &repr, &mut good)
        .map_err(|_| "protect")?;
    let mut bad = good;
    bad[6 + HEADER_LEN] ^= 1;
    let crc = mmic::ccsds::pec(&bad[..n - 2]);
    bad[n - 2..n].copy_from_slice(&crc.to_be_bytes());
    let config = tc_frame::mission(SpacecraftId::of_board(one));
    let mut replayed = robot.clone();
    {
        let f = TcFrame::new_checked(&good[..n], &config).map_err(|_| "frame")?;
        let mut plain = [0u8; tc_frame::MAX_FRAME_LEN];
        frames::verify_tc(&mut replayed, &f, &mut plain).map_err(|_| "first verify")?;
    }
    let top = sp() & !3;
    let bottom = top - PAINT;
    let measure = |f: &mut dyn FnMut(usize) -> bool| -> Result<(u32, usize), &'static str> {
        let mut best = u32::MAX;
        let mut stack = 0;
        for k in 0..16 {
            // SAFETY: as in `drive`: [bottom, top - 64) is unused stack below this frame.
            unsafe { paint(bottom, top - 64) };
            let a = minstret::read() as u32;
            let ok = f(k);
            let b = minstret::read() as u32;
            stack = stack.max(top - lowest_dirty(bottom, top - 64));
            if !ok {
                return Err("an SDLS operation did not give the expected outcome");
            }
            best = best.min(b.wrapping_sub(a));
        }
        Ok((best, stack))
    };
    // One copy of the association per run, made before any count starts.
    fn copies<T: Clone>(t: &T) -> [T; 16] {
        core::array::from_fn(|_| t.clone())
    }
    let verify = |tables: &mut [SaTable<1>; 16], bytes: &[u8], accept: bool, k: usize| {
        let Ok(f) = TcFrame::new_checked(bytes, &config) else {
            return false;
        };
        let mut plain = [0u8; tc_frame::MAX_FRAME_LEN];
        frames::verify_tc(&mut tables[k], &f, &mut plain).is_ok() == accept
    };
    println!("| SDLS operation on the server board | RV32IMC instructions | stack, bytes |\n|---|--:|--:|");
    let mut t = copies(&robot);
    let (i, st) = measure(&mut |k| verify(&mut t, &good[..n], true, k))?;
    println!("| verify and decrypt a TC frame ({n} octets: a 13-octet TC(17,1)), frame checks included | {i} | {st} |");
    let mut t = copies(&robot);
    let (i, st) = measure(&mut |k| verify(&mut t, &bad[..n], false, k))?;
    println!("| refuse it with one data bit flipped (bad MAC) | {i} | {st} |");
    let mut t = copies(&replayed);
    let (i, st) = measure(&mut |k| verify(&mut t, &good[..n], false, k))?;
    println!("| refuse it replayed (before any cryptography) | {i} | {st} |");
    let params = TmFrameParams::mission(0x101)
        .and_then(|p| p.with_security(HEADER_LEN as u8, MAC_LEN as u8))
        .ok_or("params")?;
    let mut tm: SaTable<1> = SaTable::new();
    tm.add(mission::tm_sender(one, key(), None))
        .map_err(|_| "table")?;
    reserve(&mut tm);
    let mut t = copies(&tm);
    let mut frame = [0x55u8; TM_FRAME_LEN];
    let (i, st) = measure(&mut |k| {
        frames::protect_tm(&mut t[k], mission::tm_spi(one), &params, &mut frame).is_ok()
    })?;
    println!("| protect a 256-octet TM frame (214 octets encrypted, FECF again) | {i} | {st} |");
    dropped_sa_is_zeroized(mission::tc_receiver(one, key(), None), &key().schedule())?;
    println!("\nmmic-rv32: a dropped security association's key schedule and GHASH key: all zeros");
    Ok(())
}

/// Checks, on the ESP32-C3's software backends, that dropping `sa` zeroizes the key schedule
/// and GHASH key it kept (`mmic::link::sdls::key`'s `zeroize` guarantee): finds the bytes of
/// `same` (a schedule of the same key: the backends build it deterministically) inside the
/// association, drops it in place and reads them again. Fails if the schedule is not found
/// (or is all zeros before the drop), or if one octet of it is not zero after.
fn dropped_sa_is_zeroized(
    sa: mmic::link::sdls::SecurityAssociation,
    same: &mmic::link::sdls::key::Schedule,
) -> Result<(), &'static str> {
    use core::mem::{size_of, MaybeUninit};
    let len = size_of::<mmic::link::sdls::key::Schedule>();
    let n = size_of::<mmic::link::sdls::SecurityAssociation>();
    let read = |a: usize| -> u8 {
        // SAFETY: `a` is inside `same` or `slot` below, live memory this function owns or
        // borrows; a volatile read of an octet, as the stack paint's.
        unsafe { core::ptr::read_volatile(a as *const u8) }
    };
    let pattern = same as *const _ as usize;
    if (0..len).all(|i| read(pattern + i) == 0) {
        return Err("a key schedule is all zeros before any drop");
    }
    let mut slot = MaybeUninit::new(sa);
    let base = slot.as_ptr() as usize;
    let at = (0..=n - len)
        .find(|&o| (0..len).all(|i| read(base + o + i) == read(pattern + i)))
        .ok_or("a security association holds no copy of its key's schedule")?;
    // SAFETY: `slot` was initialised above and is dropped once; its storage stays in place
    // (and is only read) until this function returns.
    unsafe { slot.assume_init_drop() };
    if (0..len).any(|i| read(base + at + i) != 0) {
        return Err("a dropped security association left its key schedule in memory");
    }
    Ok(())
}

/// The stack pointer.
#[inline(always)]
fn sp() -> usize {
    let sp: usize;
    // SAFETY: reads a register into a local.
    unsafe { core::arch::asm!("mv {0}, sp", out(reg) sp, options(nomem, nostack)) };
    sp
}

/// Paints the words of `[from, to)`.
///
/// # Safety
/// The range must lie in RAM below every live stack frame.
#[inline(always)]
unsafe fn paint(from: usize, to: usize) {
    let mut a = from;
    while a < to {
        // SAFETY: the caller's range is unused stack.
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT_WORD) };
        a += 4;
    }
}

/// The lowest word of `[bottom, top)` that is no longer paint (`top` if none).
fn lowest_dirty(bottom: usize, top: usize) -> usize {
    let mut a = bottom;
    while a < top {
        // SAFETY: the range is the painted stack area, in RAM and word-aligned; reading it
        // has no effect.
        if unsafe { core::ptr::read_volatile(a as *const u32) } != PAINT_WORD {
            return a;
        }
        a += 4;
    }
    top
}

/// The frame gateway's library calls over a trace ([`Call`]): how many, the most
/// instructions one took and when, and their sum.
#[derive(Default, Clone, Copy)]
struct CallStat {
    calls: u32,
    max: u32,
    max_t: u32,
    sum: u64,
}

/// Counts instructions per phase and takes the stack depth when the output record starts.
struct Counter<'c> {
    bottom: usize,
    top: usize,
    phase: Phase,
    last: u32,
    acc: [u32; 4],
    stack_node: Option<usize>,
    t: u32,
    call_start: u32,
    calls: &'c mut [CallStat; 4],
}

impl Meter for Counter<'_> {
    #[inline(never)]
    fn call(&mut self, c: Call, start: bool) {
        let now = minstret::read() as u32;
        if start {
            self.call_start = now;
            return;
        }
        let n = now.wrapping_sub(self.call_start);
        if let Some(s) = self.calls.get_mut(c as usize) {
            s.calls += 1;
            s.sum += u64::from(n);
            if n > s.max {
                s.max = n;
                s.max_t = self.t;
            }
        }
    }

    #[inline(never)]
    fn enter(&mut self, p: Phase) {
        let now = minstret::read() as u32;
        let i = self.phase as usize;
        self.acc[i] = self.acc[i].wrapping_add(now.wrapping_sub(self.last));
        if p == Phase::Record && self.stack_node.is_none() {
            self.stack_node = Some(self.top - lowest_dirty(self.bottom, self.top));
        }
        self.phase = p;
        self.last = minstret::read() as u32;
    }
}

/// Runs every record, each measured; returns how many ran.
#[inline(never)]
fn drive(
    t: &Trace<'_>,
    replay: &mut Replay,
    out: &mut Buffered,
    costs: &mut Buffered,
) -> Result<usize, &'static str> {
    // Every call below starts its frames at this stack pointer.
    let top = sp() & !3;
    let bottom = top - PAINT;
    // SAFETY: [bottom, top - 64) is below this function's frame and unused: the stack is 64 MiB
    // minus the program, far more than PAINT (riscv-rt's memory.x gives the stack the rest of
    // RAM), and nothing else runs (one hart, no interrupts enabled).
    unsafe { paint(bottom, top - 64) };
    let mut n = 0;
    let mut calls = [CallStat::default(); 4];
    for rec in t.records() {
        let rec = rec.map_err(|_| "a trace record is malformed")?;
        let mut m = Counter {
            bottom,
            top,
            phase: Phase::Glue,
            last: 0,
            acc: [0; 4],
            stack_node: None,
            t: rec.t(),
            call_start: 0,
            calls: &mut calls,
        };
        m.last = minstret::read() as u32;
        step(replay, &rec, out, &mut m);
        m.enter(Phase::Record);
        let low = lowest_dirty(bottom, top - 64);
        if low == bottom {
            return Err("a call used more than the painted 32 KiB of stack");
        }
        let c = Cost {
            tag: rec.tag(),
            node: rec.node() as u8,
            t: rec.t(),
            phases: m.acc,
            stack_node: m.stack_node.unwrap_or(top - low) as u32,
            stack_all: (top - low) as u32,
        };
        let mut b = [0u8; COST_LEN];
        c.emit(&mut b);
        costs.put(&b);
        // SAFETY: as above; the words below `low` are still paint.
        unsafe { paint(low, top - 64) };
        n += 1;
    }
    // The frame gateway's own calls (a frames trace only): each call's instructions, between
    // two reads of minstret around it.
    for (c, s) in Call::ALL.iter().zip(calls) {
        if s.calls > 0 {
            println!(
                "mmic-rv32: frame gateway {}: {} calls, instructions max {} (at {} ms), mean {}",
                c.name(),
                s.calls,
                s.max,
                s.max_t,
                s.sum / u64::from(s.calls)
            );
        }
    }
    Ok(n)
}

/// One call, in a frame of its own below `drive`'s stack pointer, so that the call's own
/// locals (whatever is inlined into it) are counted in its stack depth.
#[inline(never)]
fn step(replay: &mut Replay, rec: &Record<'_>, out: &mut Buffered, m: &mut Counter<'_>) {
    replay.step(rec, out, m);
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    eprintln!("mmic-rv32: panic");
    semihosting::process::exit(101)
}
