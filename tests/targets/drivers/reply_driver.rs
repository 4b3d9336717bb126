//! Reply driver of the generated Rust crate: stdin one line per input line in hex; stdout what parse_reply() made
//! of it, "ready <protocol> <fingerprint> <integrity>", "ok <kind>", "malformed <kind>", "unknown" or "bad_check",
//! the format every language's reply driver shares.
use drone_protocol::{parse_reply, Reply, ReplyError};
use std::io::{BufRead, BufWriter, Write};

fn main() {
    let mut out = BufWriter::new(std::io::stdout().lock());
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("stdin");
        let bytes: Vec<u8> = (0..line.len() / 2).map(|i| u8::from_str_radix(&line[2 * i..2 * i + 2], 16).unwrap()).collect();
        match parse_reply(&bytes) {
            Ok(Reply::Ready { protocol, fingerprint, integrity }) => writeln!(out, "ready {protocol} {fingerprint} {integrity}"),
            Ok(Reply::Accepted { .. }) => writeln!(out, "ok accepted"),
            Ok(Reply::Rejected { .. }) => writeln!(out, "ok rejected"),
            Ok(Reply::Failsafe { .. }) => writeln!(out, "ok failsafe"),
            Err(ReplyError::Malformed(kind)) => writeln!(out, "malformed {}", kind.prefix()),
            Err(ReplyError::Unknown) => writeln!(out, "unknown"),
            Err(ReplyError::BadCheck) => writeln!(out, "bad_check"),
        }
        .unwrap();
    }
}
