// Shared by the TypeScript target's tests: where things are, the built package, the vectors, a seeded PRNG.
import { existsSync, readFileSync, readdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

export const TOOLS = resolve(dirname(fileURLToPath(import.meta.url)), "..");
export const ROOT = resolve(TOOLS, "../../..");
export const GENERATED = join(ROOT, "generated");
/** `make typescript` output: the package as built by `npm pack`, and the tarball beside it. */
export const BUILD = process.env.DRONE_PROTOCOL_TS_BUILD ?? join(ROOT, "build/typescript");
export const PACKAGE = join(BUILD, "package");
export const PYTHON = process.env.DRONE_PROTOCOL_PYTHON ?? join(ROOT, ".venv/bin/python");
export const VIRTUAL_DRONE = process.env.DRONE_PROTOCOL_VIRTUAL_DRONE ?? join(ROOT, "firmware/build/host/virtual_drone");
export const TSC = join(TOOLS, "node_modules/.bin/tsc");

if (!existsSync(join(PACKAGE, "dist/index.js"))) {
  throw new Error(`${PACKAGE}/dist/index.js is missing: run \`make typescript\` first`);
}

/** The generated package, compiled (its dist/index.js). */
export const dp = await import(join(PACKAGE, "dist/index.js"));

export function tarball() {
  const found = readdirSync(BUILD).filter((f) => f.endsWith(".tgz"));
  if (found.length !== 1) throw new Error(`expected one tarball in ${BUILD}, found ${found.join(", ") || "none"}`);
  return join(BUILD, found[0]);
}

const VECTORS_JSON = JSON.parse(readFileSync(join(GENERATED, "vectors.json"), "utf8"));
export const VECTORS = VECTORS_JSON.vectors;
/** Odd ready lines and what the spec's one rule makes of them. */
export const READY_LINES = VECTORS_JSON.ready_lines;

export function fromHex(hex) {
  return Uint8Array.from(hex.match(/../g) ?? [], (h) => parseInt(h, 16));
}

export function toHex(bytes) {
  return Array.from(bytes, (b) => b.toString(16).padStart(2, "0")).join("");
}

export function ascii(bytes) {
  return String.fromCharCode(...bytes);
}

/** A small seeded PRNG (mulberry32): the same streams on every run and in every language's driver input. */
export function rng(seed) {
  let a = seed >>> 0;
  const next = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  return {
    next,
    int: (n) => Math.floor(next() * n),
    pick: (list) => list[Math.floor(next() * list.length)],
    bytes: (n) => Uint8Array.from({ length: n }, () => Math.floor(next() * 256)),
  };
}
