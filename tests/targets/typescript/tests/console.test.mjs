// The bench console in headless Chromium (Debian's), driven by playwright-core, flying the virtual drone (the
// firmware's host build) through the WebSocket bridge: the serial layer is the console's own LinkOpener, the page
// is the self-contained dist/console.html opened from a file, as a user opens it.
import assert from "node:assert/strict";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { chromium } from "playwright-core";
import { startBridge } from "../ws_bridge.mjs";
import { BUILD, PACKAGE, VIRTUAL_DRONE, dp } from "./support.mjs";

const CHROMIUM = process.env.CHROMIUM ?? "/usr/bin/chromium";
// playwright adds --headless and the profile folder (a fresh one per run).
const FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
  "--disable-background-networking", "--disable-component-update", "--disable-sync"];
const MOVE = Object.values(dp.COMMANDS).find((s) => s.category === dp.CATEGORIES[0].code && s.default !== null);
const ARM = dp.COMMANDS.arm;

let bridge;
let context;
let page;
let profile;
const pageErrors = [];

before(async () => {
  bridge = await startBridge({ executable: VIRTUAL_DRONE });
  profile = mkdtempSync(join(tmpdir(), "console-chromium-"));
  context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM, args: FLAGS, headless: true, viewport: { width: 1180, height: 1000 },
  });
  page = context.pages()[0] ?? await context.newPage();
  page.on("pageerror", (error) => pageErrors.push(error.message));
  await page.goto(`file://${join(PACKAGE, "dist/console.html")}?bridge=${bridge.url}`);
});

after(async () => {
  await context?.close();
  await bridge?.close();
  if (profile) rmSync(profile, { recursive: true, force: true });
});

