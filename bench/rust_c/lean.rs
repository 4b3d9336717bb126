//! The Rust codec against lean hand-written floors, in instructions (run under callgrind, one function counted
//! per run). Usage: lean write <dir> (the inputs: clean.bin, garbage.bin, distinct.bin) | lean <mode> <file>
//! with mode stream, floor_stream, decode or floor_decode | lean time <dir> (ns per unit, codec and floor, best
//! of 31 interleaved runs, for each input).
//!
//! The floors know only the frame format: tables built here from the crate's `COMMANDS` (a category byte's
//! slot, a direction byte's command, each command's range), each byte checked as it arrives and a slide of one
//! byte on an invalid one, but no timeouts, no error kinds or counts and no `last_error`.
use std::hint::black_box;
use std::time::Instant;

use drone_protocol::{decode, encode, StreamParser, COMMANDS, FRAME_LENGTH, WIRE_LENGTH};

/// The floor's tables.
pub struct Lean {
    category: [u16; 256],      // slot + 1 of a category byte (0: none)
    command: Vec<[u16; 256]>,  // by slot: the command + 1 of a direction byte (0: none)
    range: Vec<(u32, u32)>,    // by command
}

impl Lean {
    fn new() -> Lean {
        let mut lean = Lean { category: [0; 256], command: Vec::new(), range: Vec::new() };
        for (i, c) in COMMANDS.iter().enumerate() {
            let code = usize::from(c.category.code());
            if lean.category[code] == 0 {
                lean.command.push([0; 256]);
                lean.category[code] = lean.command.len() as u16;
            }
            lean.command[usize::from(lean.category[code]) - 1][usize::from(c.direction)] = i as u16 + 1;
            lean.range.push((c.min.into(), c.max.into()));
        }
        lean
    }
}

/// The floor's parser: the command + 1 after byte 1, the value so far.
#[derive(Default)]
struct State {
    bytes: [u8; FRAME_LENGTH],
    length: usize,
    slot: u16,
    command: u16,
    value: u32,
}

impl State {
    /// Take `byte` at the next position: Some(true) when it completes a valid frame, None when it is invalid.
    #[inline(always)]
    fn push(&mut self, t: &Lean, byte: u8) -> Option<bool> {
        let n = self.length;
        if n == 0 {
            self.slot = t.category[usize::from(byte)]; // a 256-entry table: no bounds check
            if self.slot == 0 {
                return None;
            }
        } else if n == 1 {
            // SAFETY: slot is 1..=t.command.len() (set from the category table at byte 0).
            self.command = unsafe { t.command.get_unchecked(usize::from(self.slot) - 1) }[usize::from(byte)];
            if self.command == 0 {
                return None;
            }
            self.value = 0;
        } else {
            let digit = byte.wrapping_sub(b'0');
            if digit > 9 {
                return None;
            }
            self.value = self.value * 10 + u32::from(digit);
        }
        // SAFETY: n < FRAME_LENGTH (length is reset when it reaches FRAME_LENGTH or fails the range).
        unsafe { *self.bytes.get_unchecked_mut(n) = byte };
        self.length = n + 1;
        if self.length < FRAME_LENGTH {
            return Some(false);
        }
        // SAFETY: command is 1..=t.range.len() (set from the direction table at byte 1).
        let (min, max) = *unsafe { t.range.get_unchecked(usize::from(self.command) - 1) };
        if self.value < min || self.value > max {
            return None; // length stays FRAME_LENGTH: the slide re-reads the frame after its first byte
        }
        self.length = 0;
        Some(true)
    }
}

#[no_mangle]
#[inline(never)]
pub fn floor_stream(t: &Lean, bytes: &[u8]) -> usize {
    let mut s = State::default();
    let mut found = 0;
    for &b in bytes {
        match s.push(t, b) {
            Some(complete) => found += usize::from(complete),
            None => {
                // Slide: re-read what was held after its first byte, then the new byte, from an empty state.
                let mut held = [0u8; FRAME_LENGTH];
                let n = if s.length == FRAME_LENGTH {
                    held.copy_from_slice(&s.bytes);
                    FRAME_LENGTH - 1
                } else {
                    held[..s.length].copy_from_slice(&s.bytes[..s.length]);
                    held[s.length] = b;
                    s.length
                };
                let mut start = 1;
                'slide: while start <= n {
                    s.length = 0;
                    for &h in &held[start..=n] {
                        if s.push(t, h).is_none() {
                            start += 1;
                            continue 'slide;
                        }
                    }
                    break;
                }
                if start > n {
                    s.length = 0;
                }
            }
        }
    }
    found
}

