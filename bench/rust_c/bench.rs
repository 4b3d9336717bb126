//! Rust codec benchmark: encode and decode per frame and the stream parser per byte, each against a hand-written
//! floor in the same run. Usage: bench <stream file> time | stream (stream: only the parser, for callgrind).
use std::hint::black_box;
use std::time::Instant;

use drone_protocol::{decode, encode, CommandId, StreamParser, COMMANDS, FRAME_LENGTH};

/// The floor's table: (category, direction, min, max) of every command, copied from the crate's data.
fn table() -> Vec<(u8, u8, u16, u16)> {
    COMMANDS.iter().map(|c| (c.category.code(), c.direction, c.min, c.max)).collect()
}

/// Floor decode: slice and parse, a linear scan of the table; no error kinds.
fn floor_decode(table: &[(u8, u8, u16, u16)], f: &[u8]) -> Option<(usize, u16)> {
    if f.len() != FRAME_LENGTH {
        return None;
    }
    let mut value = 0u16;
    for &d in &f[2..] {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value * 10 + u16::from(d - b'0');
    }
    let i = table.iter().position(|&(c, d, _, _)| c == f[0] && d == f[1])?;
    (table[i].2 <= value && value <= table[i].3).then_some((i, value))
}

/// Floor encode: a string template (category, direction, zero-padded digits); no range check.
fn floor_encode(table: &[(u8, u8, u16, u16)], i: usize, value: u16, out: &mut [u8; FRAME_LENGTH]) {
    out[0] = table[i].0;
    out[1] = table[i].1;
    let mut v = value;
    for b in out[2..].iter_mut().rev() {
        *b = b'0' + (v % 10) as u8;
        v /= 10;
    }
}

#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_stream(bytes: *const u8, len: usize) -> usize {
    let bytes = unsafe { std::slice::from_raw_parts(bytes, len) };
    let mut parser = StreamParser::new();
    let mut found = 0;
    for &b in bytes {
        found += usize::from(parser.feed(b, 0).is_some());
    }
    found
}

fn floor_stream(table: &[(u8, u8, u16, u16)], bytes: &[u8]) -> usize {
    let (mut buf, mut len, mut found) = ([0u8; FRAME_LENGTH], 0, 0);
    for &b in bytes {
        buf[len] = b;
        len += 1;
        if len == FRAME_LENGTH {
            if floor_decode(table, &buf).is_some() {
                found += 1;
                len = 0;
            } else {
                buf.copy_within(1.., 0);
                len -= 1;
            }
        }
    }
    found
}

fn best_ns(reps: usize, count: usize, mut f: impl FnMut() -> usize) -> f64 {
    (0..reps)
        .map(|_| {
            let start = Instant::now();
            black_box(f());
            start.elapsed().as_nanos() as f64 / count as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let stream = std::fs::read(&args[1]).expect("stream file");
    if args[2] == "stream" {
        println!("{}", bench_stream(stream.as_ptr(), stream.len()));
        return;
    }
    let table = table();
    let frames: Vec<&[u8]> = stream.chunks_exact(FRAME_LENGTH).filter(|f| decode(f).is_ok()).take(100_000).collect();
    let pairs: Vec<(usize, u16)> = frames.iter().map(|f| floor_decode(&table, f).unwrap()).collect();
    let reps = 15;
    let mut out = [0u8; FRAME_LENGTH];
    let enc = best_ns(reps, pairs.len(), || {
        pairs.iter().map(|&(i, v)| encode(CommandId::ALL[i], black_box(v), &mut out).map_or(0, |_| out[5] as usize)).sum()
    });
    let enc_floor = best_ns(reps, pairs.len(), || {
        pairs.iter().map(|&(i, v)| { floor_encode(&table, i, black_box(v), &mut out); out[5] as usize }).sum()
    });
    let dec = best_ns(reps, frames.len(), || frames.iter().map(|f| decode(black_box(f)).map_or(0, |c| c.value as usize)).sum());
    let dec_floor = best_ns(reps, frames.len(), || {
        frames.iter().map(|f| floor_decode(&table, black_box(f)).map_or(0, |c| c.1 as usize)).sum()
    });
    let st = best_ns(reps, stream.len(), || bench_stream(black_box(stream.as_ptr()), stream.len()));
    let st_floor = best_ns(reps, stream.len(), || floor_stream(&table, black_box(&stream)));
    assert_eq!(bench_stream(stream.as_ptr(), stream.len()) > 0, floor_stream(&table, &stream) > 0);
    println!("encode_ns {enc:.2} {enc_floor:.2}");
    println!("decode_ns {dec:.2} {dec_floor:.2}");
    println!("stream_ns_per_byte {st:.2} {st_floor:.2}");
}