const row = (name) => page.locator(`[data-command="${name}"]`);
const logText = () => page.locator("#log").innerText();
/** Waits until the virtual drone reports, after its output line `from`, an output that satisfies `predicate`. */
async function droneReports(predicate, timeoutMs, what, from = 0) {
  const deadline = Date.now() + timeoutMs;
  while (Date.now() < deadline) {
    if (bridge.outputs.slice(from).some(predicate)) return;
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  const last = JSON.stringify(bridge.outputs.at(-1));
  assert.fail(`the virtual drone never reported ${what}; its last output: ${last}; the console's log:\n${await logText()}`);
}

test("the page builds one control per command from the spec, and waits for a link", async () => {
  assert.equal(await page.locator("[data-command]").count(), Object.keys(dp.COMMANDS).length);
  for (const spec of Object.values(dp.COMMANDS)) {
    const input = row(spec.name).locator("input");
    if (spec.minimum === spec.maximum) {
      assert.equal(await input.count(), 0, spec.name);
    } else {
      assert.equal(await input.getAttribute("min"), String(spec.minimum), spec.name);
      assert.equal(await input.getAttribute("max"), String(spec.maximum), spec.name);
      assert.equal(await input.inputValue(), spec.default === null ? "" : String(spec.default), spec.name);
    }
    assert.equal(await row(spec.name).locator("button").isDisabled(), true, `${spec.name} enabled with no link`);
  }
  assert.equal(await page.locator("#safe").isDisabled(), true);
});

test("connect: the ready line with this spec's fingerprint enables the controls", async () => {
  await page.click("#connect-bridge");
  await page.locator("#ready.ok").waitFor({ timeout: 5000 });
  assert.match(await page.locator("#ready").innerText(), new RegExp(`${dp.PROTOCOL_NAME} ${dp.SPEC_FINGERPRINT}`));
  assert.equal(await row(MOVE.name).locator("button").isDisabled(), false);
  assert.equal(await page.locator("#safe").isDisabled(), false);
});

test("a move before arming is refused, and the refusal is shown by its error name", async () => {
  await row(MOVE.name).locator("button").click();
  await page.locator('#errors [data-error="not_armed"]').waitFor({ timeout: 3000 });
  assert.match(await logText(), new RegExp(`rejected: not_armed \\(${dp.ERRORS.not_armed.description}\\)`));
});

test("arm through the UI (keep-alive on), send a move: acknowledged, and the drone flies it", async () => {
  await page.check("#keepalive");
  await row(ARM.name).locator("button").click();
  await page.locator("#log li", { hasText: "acknowledged arm" }).waitFor({ timeout: 3000 });
  await droneReports((o) => o.armed === true, dp.ARMING_HOLD_MS + 2000, "armed");
  const value = MOVE.default + 50 <= MOVE.maximum ? MOVE.default + 50 : MOVE.minimum;
  await row(MOVE.name).locator("input").fill(String(value));
  await row(MOVE.name).locator("button").click();
  await page.locator("#log li", { hasText: `acknowledged ${MOVE.name}` }).waitFor({ timeout: 3000 });
  const channel = dp.CHANNELS[MOVE.target];
  assert.ok(channel !== undefined, `${MOVE.name} drives ${MOVE.target}`);
  await droneReports((o) => o[MOVE.target] === value, 2000, `${MOVE.target} at ${value}`);
  assert.equal(await page.locator("#failsafe").isHidden(), true, "failsafe shown while the link is alive");
});

test("silence: the failsafe fires and is shown", async () => {
  await page.uncheck("#keepalive");
  const silentFrom = Date.now();
  const from = bridge.outputs.length;
  await page.locator("#failsafe").waitFor({ state: "visible", timeout: dp.FAILSAFE_TIMEOUT_MS + 3000 });
  assert.ok(Date.now() - silentFrom >= dp.FAILSAFE_TIMEOUT_MS - 300, "failsafe shown too early");
  assert.match(await page.locator("#failsafe").innerText(), /FAILSAFE/);
  await droneReports((o) => o.throttle === dp.FAILSAFE_THROTTLE_US, 2000, "the failsafe throttle", from);
});

test("an out-of-range or malformed value cannot be sent, by button or by Enter", async () => {
  const button = row(MOVE.name).locator("button");
  const input = row(MOVE.name).locator("input");
  const before = bridge.sentToDrone();
  const logBefore = await page.locator("#log li").count();
  for (const bad of [String(MOVE.maximum + 1), String(MOVE.minimum - 1), `${MOVE.default}.5`, "-5", "1e3", ""]) {
    await input.fill(bad);
    assert.equal(await button.isDisabled(), true, `send enabled for ${JSON.stringify(bad)}`);
    assert.equal(await input.getAttribute("aria-invalid"), bad === "" ? "false" : "true", bad);
    await input.press("Enter");
    await button.click({ force: true, timeout: 1000 }).catch(() => undefined);
    await page.evaluate((name) => document.querySelector(`[data-command="${name}"] button`).click(), MOVE.name);
  }
  await page.waitForTimeout(300);
  assert.equal(bridge.sentToDrone(), before, "bytes reached the drone");
  assert.equal(await page.locator("#log li").count(), logBefore, "something was logged as sent");
  await input.fill(String(MOVE.default));
  assert.equal(await button.isDisabled(), false);
});

test("the safe button: laser off, neutral, disarm, and the drone ends disarmed", async () => {
  const sentBefore = await page.locator("#log li.sent").count();
  const from = bridge.outputs.length;
  await page.click("#safe");
  for (const name of ["laser_off", "hold_altitude", "disarm"].filter((n) => n in dp.COMMANDS)) {
    await page.locator("#log li.sent", { hasText: name }).last().waitFor({ timeout: 3000 });
  }
  assert.ok((await page.locator("#log li.sent").count()) > sentBefore);
  // (The laser is not checked here: firmware built before laser_off existed runs it as its category's toggle.)
  await droneReports((o) => o.armed === false, 3 * dp.ARMING_HOLD_MS + 3000, "disarmed", from);
  assert.deepEqual(pageErrors, []);
  // The README's picture (docs/img/console.png is a copy of it): at 75 %, to keep the file small.
  await page.evaluate(() => { document.body.style.zoom = "0.75"; });
  await page.locator("main").screenshot({ path: join(BUILD, "console.png") });
});
