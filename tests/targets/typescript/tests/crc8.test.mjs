// frame.integrity crc8: the package generated from the spec with `integrity: crc8`, compiled and checked.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { PYTHON, ROOT, TSC, fromHex } from "./support.mjs";

let dir;
let dp;
let vectors;
const ascii = (text) => Uint8Array.from(text, (c) => c.charCodeAt(0));

before(async () => {
  dir = mkdtempSync(join(tmpdir(), "drone-protocol-crc8-"));
  const spec = readFileSync(join(ROOT, "spec/drone.yaml"), "utf8");
  assert.equal(spec.match(/^  integrity: none$/gm)?.length, 1, "the spec's integrity line moved");
  writeFileSync(join(dir, "drone.yaml"), spec.replace(/^  integrity: none$/m, "  integrity: crc8"));
  execFileSync(PYTHON, ["-m", "generator", "--spec", join(dir, "drone.yaml"), "--out", join(dir, "out")], { cwd: ROOT });
  execFileSync(TSC, ["-p", join(dir, "out/typescript/tsconfig.json")]);
  dp = await import(join(dir, "out/typescript/dist/index.js"));
  vectors = JSON.parse(readFileSync(join(dir, "out/vectors.json"), "utf8")).vectors;
});

after(() => rmSync(dir, { recursive: true, force: true }));

test("CRC-8/SMBUS: the standard check value, and the generator's own crc8", () => {
  assert.equal(dp.crc8(ascii("123456789")), 0xf4);
  const samples = ["mf1600", "l00000", "Amf m0", "#READY drone_protocol 0123456789abcdef crc8"];
  const python = execFileSync(PYTHON, ["-c",
    "import sys; from generator.model import check_text; print(' '.join(check_text(a.encode()) for a in sys.argv[1:]))",
    ...samples], { cwd: ROOT, encoding: "utf8" }).trim().split(" ");
  assert.deepEqual(samples.map((s) => dp.checkText(ascii(s))), python);
});

test("frames carry their check: encode, and every vector of the crc8 spec", () => {
  assert.equal(dp.INTEGRITY, "crc8");
  assert.equal(dp.WIRE_LENGTH, dp.FRAME_LENGTH + 2);
  const spec = Object.values(dp.COMMANDS)[0];
  const frame = dp.encode(spec.category, spec.direction, spec.minimum);
  assert.equal(frame.length, dp.WIRE_LENGTH);
  assert.equal(String.fromCharCode(...frame.subarray(dp.FRAME_LENGTH)), dp.checkText(frame, dp.FRAME_LENGTH));
  assert.ok(vectors.filter((v) => v.ok).every((v) => fromHex(v.frame_hex).length === dp.WIRE_LENGTH));
  assert.ok(vectors.some((v) => v.error === "bad_check"), "no bad_check vector");
  for (const v of vectors) {
    const bytes = fromHex(v.frame_hex);
    if (v.ok) {
      assert.equal(dp.decode(bytes).value, v.value, v.note);
    } else {
      assert.throws(() => dp.decode(bytes), (e) => e instanceof dp.ProtocolError && e.code === v.error && e.position === v.position, v.note);
    }
  }
});

test("a wrong or malformed check digit is bad_check at its byte, found before the range", () => {
  const spec = Object.values(dp.COMMANDS).find((s) => s.maximum < 9999);
  const good = dp.encode(spec.category, spec.direction, spec.maximum);
  const flipped = good.slice();
  flipped[dp.FRAME_LENGTH + 1] = flipped[dp.FRAME_LENGTH + 1] === 0x30 ? 0x31 : 0x30;
  const codeOf = (bytes) => {
    try {
      dp.decode(bytes);
      return "ok";
    } catch (e) {
      return `${e.code}@${e.position}`;
    }
  };
  assert.equal(codeOf(flipped), `bad_check@${dp.FRAME_LENGTH + 1}`);
  const lower = good.slice();
  lower[dp.FRAME_LENGTH] = 0x61;
  assert.equal(codeOf(lower), `bad_check@${dp.FRAME_LENGTH}`);
  const outOfRange = ascii(`${spec.category}${spec.direction}${String(spec.maximum + 1).padStart(dp.VALUE_WIDTH, "0")}`);
  assert.equal(codeOf(Uint8Array.from([...outOfRange, 0x30, 0x30])), dp.checkText(outOfRange) === "00" ? `out_of_range@2` : `bad_check@${dp.FRAME_LENGTH}`);
  assert.equal(codeOf(Uint8Array.from([...outOfRange, ...ascii(dp.checkText(outOfRange))])), "out_of_range@2");
  assert.equal(codeOf(good.subarray(0, dp.FRAME_LENGTH)), `too_short@${dp.FRAME_LENGTH}`);
});

test("the stream parser finds checked frames after garbage and counts a corrupted one as bad_check", () => {
  const spec = Object.values(dp.COMMANDS)[0];
  const good = dp.encode(spec.category, spec.direction, spec.minimum);
  const corrupt = good.slice();
  corrupt[dp.FRAME_LENGTH] = corrupt[dp.FRAME_LENGTH] === 0x41 ? 0x42 : 0x41;
  const parser = new dp.StreamParser();
  const found = parser.feedAll(Uint8Array.from([0x00, ...corrupt, ...good]), 0);
  assert.deepEqual(found.map((c) => c.value), [spec.minimum]);
  assert.ok(parser.errorCount("bad_check") >= 1);
  assert.ok(dp.STREAM_ERRORS.includes("bad_check"));
});

test("reply lines end in '*' and their check; a line without it is bad_check", () => {
  const status = { state: Object.keys(dp.STATES)[0], laserOn: true };
  const line = dp.failsafeLine(status);
  assert.match(line, /\*[0-9A-F]{2}\n$/);
  assert.deepEqual(dp.parseReply(line), { kind: "failsafe", status });
  assert.equal(dp.parseReply(dp.readyLine()).integrity, "crc8");
  assert.throws(() => dp.parseReply(line.replace(/\*..\n$/, "")), (e) => e.code === "bad_check");
  assert.throws(() => dp.parseReply(line.replace(/\*(.)(.)/, "*$2$1")), (e) => e.code === "bad_check" || e.code === "bad_reply");
});
