#!/usr/bin/env node
// The generated TypeScript codec against hand-written floors in the same run (`make bench-typescript`):
//   encode   per-command function and encode() vs a string template copied into a Uint8Array (no checks)
//   decode   decode() vs slice-and-parse (a name table, parseInt of the digits, no checks)
//   stream   StreamParser.feed per byte vs a 6-byte accumulator that slice-and-parses each full buffer
// Goal: each at most 2x its floor. Each figure is the median of 9 rounds over 1024 frames of every command at
// random values; writes bench/typescript/RESULTS.md (--no-write: print only).
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const build = process.env.DRONE_PROTOCOL_TS_BUILD ?? resolve(here, "../../build/typescript");
const dp = await import(pathToFileURL(join(build, "package/dist/index.js")).href);

const ROUNDS = 9;
const FRAMES = 1024;
const specs = Object.values(dp.COMMANDS);
let seed = 12345;
const random = (n) => {
  seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
  return seed % n;
};
const cases = Array.from({ length: FRAMES }, () => {
  const s = specs[random(specs.length)];
  return { spec: s, value: s.minimum + random(s.maximum - s.minimum + 1), fn: dp[s.functionName] };
});
const frames = cases.map((c) => dp.encode(c.spec.category, c.spec.direction, c.value));
const stream = Uint8Array.from(frames.flatMap((f) => [...f]));

// The floors: what a careful hand-written codec for this one format costs, with no validation at all.
const NAMES = Object.fromEntries(specs.map((s) => [s.category + s.direction, s]));
function floorEncode(prefix, value) {
  const text = `${prefix}${String(value).padStart(4, "0")}`;
  const out = new Uint8Array(6);
  for (let i = 0; i < 6; i++) out[i] = text.charCodeAt(i);
  return out;
}
function floorDecode(frame) {
  const text = String.fromCharCode(frame[0], frame[1], frame[2], frame[3], frame[4], frame[5]);
  const s = NAMES[text.slice(0, 2)];
  return { name: s.name, category: s.category, direction: s.direction, value: parseInt(text.slice(2), 10) };
}
class FloorStream {
  buffer = new Uint8Array(6);
  length = 0;
  feed(byte) {
    this.buffer[this.length++] = byte;
    if (this.length < 6) return null;
    this.length = 0;
    return floorDecode(this.buffer);
  }
}

let sink = 0;
function time(label, perRound, body) {
  const samples = [];
  for (let r = 0; r < ROUNDS + 2; r++) {
    const start = process.hrtime.bigint();
    body();
    const ns = Number(process.hrtime.bigint() - start) / perRound;
    if (r >= 2) samples.push(ns); // the first two rounds warm the JIT
  }
  samples.sort((a, b) => a - b);
  return { label, ns: samples[Math.floor(samples.length / 2)] };
}

const REPEAT = 200; // passes over the 1024 frames per round
const perFrame = REPEAT * FRAMES;
const perByte = REPEAT * stream.length;
const prefixes = cases.map((c) => c.spec.category + c.spec.direction);
const results = [
  [
    time("per-command functions (`moveForward(v)` ...)", perFrame, () => {
      for (let k = 0; k < REPEAT; k++) {
        for (const c of cases) sink += (c.spec.minimum === c.spec.maximum ? c.fn() : c.fn(c.value))[5];
      }
    }),
    time("encode(category, direction, value)", perFrame, () => {
      for (let k = 0; k < REPEAT; k++) for (const c of cases) sink += dp.encode(c.spec.category, c.spec.direction, c.value)[5];
    }),
    time("floor: string template into a Uint8Array", perFrame, () => {
      for (let k = 0; k < REPEAT; k++) for (let i = 0; i < FRAMES; i++) sink += floorEncode(prefixes[i], cases[i].value)[5];
    }),
  ],
  [
    time("decode(frame)", perFrame, () => {
      for (let k = 0; k < REPEAT; k++) for (const f of frames) sink += dp.decode(f).value;
    }),
    time("floor: slice-and-parse", perFrame, () => {
      for (let k = 0; k < REPEAT; k++) for (const f of frames) sink += floorDecode(f).value;
    }),
  ],
  [
    time("StreamParser.feed(byte, now)", perByte, () => {
      const parser = new dp.StreamParser();
      for (let k = 0; k < REPEAT; k++) {
        for (let i = 0; i < stream.length; i++) {
          const c = parser.feed(stream[i], k);
          if (c !== null) sink += c.value;
        }
      }
    }),
    time("floor: 6-byte accumulator + slice-and-parse", perByte, () => {
      const parser = new FloorStream();
      for (let k = 0; k < REPEAT; k++) {
        for (let i = 0; i < stream.length; i++) {
          const c = parser.feed(stream[i]);
          if (c !== null) sink += c.value;
        }
      }
    }),
  ],
];

const lines = [
  "# TypeScript codec: time per frame / per byte against hand-written floors",
  "",
  `Measured by \`make bench-typescript\` (bench/typescript/bench.mjs) with Node ${process.version} on this machine`,
  `(2 shared cores, so absolute times are noisy; the ratios are to a floor timed in the same run). Median of`,
  `${ROUNDS} rounds of ${REPEAT} passes over ${FRAMES} frames of every command at random values. Goal: at most 2x.`,
  "",
  "| what | time | floor | ratio | goal ≤ 2x |",
  "|---|---|---|---|---|",
];
for (const group of results) {
  const floor = group.at(-1);
  for (const r of group.slice(0, -1)) {
    const ratio = r.ns / floor.ns;
    lines.push(`| ${r.label} | ${r.ns.toFixed(1)} ns | ${floor.label}: ${floor.ns.toFixed(1)} ns | ${ratio.toFixed(2)}x | ${ratio <= 2 ? "met" : "missed"} |`);
  }
}
lines.push("");
console.log(lines.join("\n"));
if (sink === 0.5) console.log("unreachable"); // keeps `sink` alive
if (!process.argv.includes("--no-write")) {
  // instructions.py's section is kept
  const results = join(here, "RESULTS.md");
  const old = existsSync(results) ? readFileSync(results, "utf8") : "";
  const kept = old.indexOf("## Instructions against lean floors");
  writeFileSync(results, lines.join("\n") + (kept >= 0 ? "\n" + old.slice(kept) : ""));
}