#[no_mangle]
#[inline(never)]
pub fn bench_stream(bytes: &[u8]) -> usize {
    let mut parser = StreamParser::new();
    let mut found = 0;
    for &b in bytes {
        found += usize::from(parser.feed(b, 0).is_some());
    }
    found
}

#[no_mangle]
#[inline(never)]
pub fn floor_decode(t: &Lean, frames: &[u8]) -> usize {
    let mut sum = 0;
    for f in frames.chunks_exact(FRAME_LENGTH) {
        let mut s = State::default();
        if f.iter().all(|&b| s.push(t, b).is_some()) {
            sum += s.value as usize;
        }
    }
    sum
}

#[no_mangle]
#[inline(never)]
pub fn bench_decode(frames: &[u8]) -> usize {
    frames.chunks_exact(WIRE_LENGTH).map(|f| decode(f).map_or(0, |c| usize::from(c.value))).sum()
}

/// A xorshift generator: the same inputs in every run.
struct Random(u64);

impl Random {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

fn frame(i: usize, value: u16) -> [u8; WIRE_LENGTH] {
    let mut out = [0; WIRE_LENGTH];
    encode(drone_protocol::CommandId::ALL[i], value, &mut out).expect("a value in range");
    out
}

/// clean.bin: random valid frames; garbage.bin: the same with random bytes between them, half the stream;
/// distinct.bin: distinct valid frames (every command at distinct values, shuffled).
fn write(dir: &str, size: usize) {
    let mut r = Random(0x9E37_79B9_7F4A_7C15);
    let pick = |r: &mut Random| {
        let i = r.below(COMMANDS.len());
        let c = &COMMANDS[i];
        frame(i, c.min + r.below(usize::from(c.max - c.min) + 1) as u16)
    };
    let (mut clean, mut garbage) = (Vec::new(), Vec::new());
    while clean.len() < size {
        clean.extend_from_slice(&pick(&mut r));
    }
    while garbage.len() < size {
        garbage.extend_from_slice(&pick(&mut r));
        for _ in 0..WIRE_LENGTH {
            garbage.push(r.below(256) as u8);
        }
    }
    let mut all: Vec<[u8; WIRE_LENGTH]> = Vec::new();
    for (i, c) in COMMANDS.iter().enumerate() {
        let step = (usize::from(c.max - c.min) + 1).div_ceil(64).max(1);
        all.extend((usize::from(c.min)..=usize::from(c.max)).step_by(step).map(|v| frame(i, v as u16)));
    }
    for i in (1..all.len()).rev() {
        all.swap(i, r.below(i + 1));
    }
    std::fs::write(format!("{dir}/clean.bin"), &clean[..size]).expect("clean.bin");
    std::fs::write(format!("{dir}/garbage.bin"), &garbage[..size]).expect("garbage.bin");
    std::fs::write(format!("{dir}/distinct.bin"), all.concat()).expect("distinct.bin");
}

/// Best ns per unit of the codec and of the floor on each input, timed alternately.
fn time(dir: &str) {
    let t = Lean::new();
    for (name, unit) in [("clean", 1), ("garbage", 1), ("distinct", FRAME_LENGTH)] {
        let input = std::fs::read(format!("{dir}/{name}.bin")).expect("an input file");
        let units = (input.len() / unit) as f64;
        let (mut ours, mut floor) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..31 {
            let start = Instant::now();
            black_box(if unit == 1 { bench_stream(black_box(&input)) } else { bench_decode(black_box(&input)) });
            ours = ours.min(start.elapsed().as_nanos() as f64 / units);
            let start = Instant::now();
            black_box(if unit == 1 { floor_stream(&t, black_box(&input)) } else { floor_decode(&t, black_box(&input)) });
            floor = floor.min(start.elapsed().as_nanos() as f64 / units);
        }
        println!("{name} {ours:.3} {floor:.3}");
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args[1] == "write" {
        write(&args[2], args.get(3).map_or(200_000, |n| n.parse().expect("a size")));
        return;
    }
    if args[1] == "time" {
        time(&args[2]);
        return;
    }
    let input = std::fs::read(&args[2]).expect("an input file");
    let t = Lean::new();
    let result = match args[1].as_str() {
        "stream" => bench_stream(black_box(&input)),
        "floor_stream" => floor_stream(&t, black_box(&input)),
        "decode" => bench_decode(black_box(&input)),
        "floor_decode" => floor_decode(&t, black_box(&input)),
        mode => panic!("unknown mode {mode}"),
    };
    println!("{result}");
}
