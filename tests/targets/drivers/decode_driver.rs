//! Decode driver of the generated Rust crate: stdin one frame per line in hex (an empty line is a 0-byte frame);
//! stdout "ok <command> <value>" or "err <error name>" per line, the format every language's decode driver shares.
use std::io::{BufRead, BufWriter, Write};

fn main() {
    let mut out = BufWriter::new(std::io::stdout().lock());
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("stdin");
        let frame: Vec<u8> = (0..line.len() / 2).map(|i| u8::from_str_radix(&line[2 * i..2 * i + 2], 16).unwrap()).collect();
        match drone_protocol::decode(&frame) {
            Ok(command) => writeln!(out, "ok {} {}", command.name(), command.value),
            Err(error) => writeln!(out, "err {}", error.name()),
        }
        .unwrap();
    }
}
