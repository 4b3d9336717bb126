// JavaScript callers have no types to stop them: what is not bytes, a byte or a clock is a TypeError naming the
// call and what it takes, never a frame of the wrong bytes (`decode("mf1500")` read the string's characters as
// bytes, `feed(chunk)` fed `chunk & 0xff`, 0, and a feed without its clock never timed a partial frame out).
import assert from "node:assert/strict";
import { test } from "node:test";
import { dp } from "./support.mjs";

const FRAME = dp.moveForward();

test("decode() refuses what is not bytes, naming what it got", () => {
  for (const [value, named] of [["mf1500", "a string"], [undefined, "undefined"], [null, "null"], [6, "number"],
    [new ArrayBuffer(6), "ArrayBuffer"]]) {
    assert.throws(() => dp.decode(value), { name: "TypeError", message: `decode() takes bytes (a Uint8Array or an array of numbers), not ${named}` });
  }
  assert.equal(dp.decode(Array.from(FRAME)).name, "move_forward");  // an array of numbers is bytes
});

test("StreamParser.feed() refuses a chunk or a missing clock; feedAll() takes the chunk", () => {
  const parser = new dp.StreamParser();
  assert.throws(() => parser.feed(FRAME, 0), { name: "TypeError", message: /feed\(\) takes one byte \(a number\), not object: feedAll\(\)/ });
  assert.throws(() => parser.feed(FRAME[0]), { name: "TypeError", message: /needs the time in whole milliseconds/ });
  assert.throws(() => parser.feed(FRAME[0], NaN), { name: "TypeError" });
  assert.throws(() => parser.feedAll("mf1600", 0), { name: "TypeError", message: /feedAll\(\) takes bytes .*not a string/ });
  assert.equal(parser.pending, 0);  // nothing refused was taken in
  assert.deepEqual(parser.feedAll(FRAME, 0).map((c) => c.name), ["move_forward"]);
});

test("parseReply() takes a string or its bytes, and refuses anything else", () => {
  const line = dp.readyLine();
  assert.equal(dp.parseReply(line).kind, dp.parseReply(new TextEncoder().encode(line)).kind);
  assert.throws(() => dp.parseReply(undefined), { name: "TypeError", message: "parseReply() takes a line (a string, or its bytes), not undefined" });
});
