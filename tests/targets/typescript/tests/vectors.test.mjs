// The generated TypeScript codec against vectors.json and against the generated Python codec.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { join } from "node:path";
import { test } from "node:test";
import { PYTHON, READY_LINES, TOOLS, VECTORS, ascii, dp, fromHex, rng, toHex } from "./support.mjs";

const reference = (mode, input = "") =>
  execFileSync(PYTHON, [join(TOOLS, "python_reference.py"), mode], { input, encoding: "utf8", maxBuffer: 1 << 28 });

test("the vectors cover every command and every error decode() raises", () => {
  assert.deepEqual(new Set(VECTORS.filter((v) => v.ok).map((v) => v.command)), new Set(Object.keys(dp.COMMANDS)));
  const errors = new Set(VECTORS.filter((v) => !v.ok).map((v) => v.error));
  assert.ok(errors.size >= 6, [...errors].join(" "));
  for (const name of errors) assert.ok(name in dp.ERRORS, name);
});

test("every valid vector decodes, and encodes back through encode(), encodeCommand() and its own function", () => {
  for (const v of VECTORS.filter((x) => x.ok)) {
    const frame = fromHex(v.frame_hex);
    const command = dp.decode(frame);
    assert.deepEqual({ ...command }, { name: v.command, category: v.category, direction: v.direction, value: v.value }, v.note);
    assert.deepEqual(dp.encodeCommand(command), frame, v.note);
    assert.deepEqual(dp.encode(v.category, v.direction, v.value), frame, v.note);
    const spec = dp.COMMANDS[v.command];
    const fn = dp[spec.functionName];
    assert.equal(typeof fn, "function", `${spec.functionName} is not exported`);
    assert.deepEqual(spec.minimum === spec.maximum ? fn() : fn(v.value), frame, v.note);
    if (spec.default !== null && v.value === spec.default) {
      assert.deepEqual(fn(), frame, `${spec.functionName}() takes the default`);
      assert.deepEqual(dp.encode(v.category, v.direction), frame);
    }
  }
});

test("every malformed vector is rejected with its error name and position, as a ProtocolError", () => {
  for (const v of VECTORS.filter((x) => !x.ok)) {
    assert.throws(() => dp.decode(fromHex(v.frame_hex)), (error) => {
      assert.ok(error instanceof dp.ProtocolError && error instanceof Error, v.note);
      assert.equal(error.code, v.error, v.note);
      assert.equal(error.position, v.position, v.note);
      assert.equal(error.replyCode, dp.ERRORS[v.error].code);
      assert.ok(error.message.length > 10, v.note);
      return true;
    });
  }
});

test("encode() refuses what the protocol does not allow", () => {
  const spec = Object.values(dp.COMMANDS).find((s) => s.minimum < s.maximum && s.default !== null);
  const required = Object.values(dp.COMMANDS).find((s) => s.default === null);
  const code = (fn) => {
    try {
      fn();
    } catch (error) {
      return error instanceof dp.ProtocolError ? error.code : error.constructor.name;
    }
    return "accepted";
  };
  assert.equal(code(() => dp.encode(spec.category, spec.direction, spec.maximum + 1)), "out_of_range");
  assert.equal(code(() => dp.encode(spec.category, spec.direction, spec.minimum - 1)), "out_of_range");
  assert.equal(code(() => dp[spec.functionName](spec.maximum + 1)), "out_of_range");
  assert.equal(code(() => dp.encode(spec.category, spec.direction, spec.minimum + 0.5)), "TypeError");
  assert.equal(code(() => dp.encode(spec.category, spec.direction, Number.NaN)), "TypeError");
  assert.equal(code(() => dp.encode("?", spec.direction, spec.minimum)), "bad_category");
  assert.equal(code(() => dp.encode(spec.category + spec.category, spec.direction)), "bad_category");
  assert.equal(code(() => dp.encode(spec.category, "?")), "bad_direction");
  assert.equal(code(() => dp.encode(required.category, required.direction)), "missing_value");
  assert.equal(code(() => dp[required.functionName]()), "missing_value");  // the same error from its own function
  const several = dp.CATEGORIES.find((c) => c.commands.length > 1);
  assert.equal(code(() => dp.encode(several.code)), "bad_direction");
  const single = dp.CATEGORIES.find((c) => c.commands.length === 1);
  if (single !== undefined) assert.equal(code(() => dp.encode(single.code)), "accepted");
});

test("the spec's tables and fingerprint are the Python module's, and its accepted lines parse", () => {
  const py = JSON.parse(reference("info"));
  assert.equal(dp.SPEC_FINGERPRINT, py.fingerprint);
  assert.equal(dp.SPEC_SHA256, py.sha256);
  assert.deepEqual(Object.fromEntries(Object.entries(dp.ERRORS).map(([name, e]) => [name, e.code])), py.errors);
  assert.deepEqual(Object.fromEntries(Object.values(dp.COMMANDS).map((s) =>
    [s.name, [s.category, s.direction, s.minimum, s.maximum, s.default]])), py.commands);
  const names = Object.keys(dp.COMMANDS);
  assert.deepEqual(py.accepted.map((line) => dp.parseReply(line)).map((r) => r.kind === "accepted" && r.command), names);
});

