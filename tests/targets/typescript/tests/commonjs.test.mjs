// The package from a CommonJS project, as most Node and TypeScript projects still are: `require()` and a CommonJS
// TypeScript build (both module resolutions tsc offers for it) compile and run against the installed tarball, and
// they get the same exports as `import`. The tarball carries its README and LICENSE and installs without a warning.
import assert from "node:assert/strict";
import { execFileSync, spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { GENERATED, ROOT, TSC, dp, tarball } from "./support.mjs";

const NAME = JSON.parse(readFileSync(join(GENERATED, "typescript/package.json"), "utf8")).name;
let project;
let installLog;

const run = (command, args) =>
  execFileSync(command, args, { cwd: project, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"] });

before(() => {
  project = mkdtempSync(join(tmpdir(), "drone-protocol-cjs-"));
  writeFileSync(join(project, "package.json"), JSON.stringify({ name: "cjs-project", private: true }));
  const install = spawnSync("npm", ["install", "--offline", "--no-audit", "--no-fund", "--loglevel=warn", tarball()],
    { cwd: project, encoding: "utf8" });
  assert.equal(install.status, 0, install.stderr);
  installLog = install.stdout + install.stderr;
});

after(() => rmSync(project, { recursive: true, force: true }));

test("npm installs the tarball with no warning", () => {
  assert.doesNotMatch(installLog, /warn|deprecat/i);
});

test("require() gets the same exports as import", () => {
  const script = `const p = require("${NAME}");
    const spec = Object.values(p.COMMANDS)[0];
    console.log(JSON.stringify([Object.keys(p).sort(), p.decode(p.encode(spec.category, spec.direction, spec.minimum)).name]));`;
  const [keys, name] = JSON.parse(run(process.execPath, ["-e", script]));
  assert.deepEqual(keys, Object.keys(dp).sort());
  assert.equal(name, Object.keys(dp.COMMANDS)[0]);
});

for (const [module, resolution] of [["commonjs", "node10"], ["node16", "node16"]]) {
  test(`a CommonJS TypeScript project (module ${module}, resolution ${resolution}) compiles and runs`, () => {
    const spec = Object.values(dp.COMMANDS)[0];
    writeFileSync(join(project, "main.ts"), `import { SPEC_FINGERPRINT, decode, ${spec.functionName}, type Command } from "${NAME}";
const command: Command = decode(${spec.functionName}(${spec.minimum}));
console.log(SPEC_FINGERPRINT, command.name);
`);
    writeFileSync(join(project, "tsconfig.json"), JSON.stringify({
      compilerOptions: { strict: true, module, moduleResolution: resolution, target: "es2020", types: [], outDir: "out" },
      files: ["main.ts"],
    }));
    rmSync(join(project, "out"), { recursive: true, force: true });
    run(TSC, ["-p", "tsconfig.json"]);
    assert.match(readFileSync(join(project, "out/main.js"), "utf8"), /require\(/);
    assert.equal(run(process.execPath, [join(project, "out/main.js")]).trim(), `${dp.SPEC_FINGERPRINT} ${spec.name}`);
  });
}

test("the tarball carries its README and the project's LICENSE", () => {
  const installed = join(project, "node_modules", NAME);
  assert.match(readFileSync(join(installed, "README.md"), "utf8"), new RegExp(dp.SPEC_FINGERPRINT));
  assert.equal(readFileSync(join(installed, "LICENSE"), "utf8"), readFileSync(join(ROOT, "LICENSE"), "utf8"));
  assert.ok(existsSync(join(installed, "dist/cjs/index.d.ts")) && existsSync(join(installed, "dist/index.d.ts")));
});
