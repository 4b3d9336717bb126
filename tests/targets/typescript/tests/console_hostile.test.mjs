// Spec text is inert in the bench console: a package generated from a spec whose descriptions hold what would end
// the page's script or switch the HTML parser into a state where the real </script> no longer ends it ("<!--" then
// "<script" left the page stuck on "Loading the console…"), built as `npm run build` does, opened in headless
// Chromium from a file: the console starts, and the hostile text is shown as text.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { chromium } from "playwright-core";
import { PYTHON, ROOT, TSC } from "./support.mjs";

const CHROMIUM = process.env.CHROMIUM ?? "/usr/bin/chromium";
const FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
  "--disable-background-networking", "--disable-component-update", "--disable-sync"];
// Each replaces one description of the spec (the reader refuses backslashes and C comment markers already).
const HOSTILE = {
  "    description: Move the drone forward, backward, strafe left or right, move up or down.": "<!--<script>",
  "        description: Strafe left": "</script><script>document.title='owned'</script>",
  "        description: Turn left": "<!-- </SCRIPT > -->",
  "        description: Arms the drone": "<ScRiPt>globalThis.owned = 1</sCrIpT> <b>bold</b> `code` ${x}",
};

let dir;
let context;
let page;
const pageErrors = [];

before(async () => {
  dir = mkdtempSync(join(tmpdir(), "drone-protocol-hostile-console-"));
  let spec = readFileSync(join(ROOT, "spec/drone.yaml"), "utf8");
  for (const [line, text] of Object.entries(HOSTILE)) {
    assert.equal(spec.split(`${line}\n`).length, 2, `the spec line moved: ${line}`);
    spec = spec.replace(`${line}\n`, `${line.slice(0, line.indexOf(":") + 1)} ${JSON.stringify(text)}\n`);
  }
  writeFileSync(join(dir, "drone.yaml"), spec);
  execFileSync(PYTHON, ["-m", "generator", "--spec", join(dir, "drone.yaml"), "--out", join(dir, "out")], { cwd: ROOT });
  const pkg = join(dir, "out/typescript");
  execFileSync(TSC, ["-p", join(pkg, "tsconfig.json")]);  // the package's own build: ES modules, CommonJS, console
  execFileSync(TSC, ["-p", join(pkg, "tsconfig.cjs.json")]);
  execFileSync("node", [join(pkg, "scripts/build-console.mjs")], { cwd: pkg });
  context = await chromium.launchPersistentContext(join(dir, "profile"), {
    executablePath: CHROMIUM, args: FLAGS, headless: true,
  });
  page = context.pages()[0] ?? await context.newPage();
  page.on("pageerror", (error) => pageErrors.push(error.message));
  await page.goto(`file://${join(pkg, "dist/console.html")}?bridge=ws://127.0.0.1:9`);
});

after(async () => {
  await context?.close();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

test("the console starts with hostile descriptions, shows them as text and runs none of them", async () => {
  await page.locator("[data-command]").first().waitFor({ timeout: 10000 });
  assert.doesNotMatch(await page.locator("#app").innerText(), /Loading the console/);
  const shown = await page.locator("#app").innerText();
  for (const text of Object.values(HOSTILE)) assert.ok(shown.includes(text), `not shown as text: ${text}`);
  assert.equal(await page.locator("script").count(), 1, "a description became a script element");
  assert.equal(await page.locator("#app b").count(), 0, "a description became markup");
  assert.equal(await page.title(), "drone_protocol bench console");
  assert.equal(await page.evaluate(() => globalThis.owned), undefined);
  assert.deepEqual(pageErrors, []);
});