test("parseReply() reads every line the writers write, with every status, and refuses others", () => {
  const statuses = Object.keys(dp.STATES).flatMap((state) => [{ state, laserOn: false }, { state, laserOn: true }]);
  assert.deepEqual(dp.parseReply(dp.readyLine()),
    { kind: "ready", protocol: dp.PROTOCOL_NAME, fingerprint: dp.SPEC_FINGERPRINT, integrity: dp.INTEGRITY });
  for (const [i, spec] of Object.values(dp.COMMANDS).entries()) {
    const status = statuses[i % statuses.length];
    const line = dp.acceptedLine(dp.decode(dp.encode(spec.category, spec.direction, spec.minimum)), status);
    assert.deepEqual(dp.parseReply(line),
      { kind: "accepted", command: spec.name, category: spec.category, direction: spec.direction, status });
    assert.deepEqual(dp.parseReply(new TextEncoder().encode(line.replace("\n", "\r\n"))).status, status);
  }
  for (const [i, name] of Object.keys(dp.ERRORS).entries()) {
    const status = statuses[(3 * i) % statuses.length];
    assert.deepEqual(dp.parseReply(dp.rejectedLine(name, status)), { kind: "rejected", error: name, status });
  }
  for (const status of statuses) assert.deepEqual(dp.parseReply(dp.failsafeLine(status)), { kind: "failsafe", status });
  const text = dp.failsafeLine(statuses[0]);
  const state = dp.STATES[statuses[0].state].code;
  const bad = [
    "", "?", dp.REPLIES.accepted.prefix, `${dp.REPLIES.accepted.prefix}??`, `${dp.REPLIES.rejected.prefix}?`,
    `${dp.REPLIES.failsafe.prefix}x`, dp.REPLIES.ready.prefix, `${dp.REPLIES.ready.prefix} one`,
    text.replace(`${state}${dp.LASER_OFF}`, `${state}?`), `${dp.REPLIES.failsafe.prefix}${dp.STATUS_SEPARATOR}?${dp.LASER_OFF}`,
  ];
  for (const line of bad) {
    assert.throws(() => dp.parseReply(line), (e) => e instanceof dp.ProtocolError && ["bad_reply", "bad_check"].includes(e.code), line);
  }
});

test("parseReply() judges every odd ready line of vectors.json as the spec's one rule does", () => {
  assert.ok(READY_LINES.length > 100, `${READY_LINES.length} ready lines`);
  for (const v of READY_LINES) {
    const line = fromHex(v.ready_hex);
    if (v.kind === "ready") {
      assert.deepEqual(dp.parseReply(line),
        { kind: "ready", protocol: v.protocol, fingerprint: v.fingerprint, integrity: v.integrity }, v.note);
      continue;
    }
    assert.throws(() => dp.parseReply(line), (e) => {
      assert.ok(e instanceof dp.ProtocolError, v.note);
      assert.equal(e.code, v.kind === "bad_check" ? "bad_check" : "bad_reply", v.note);
      assert.match(e.message, v.kind === "unknown" ? /^unknown reply/ : /^(malformed ready reply|reply .* has no valid check)/, v.note);
      return true;
    });
  }
});

test("decode() gives Python's result on 100k 6-byte inputs biased toward almost-valid frames", () => {
  const random = rng(20261123);
  const specs = Object.values(dp.COMMANDS);
  const alphabet = [...new Set([...specs.flatMap((s) => [s.category, s.direction]), ..."0123456789 -\x00\x7f\xff"])]
    .map((c) => c.charCodeAt(0));
  const edges = specs.flatMap((s) => [s.minimum - 1, s.minimum, s.maximum, s.maximum + 1]).filter((v) => v >= 0 && v < 10000);
  const frames = [];
  for (let i = 0; i < 100_000; i++) {
    const spec = random.pick(specs);
    const digits = (v) => String(v).padStart(4, "0");
    let text;
    switch (i % 6) {
      case 0: frames.push(random.bytes(6)); continue;
      case 1: text = spec.category + spec.direction + digits(random.int(10000)); break;
      case 2: text = spec.category + spec.direction + digits(random.pick(edges)); break;
      case 3: text = random.pick(specs).category + random.pick(specs).direction + digits(random.pick(edges)); break;
      case 4: text = spec.category + spec.direction + digits(spec.minimum + random.int(spec.maximum - spec.minimum + 1)); break;
      default: frames.push(Uint8Array.from({ length: 6 }, () => random.pick(alphabet))); continue;
    }
    frames.push(Uint8Array.from(text, (c) => c.charCodeAt(0)));
  }
  for (let n = 0; n < 12; n++) frames.push(random.bytes(n));
  const ours = frames.map((frame) => {
    try {
      const c = dp.decode(frame);
      return `ok ${c.name} ${c.value}`;
    } catch (error) {
      assert.ok(error instanceof dp.ProtocolError, `${toHex(frame)}: ${error}`);
      return `err ${error.code} ${error.position}`;
    }
  });
  const python = reference("decode", frames.map((f) => toHex(f) + "\n").join("")).trimEnd().split("\n");
  assert.equal(python.length, ours.length);
  const differ = ours.map((r, i) => [r, python[i], ascii(frames[i])]).filter(([a, b]) => a !== b);
  assert.deepEqual(differ.slice(0, 5), [], `${differ.length} inputs decode differently`);
  const kinds = new Set(ours.map((r) => r.split(" ")[1]));
  for (const name of ["bad_category", "bad_direction", "bad_digit", "out_of_range", "too_short", "too_long"]) {
    assert.ok([...kinds].some((k) => k === name), `no ${name} in the sample`);
  }
  assert.ok(ours.filter((r) => r.startsWith("ok")).length > 10_000, "too few valid frames in the sample");
});
