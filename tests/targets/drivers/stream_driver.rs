//! Stream driver of the generated Rust crate, in the format every language's driver shares:
//! stdin "<now_ms> <hex bytes>" per line; stdout "<command name> <value>" per command found, then
//! "errors <name>=<count> ..." with every error kind of the spec, in spec order.
use std::io::{BufWriter, Read, Write};

use drone_protocol::{Error, StreamParser};

fn hex_digit(c: u8) -> Option<u8> {
    (c as char).to_digit(16).map(|d| d as u8)
}

fn main() {
    let mut input = Vec::new();
    std::io::stdin().read_to_end(&mut input).expect("stdin");
    let mut out = BufWriter::new(std::io::stdout().lock());
    let mut parser = StreamParser::new();
    for line in input.split(|&b| b == b'\n') {
        let mut parts = line.split(|&b| b == b' ').filter(|p| !p.is_empty());
        let Some(now) = parts.next() else { continue };
        let now: u32 = std::str::from_utf8(now).unwrap().parse().expect("a time in ms");
        let hex = parts.next().unwrap_or(b"");
        for pair in hex.chunks_exact(2) {
            let (Some(high), Some(low)) = (hex_digit(pair[0]), hex_digit(pair[1])) else { break };
            if let Some(command) = parser.feed(high << 4 | low, now) {
                writeln!(out, "{} {}", command.name(), command.value).unwrap();
            }
        }
    }
    write!(out, "errors").unwrap();
    for error in Error::ALL {
        write!(out, " {}={}", error.name(), parser.error_count(error)).unwrap();
    }
    writeln!(out).unwrap();
}
