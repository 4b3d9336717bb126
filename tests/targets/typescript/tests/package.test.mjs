// The package as a user gets it: `npm pack`'s tarball installed into a fresh project, imported from plain Node,
// its types checked by tsc, and the usage examples of the README and the generated docs compiled and run.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { GENERATED, PACKAGE, ROOT, TSC, dp, tarball } from "./support.mjs";

const NAME = JSON.parse(readFileSync(join(GENERATED, "typescript/package.json"), "utf8")).name;
let project;

const run = (command, args, options = {}) =>
  execFileSync(command, args, { cwd: project, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], ...options });

before(() => {
  project = mkdtempSync(join(tmpdir(), "drone-protocol-ts-"));
  writeFileSync(join(project, "package.json"), JSON.stringify({ name: "user-project", private: true, type: "module" }));
  run("npm", ["install", "--offline", "--no-audit", "--no-fund", "--loglevel=error", tarball()]);
});

after(() => rmSync(project, { recursive: true, force: true }));

test("the tarball installs with no dependencies and imports from plain Node", () => {
  const installed = JSON.parse(readFileSync(join(project, "node_modules", NAME, "package.json"), "utf8"));
  assert.deepEqual(installed.dependencies ?? {}, {});
  assert.equal(installed.version, `${dp.PROTOCOL_VERSION}.0.0`);
  assert.deepEqual(readdirSync(join(project, "node_modules")).filter((d) => !d.startsWith(".")), [NAME]);
  const script = `import * as p from "${NAME}";
    const spec = Object.values(p.COMMANDS)[0];
    const frame = p.encode(spec.category, spec.direction, spec.minimum);
    console.log(p.SPEC_FINGERPRINT, frame instanceof Uint8Array, p.decode(frame).name);`;
  assert.equal(run(process.execPath, ["--input-type=module", "-e", script]).trim(),
    `${dp.SPEC_FINGERPRINT} true ${Object.keys(dp.COMMANDS)[0]}`);
  // The bench console ships in the package as one page.
  assert.match(readFileSync(join(project, "node_modules", NAME, "dist/console.html"), "utf8"), /startConsole/);
});

test("its types are strict: a TypeScript user gets the spec's names and is refused others", () => {
  const spec = Object.values(dp.COMMANDS)[0];
  writeFileSync(join(project, "tsconfig.json"), JSON.stringify({
    compilerOptions: { strict: true, noEmit: true, module: "nodenext", moduleResolution: "nodenext", target: "es2020", types: [] },
  }));
  writeFileSync(join(project, "good.ts"), `import { type Command, type ErrorName, ProtocolError, decode, ${spec.functionName} } from "${NAME}";
const frame: Uint8Array = ${spec.functionName}(${spec.minimum});
const command: Command = decode(frame);
const name: "${spec.name}" | string = command.name;
const code: ErrorName = "${Object.keys(dp.ERRORS)[0]}";
export const all = [name, code, new ProtocolError(code, "m")];
`);
  run(TSC, ["-p", "tsconfig.json"]);
  writeFileSync(join(project, "bad.ts"), `import { type CommandName, type ErrorName } from "${NAME}";
export const a: CommandName = "no_such_command";
export const b: ErrorName = "no_such_error";
`);
  const failed = (() => {
    try {
      run(TSC, ["-p", "tsconfig.json"]);
      return "";
    } catch (error) {
      return error.stdout;
    }
  })();
  rmSync(join(project, "bad.ts"));
  assert.match(failed, /bad\.ts\(2,14\): error TS2322/);
  assert.match(failed, /bad\.ts\(3,14\): error TS2322/);
});

test("the generated sources are strict TypeScript; the codec needs neither the DOM nor Node", () => {
  const sources = join(GENERATED, "typescript");
  run(TSC, ["-p", join(sources, "tsconfig.json"), "--strict", "--noEmit"]);
  run(TSC, ["--strict", "--noEmit", "--lib", "es2020", "--module", "nodenext", "--moduleResolution", "nodenext",
    "--target", "es2020", join(sources, "src/index.ts")], { cwd: PACKAGE });
});

/** The ```ts block of the section `heading` in `file`, with its "// → output" comments. */
function example(file, heading) {
  const text = readFileSync(file, "utf8");
  const start = text.indexOf(`${heading}\n`);
  assert.ok(start >= 0, `${file} has no "${heading}" section`);
  const block = /```ts\n([\s\S]*?)```/.exec(text.slice(start));
  assert.ok(block !== null, `${file}: no ts block under ${heading}`);
  const code = block[1];
  const expected = [...code.matchAll(/\/\/ → (.*)$/gm)].map((m) => m[1]);
  assert.ok(expected.length >= 2, `${file}: the example shows no outputs`);
  return { code, expected };
}

for (const [file, heading] of [[join(ROOT, "README.md"), "### Using the TypeScript package"],
  [join(GENERATED, "docs/protocol.md"), "## TypeScript"]]) {
  test(`the usage example of ${file.slice(ROOT.length + 1)} compiles and prints what it says`, () => {
    const { code, expected } = example(file, heading);
    const lines = code.trimEnd().split("\n").filter((l) => l.trim() !== "");
    assert.ok(lines.length <= 6, `the example has ${lines.length} lines`);
    writeFileSync(join(project, "example.ts"), code);
    writeFileSync(join(project, "tsconfig.json"), JSON.stringify({
      compilerOptions: { strict: true, module: "nodenext", moduleResolution: "nodenext", target: "es2020", lib: ["es2020", "dom"], types: [], outDir: "out" },
      files: ["example.ts"],
    }));
    run(TSC, ["-p", "tsconfig.json"]);
    const output = run(process.execPath, [join(project, "out/example.js")]).trimEnd().split("\n");
    assert.deepEqual(output, expected);
  });
}
