#!/usr/bin/env node
// The generated TypeScript StreamParser as a command-line driver, for differential tests across languages.
//
//   node tests/targets/typescript/stream_driver.mjs [PACKAGE_DIST]    (default: build/typescript/package/dist,
//                                                                      made by `make typescript`)
//
// stdin: one line per burst of bytes, "<now_ms> <hex bytes>": a decimal millisecond clock (non-decreasing,
//   whole ms) and the bytes received at that time in hex (two digits each, no separators; may be empty).
//   Blank lines are ignored. Every byte goes through StreamParser.feed(byte, now_ms), one at a time.
// stdout: "<command name> <value>" for every frame the parser completes, in order (e.g. "move_forward 1600"),
//   then one last line "errors <name>=<n> ..." with the count of every error kind of the spec, in the spec's
//   order (e.g. "errors bad_category=4 bad_direction=0 ... timeout=1 ... busy=0 ..."; kinds the stream parser
//   never meets are 0), the format the Python, C++, C and Rust drivers of tests/targets/drivers/ share.
// A malformed input line exits 2 with a message on stderr.
import { createInterface } from "node:readline";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const dist = resolve(process.argv[2] ?? join(here, "../../../build/typescript/package/dist"));
const { StreamParser, ERRORS } = await import(pathToFileURL(join(dist, "index.js")).href);

const parser = new StreamParser();
const out = [];
let lineNo = 0;
for await (const line of createInterface({ input: process.stdin, crlfDelay: Infinity })) {
  lineNo++;
  const text = line.trim();
  if (text === "") continue;
  const match = /^(\d+)(?:\s+([0-9a-fA-F]*))?$/.exec(text);
  if (match === null || (match[2] ?? "").length % 2 !== 0) {
    process.stderr.write(`stdin line ${lineNo}: expected "<now_ms> <hex bytes>", got ${JSON.stringify(line)}\n`);
    process.exit(2);
  }
  const now = Number(match[1]);
  const hex = match[2] ?? "";
  for (let i = 0; i < hex.length; i += 2) {
    const command = parser.feed(parseInt(hex.slice(i, i + 2), 16), now);
    if (command !== null) out.push(`${command.name} ${command.value}`);
  }
  if (out.length >= 4096) process.stdout.write(out.splice(0).join("\n") + "\n");
}
out.push(`errors ${Object.keys(ERRORS).map((name) => `${name}=${parser.errorCount(name)}`).join(" ")}`);
process.stdout.write(out.join("\n") + "\n");
