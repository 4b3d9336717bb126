// The bench console's page in headless Chromium (Debian's), opened from a file as a user opens it: the command grid
// fits its column at common desktop widths (it overflowed by 30 px at 1280 and 1920: a fieldset never shrinks below
// its content by default), and a browser without Web Serial says so on the page, not only in a greyed button's
// tooltip.
import assert from "node:assert/strict";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { chromium } from "playwright-core";
import { PACKAGE } from "./support.mjs";

const CHROMIUM = process.env.CHROMIUM ?? "/usr/bin/chromium";
const FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
  "--disable-background-networking", "--disable-component-update", "--disable-sync"];
const PAGE = `file://${join(PACKAGE, "dist/console.html")}`;

let context;
let profile;

before(async () => {
  profile = mkdtempSync(join(tmpdir(), "console-layout-"));
  context = await chromium.launchPersistentContext(profile, { executablePath: CHROMIUM, args: FLAGS, headless: true });
});

after(async () => {
  await context?.close();
  if (profile) rmSync(profile, { recursive: true, force: true });
});

async function open(width, { withoutWebSerial = false } = {}) {
  const page = await context.newPage();
  await page.setViewportSize({ width, height: 900 });
  // A browser without the API: Firefox, Safari, or Chromium from an http: page.
  if (withoutWebSerial) await page.addInitScript(() => { delete Navigator.prototype.serial; });
  await page.goto(PAGE);
  await page.locator("[data-command]").first().waitFor({ timeout: 5000 });
  return page;
}

/** Every element that sticks out of its box: the page, the command grid, each command's fieldset. */
const overflows = (page) => page.evaluate(() => {
  const out = [];
  const doc = document.documentElement;
  if (doc.scrollWidth > doc.clientWidth) out.push(`page: ${doc.scrollWidth - doc.clientWidth} px`);
  const grid = document.querySelector(".commands");
  if (grid.scrollWidth > grid.clientWidth) out.push(`command grid: ${grid.scrollWidth - grid.clientWidth} px`);
  const gridBox = grid.getBoundingClientRect();
  for (const box of grid.querySelectorAll("fieldset")) {
    const edge = box.getBoundingClientRect();
    if (edge.right > gridBox.right + 0.5) out.push(`${box.querySelector("legend").textContent}: past the grid`);
    for (const part of box.querySelectorAll("*")) {
      const r = part.getBoundingClientRect();
      if (r.width > 0 && r.right > edge.right + 0.5) {
        out.push(`${part.closest("[data-command]")?.dataset.command ?? part.tagName}: ${Math.round(r.right - edge.right)} px`);
      }
    }
  }
  return out;
});

for (const width of [1280, 1920]) {
  test(`at ${width} px wide nothing overflows the command grid`, async () => {
    const page = await open(width);
    assert.deepEqual(await overflows(page), []);
    const columns = await page.locator(".commands").evaluate((g) => getComputedStyle(g).gridTemplateColumns.split(" ").length);
    assert.ok(columns >= 2, `${columns} column(s)`);
    await page.close();
  });
}

test("without Web Serial the page says why the serial button is grey, and what to use", async () => {
  const page = await open(1280, { withoutWebSerial: true });
  const notice = page.locator("#no-web-serial");
  assert.equal(await notice.isVisible(), true);
  assert.match(await notice.innerText(), /no Web Serial API.*Chromium, Chrome or Edge/s);
  assert.equal(await page.locator("#connect-serial").isDisabled(), true);
  assert.equal(await page.locator("#connect-bridge").isDisabled(), false);
  await page.close();
});

test("with Web Serial the notice stays out of the way", async () => {
  const page = await open(1280);
  assert.equal(await page.evaluate(() => "serial" in navigator), true);
  assert.equal(await page.locator("#no-web-serial").isVisible(), false);
  assert.equal(await page.locator("#connect-serial").isDisabled(), false);
  await page.close();
});
