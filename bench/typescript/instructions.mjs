#!/usr/bin/env node
// The TypeScript codec against lean hand-written floors, in instructions: run under
//   valgrind --tool=callgrind --dump-before=uv_loadavg node --single-threaded instructions.mjs <package dist>
// (bench/typescript/instructions.py does; add --time to time the loops natively). Each measured loop runs, after its warm-up, between two calls of
// os.loadavg(), so callgrind writes one dump of exactly that loop. Prints one JSON line: the measures in the
// order of their dumps, with the units each loop processed and what each found (codec and floor must agree).
//
// The floors know only the frame format: tables built here from COMMANDS (a category byte's slot, a slot's
// command by direction byte, each command's range), each byte checked as it arrives and a slide of one byte on
// an invalid one, the same command objects out; no timeouts, error kinds or counts, no argument checks.
import { loadavg } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";

const dp = await import(pathToFileURL(join(process.argv[2], "index.js")).href);
const specs = Object.values(dp.COMMANDS);
const FRAME = dp.FRAME_LENGTH;

let seed = 12345;
const random = (n) => {
  seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
  return (seed >>> 8) % n;
};
const randomFrame = () => {
  const s = specs[random(specs.length)];
  return dp.encode(s.category, s.direction, s.minimum + random(s.maximum - s.minimum + 1));
};
const SIZE = 30000;
function streamOf(garbage) {
  const out = [];
  while (out.length < SIZE) {
    out.push(...randomFrame());
    if (garbage) for (let i = 0; i < FRAME; i++) out.push(random(256));
  }
  return Uint8Array.from(out.slice(0, SIZE));
}
const distinct = [];
for (const s of specs) {
  const step = Math.max(1, Math.ceil((s.maximum - s.minimum + 1) / 64));
  for (let v = s.minimum; v <= s.maximum; v += step) distinct.push(dp.encode(s.category, s.direction, v));
}
for (let i = distinct.length - 1; i > 0; i--) {
  const j = random(i + 1);
  [distinct[i], distinct[j]] = [distinct[j], distinct[i]];
}

// The floor's tables.
const slotOf = new Uint8Array(256); // slot + 1 of a category byte, 0: none
const rows = [new Int32Array(256)]; // by slot + 1: command + 1 of a direction byte, 0: none
const minimum = new Int32Array(specs.length);
const maximum = new Int32Array(specs.length);
specs.forEach((s, i) => {
  const c = s.category.charCodeAt(0);
  if (slotOf[c] === 0) slotOf[c] = rows.push(new Int32Array(256)) - 1;
  rows[slotOf[c]][s.direction.charCodeAt(0)] = i + 1;
  minimum[i] = s.minimum;
  maximum[i] = s.maximum;
});
const commandOf = (i, value) => {
  const s = specs[i];
  return { name: s.name, category: s.category, direction: s.direction, value };
};

class FloorStream {
  bytes = new Uint8Array(FRAME);
  held = new Uint8Array(FRAME);
  length = 0;
  row = rows[0];
  command = 0;
  value = 0;

  // Take `byte` at the next position: 1 when valid, 2 when it completes a frame in range, 0 when invalid (an
  // out-of-range frame keeps its length, FRAME).
  push(byte) {
    const n = this.length;
    if (n === 0) {
      const slot = slotOf[byte];
      if (slot === 0) return 0;
      this.row = rows[slot];
    } else if (n === 1) {
      const command = this.row[byte];
      if (command === 0) return 0;
      this.command = command - 1;
      this.value = 0;
    } else {
      const digit = byte - 0x30;
      if (digit < 0 || digit > 9) return 0;
      this.value = this.value * 10 + digit;
    }
    this.bytes[n] = byte;
    this.length = n + 1;
    if (n + 1 < FRAME) return 1;
    if (this.value < minimum[this.command] || this.value > maximum[this.command]) return 0;
    this.length = 0;
    return 2;
  }

  feed(byte) {
    const result = this.push(byte);
    if (result === 2) return commandOf(this.command, this.value);
    if (result === 0 && this.length > 0) this.slide(byte); // nothing held: nothing to slide
    return null;
  }

  slide(byte) {
    const held = this.held;
    let n = this.length;
    for (let i = 0; i < n; i++) held[i] = this.bytes[i];
    if (n < FRAME) held[n] = byte;
    else n = FRAME - 1;
    for (let start = 1; start <= n; start++) {
      this.length = 0;
      let k = start;
      while (k <= n && this.push(held[k]) !== 0) k++;
      if (k > n) return;
    }
    this.length = 0;
  }
}

function floorDecode(frame) {
  if (frame.length !== FRAME) return null;
  const row = rows[slotOf[frame[0]]];
  const command = row[frame[1]] - 1;
  if (command < 0) return null;
  let value = 0;
  for (let i = 2; i < FRAME; i++) {
    const digit = frame[i] - 0x30;
    if (digit < 0 || digit > 9) return null;
    value = value * 10 + digit;
  }
  if (value < minimum[command] || value > maximum[command]) return null;
  return commandOf(command, value);
}

function codecStream(bytes) {
  const parser = new dp.StreamParser();
  let found = 0;
  for (let i = 0; i < bytes.length; i++) if (parser.feed(bytes[i], 0) !== null) found++;
  return found;
}
function floorStream(bytes) {
  const parser = new FloorStream();
  let found = 0;
  for (let i = 0; i < bytes.length; i++) if (parser.feed(bytes[i]) !== null) found++;
  return found;
}
const codecDecode = (frames) => frames.reduce((sum, f) => sum + dp.decode(f).value, 0);
const floorDecodeAll = (frames) => frames.reduce((sum, f) => sum + floorDecode(f).value, 0);

// Each loop warms up on about 1.2 M units, then is counted on about 120 k (whole passes over its input). With
// --time (run natively, not under callgrind), the counted loop is timed instead, best of 9: ns per unit.
const timing = process.argv.includes("--time");
const measures = [];
function measure(label, what, input, units, codec, floor) {
  const found = {};
  const ns = {};
  const passes = Math.ceil(120000 / units);
  for (const [side, fn] of [["codec", codec], ["floor", floor]]) {
    for (let i = 0; i < 10 * passes; i++) fn(input);
    let result = 0;
    ns[side] = Infinity;
    for (let round = 0; round < (timing ? 9 : 1); round++) {
      const start = process.hrtime.bigint();
      if (!timing) loadavg();
      for (let i = 0; i < passes; i++) result = fn(input);
      if (!timing) loadavg();
      ns[side] = Math.min(ns[side], Number(process.hrtime.bigint() - start) / (units * passes));
    }
    found[side] = result;
  }
  measures.push({ label, what, units: units * passes, found, ns });
}
measure("stream, clean", "byte", streamOf(false), SIZE, codecStream, floorStream);
measure("stream, 50 % garbage", "byte", streamOf(true), SIZE, codecStream, floorStream);
measure("decode, distinct frames", "frame", distinct, distinct.length, codecDecode, floorDecodeAll);
console.log(JSON.stringify(measures));
