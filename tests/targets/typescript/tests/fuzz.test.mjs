// Seeded random bytes: decode(), the StreamParser and parseReply() never throw anything but ProtocolError, and
// whatever they accept is a command of the spec within its range.
import assert from "node:assert/strict";
import { test } from "node:test";
import { dp, rng, toHex } from "./support.mjs";

const SEEDS = [11, 12, 13, 14];

function checkCommand(command, context) {
  const spec = dp.COMMANDS[command.name];
  assert.ok(spec !== undefined, context);
  assert.ok(Number.isInteger(command.value) && command.value >= spec.minimum && command.value <= spec.maximum, context);
  assert.deepEqual(dp.decode(dp.encodeCommand(command)), { ...command }, context);
}

function onlyProtocolErrors(fn, context) {
  try {
    return fn();
  } catch (error) {
    assert.ok(error instanceof dp.ProtocolError, `${context}: threw ${error}`);
    assert.ok(error.code in dp.ERRORS || error.code === "bad_reply", context);
    return undefined;
  }
}

test("decode() of random bytes of every length throws only ProtocolError", () => {
  for (const seed of SEEDS) {
    const random = rng(seed);
    for (let i = 0; i < 25_000; i++) {
      const frame = random.bytes(random.int(2 * dp.FRAME_LENGTH + 2));
      const command = onlyProtocolErrors(() => dp.decode(frame), toHex(frame));
      if (command !== undefined) checkCommand(command, toHex(frame));
    }
  }
});

test("decode() of arrays of any numbers throws only ProtocolError", () => {
  const random = rng(7);
  const odd = [-1, 256, 1e9, 0.5, 48.5, Number.NaN, Infinity, -0];
  for (let i = 0; i < 20_000; i++) {
    const frame = Array.from({ length: random.int(9) }, () => (random.int(4) === 0 ? random.pick(odd) : random.int(256)));
    const command = onlyProtocolErrors(() => dp.decode(frame), JSON.stringify(frame));
    if (command !== undefined) checkCommand(command, JSON.stringify(frame));
  }
});

test("the StreamParser never throws on 10^6 random bytes with any clock, and emits only valid commands", () => {
  for (const seed of SEEDS) {
    const random = rng(seed);
    const parser = new dp.StreamParser();
    // Bytes of the protocol's own alphabet make frames likely; any byte and any clock jump otherwise.
    const alphabet = Object.values(dp.COMMANDS).flatMap((s) => [s.category, s.direction]).concat([..."0123456789"])
      .map((c) => c.charCodeAt(0));
    const specs = Object.values(dp.COMMANDS);
    let now = random.int(2 ** 32);
    let found = 0;
    let queued = [];
    for (let i = 0; i < 250_000; i++) {
      if (queued.length === 0 && random.int(8) === 0) {
        const s = random.pick(specs);
        queued = [...dp.encode(s.category, s.direction, s.minimum)];
      }
      const byte = queued.length > 0 ? queued.shift() : random.int(3) === 0 ? random.int(256) : random.pick(alphabet);
      if (random.int(50) === 0) now += random.pick([dp.INTER_BYTE_TIMEOUT_MS, dp.INTER_BYTE_TIMEOUT_MS + 1, -5, 2 ** 31, 2 ** 32 + 3]);
      else now += random.int(2);
      const command = parser.feed(byte, now);
      assert.ok(parser.pending >= 0 && parser.pending < dp.FRAME_LENGTH);
      if (command !== null) {
        checkCommand(command, `seed ${seed} byte ${i}`);
        found++;
      }
    }
    assert.ok(found > 100, `seed ${seed}: only ${found} frames`);
    for (const n of Object.values(parser.errors)) assert.ok(Number.isInteger(n) && n >= 0);
  }
});

test("parseReply() of random lines throws only ProtocolError", () => {
  const random = rng(21);
  const prefixes = Object.values(dp.REPLIES).map((r) => r.prefix);
  for (let i = 0; i < 20_000; i++) {
    const tail = random.bytes(random.int(12));
    const head = random.int(2) === 0 ? new TextEncoder().encode(random.pick(prefixes)) : new Uint8Array();
    const line = Uint8Array.from([...head, ...tail]);
    const reply = onlyProtocolErrors(() => dp.parseReply(line), toHex(line));
    if (reply !== undefined) assert.ok(reply.kind in dp.REPLIES);
    onlyProtocolErrors(() => dp.parseReply(String.fromCharCode(...line)), toHex(line));
  }
});
