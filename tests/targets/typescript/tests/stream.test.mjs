// The generated StreamParser: the same frames and error counts as the Python StreamDecoder on seeded random
// streams (through stream_driver.mjs, the driver other languages' differential tests use), and its recovery rules.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { join } from "node:path";
import { test } from "node:test";
import { PACKAGE, PYTHON, TOOLS, dp, rng, toHex } from "./support.mjs";

const TIMEOUT = dp.INTER_BYTE_TIMEOUT_MS;
const SPECS = Object.values(dp.COMMANDS);

function validFrame(random) {
  const s = random.pick(SPECS);
  return dp.encode(s.category, s.direction, s.minimum + random.int(s.maximum - s.minimum + 1));
}

/** Driver input lines: valid frames, garbage, near-valid frames, partial frames and gaps around the timeout. */
export function randomStream(seed, minBytes) {
  const random = rng(seed);
  const lines = [];
  let now = 1000 + random.int(1000);
  let bytes = 0;
  while (bytes < minBytes) {
    const parts = [];
    for (let n = 1 + random.int(4); n > 0; n--) {
      const kind = random.int(10);
      if (kind < 4) parts.push(validFrame(random));
      else if (kind < 6) parts.push(random.bytes(1 + random.int(8)));
      else if (kind < 8) {
        const frame = validFrame(random);
        frame[random.int(frame.length)] = random.pick([...frame, 0x30, 0x39, 0x20, random.int(256)]);
        parts.push(frame);
      } else parts.push(validFrame(random).subarray(0, 1 + random.int(dp.FRAME_LENGTH - 1)));
    }
    const chunk = Uint8Array.from(parts.flatMap((p) => [...p]));
    // Split the burst at a random point, the second half after a gap around the inter-byte timeout.
    const cut = random.int(chunk.length + 1);
    lines.push(`${now} ${toHex(chunk.subarray(0, cut))}`);
    now += random.pick([0, 1, TIMEOUT - 1, TIMEOUT, TIMEOUT + 1, random.int(3 * TIMEOUT)]);
    lines.push(`${now} ${toHex(chunk.subarray(cut))}`);
    now += random.pick([0, 1, TIMEOUT, TIMEOUT + 1, random.int(5 * TIMEOUT)]);
    bytes += chunk.length;
  }
  return lines.join("\n") + "\n";
}

const run = (command, args, input) => execFileSync(command, args, { input, encoding: "utf8", maxBuffer: 1 << 28 });

test("stream_driver.mjs and the Python StreamDecoder agree on seeded random streams of 10^5 bytes each", () => {
  let frames = 0;
  for (const seed of [1, 2, 3]) {
    const input = randomStream(seed, 100_000);
    const ours = run(process.execPath, [join(TOOLS, "stream_driver.mjs"), join(PACKAGE, "dist")], input).trimEnd().split("\n");
    const python = run(PYTHON, [join(TOOLS, "python_reference.py"), "stream"], input)
      .trimEnd().split("\n");
    assert.equal(ours.at(-1), python.at(-1), `seed ${seed}: error counts`);
    const first = ours.findIndex((line, i) => line !== python[i]);
    assert.equal(first, -1, `seed ${seed}: line ${first} differs: ${ours[first]} / ${python[first]}`);
    assert.equal(ours.length, python.length);
    const counts = Object.fromEntries(ours.at(-1).split(" ").slice(1).map((kv) => kv.split("=")).map(([k, v]) => [k, Number(v)]));
    for (const name of dp.STREAM_ERRORS) assert.ok(counts[name] > 0, `seed ${seed}: no ${name} met: the stream is too tame`);
    frames += ours.length - 1;
  }
  assert.ok(frames > 10_000, `only ${frames} frames found`);
});

test("the driver refuses a malformed line with exit status 2", () => {
  assert.throws(() => run(process.execPath, [join(TOOLS, "stream_driver.mjs"), join(PACKAGE, "dist")], "10 6d6\n"),
    (error) => error.status === 2 && /expected "<now_ms> <hex bytes>"/.test(error.stderr));
});

test("a valid frame after garbage and after a gap is never lost; nothing is ever half-held", () => {
  const random = rng(99);
  for (let i = 0; i < 3000; i++) {
    const parser = new dp.StreamParser();
    let now = random.int(1 << 30);
    for (const byte of random.bytes(random.int(20))) {
      parser.feed(byte, now);
      assert.ok(parser.pending < dp.FRAME_LENGTH);
    }
    now += TIMEOUT + 1 + random.int(100); // a gap: whatever was pending is dropped
    const frame = validFrame(random);
    const found = parser.feedAll(frame, now);
    assert.deepEqual(found, [dp.decode(frame)], `after garbage: ${toHex(frame)}`);
    assert.equal(parser.pending, 0);
    // garbage right before, with no gap: the slide still finds the frame
    const junk = random.bytes(random.int(8));
    const again = parser.feedAll(Uint8Array.from([...junk, ...frame]), now + 1);
    assert.deepEqual(again.at(-1), dp.decode(frame), `after ${toHex(junk)}: ${toHex(frame)}`);
  }
});

test("the timeout drops a partial frame after a gap of more than INTER_BYTE_TIMEOUT_MS, not at it", () => {
  const frame = validFrame(rng(5));
  for (const [gap, expected] of [[TIMEOUT, 1], [TIMEOUT + 1, 0]]) {
    const parser = new dp.StreamParser();
    parser.feedAll(frame.subarray(0, 3), 100);
    const found = parser.feedAll(frame.subarray(3), 100 + gap);
    assert.equal(found.length, expected, `gap ${gap} ms`);
    assert.equal(parser.errorCount("timeout"), 1 - expected);
  }
  // The clock wraps like the Arduino's millis().
  const parser = new dp.StreamParser();
  parser.feedAll(frame.subarray(0, 3), 2 ** 32 - 5);
  assert.equal(parser.feedAll(frame.subarray(3), 2).length, 1);
});

test("lastError names the first error of the last byte, and reset() forgets everything", () => {
  const parser = new dp.StreamParser();
  const category = dp.CATEGORIES[0].code.charCodeAt(0);
  parser.feed(category, 0);
  assert.equal(parser.lastError, null);
  parser.feed(0xff, 0);
  assert.equal(parser.lastError, "bad_direction");
  assert.equal(parser.errorCount("bad_direction"), 1);
  assert.equal(parser.errorCount("bad_category"), 1);
  parser.reset();
  assert.deepEqual(Object.values(parser.errors), Object.keys(dp.ERRORS).map(() => 0));
  assert.equal(parser.pending, 0);
});
