#!/usr/bin/env node
// The generated TypeScript parseReply() as a command-line driver, for differential tests across languages.
//
//   node tests/targets/typescript/reply_driver.mjs PACKAGE_DIST
//
// stdin: one line per input line in hex. stdout: what parseReply() made of it, "ready <protocol> <fingerprint>
// <integrity>", "ok <kind>", "malformed <prefix>", "unknown" or "bad_check", the format every language's reply
// driver (tests/targets/drivers/reply_driver.*) shares.
import { createInterface } from "node:readline";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const dist = resolve(process.argv[2]);
const { parseReply, REPLIES } = await import(pathToFileURL(join(dist, "index.js")).href);

const out = [];
for await (const hex of createInterface({ input: process.stdin, crlfDelay: Infinity })) {
  const bytes = Uint8Array.from(hex.match(/../g) ?? [], (h) => parseInt(h, 16));
  try {
    const reply = parseReply(bytes);
    out.push(reply.kind === "ready" ? `ready ${reply.protocol} ${reply.fingerprint} ${reply.integrity}` : `ok ${reply.kind}`);
  } catch (error) {
    if (error.code === "bad_check") out.push("bad_check");
    else if (/^unknown reply/.test(error.message)) out.push("unknown");
    else {
      const kind = /^malformed (\w+) reply/.exec(error.message)?.[1];
      out.push(kind === undefined ? `other ${error.message}` : `malformed ${REPLIES[kind].prefix}`);
    }
  }
}
process.stdout.write(out.length ? `${out.join("\n")}\n` : "");
