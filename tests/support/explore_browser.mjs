// Drive the page of `pbrkit explore` in headless Chromium (Debian's `chromium`) with
// puppeteer-core, and print one JSON line with what happened.
//
//   node tests/support/explore_browser.mjs URL [--timeout S] [--slider TITLE] [--value X] [--source NAME]
//
// Loads URL, waits until BokehJS has rendered the document (the root views exist and the
// data source NAME, default `incidence_a`, holds data), reads that source's `y` column,
// sets the value of the slider whose title is TITLE (default `roughness`) through the
// page's Bokeh document (as a user's drag does: the model's `value` changes and BokehJS
// sends it to the server), then waits until the server's new data reaches the source.
// Output: {"rendered", "slider", "before", "after", "changed", "console", "errors"}, where
// `console` holds every console message and `errors` the page errors, failed requests
// and console errors.  Exit status 0 when the page rendered and the data changed.
import path from "node:path";
import { fileURLToPath } from "node:url";
import { createRequire } from "node:module";

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, "..", "engines", "package.json"));
const puppeteer = (await import(require.resolve("puppeteer-core"))).default;

const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const url = args[0];
const timeout = 1000 * Number(opt("--timeout", "60"));
const sliderTitle = opt("--slider", "roughness");
const sliderValue = Number(opt("--value", "0.85"));
const sourceName = opt("--source", "incidence_a");

const report = { rendered: false, slider: null, before: null, after: null, changed: false, console: [], errors: [] };
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  headless: true,
  args: ["--no-sandbox", "--disable-dev-shm-usage", "--window-size=1400,1000"],
});
let status = 1;
try {
  const tab = await browser.newPage();
  tab.on("console", (m) => {
    report.console.push(`${m.type()}: ${m.text()}`);
    if (m.type() === "error") report.errors.push(`console error: ${m.text()}`);
  });
  tab.on("pageerror", (e) => report.errors.push(`page error: ${e && e.message ? e.message : e}`));
  tab.on("requestfailed", (r) => report.errors.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
  await tab.goto(url, { waitUntil: "load", timeout });
  // BokehJS has rendered: a document, root views in Bokeh.index, and the source holds data.
  await tab.waitForFunction((name) => {
    const B = window.Bokeh;
    if (!B || !B.documents || B.documents.length === 0) return false;
    const views = B.index ? Object.keys(B.index).length : 0;
    const src = B.documents[0].get_model_by_name(name);
    return views > 0 && src != null && src.data.y != null && src.data.y.length > 0;
  }, { timeout, polling: 100 }, sourceName);
  report.rendered = true;
  const read = (name) => tab.evaluate((name) => {
    const src = window.Bokeh.documents[0].get_model_by_name(name);
    return Array.from(src.data.y, Number);
  }, name);
  report.before = await read(sourceName);
  report.slider = await tab.evaluate((title, value) => {
    const doc = window.Bokeh.documents[0];
    const models = doc._all_models ? Array.from(doc._all_models.values()) : Array.from(doc.all_models);
    const slider = models.find((m) => m.type === "Slider" && m.title === title)
      ?? models.find((m) => "title" in m && m.title === title && "value" in m && "start" in m);
    if (!slider) return null;
    const old = slider.value;
    slider.value = value;
    return { type: slider.type, title: slider.title, old, value: slider.value };
  }, sliderTitle, sliderValue);
  if (report.slider !== null) {
    await tab.waitForFunction((name, before) => {
      const y = Array.from(window.Bokeh.documents[0].get_model_by_name(name).data.y, Number);
      return y.length !== before.length || y.some((x, i) => x !== before[i]);
    }, { timeout, polling: 100 }, sourceName, report.before);
    report.after = await read(sourceName);
    report.changed = true;
  }
  status = report.changed && report.errors.length === 0 ? 0 : 1;
} catch (e) {
  report.errors.push(`driver: ${e && e.message ? e.message : e}`);
} finally {
  await browser.close();
}
const cut = (a) => (Array.isArray(a) ? a.slice(0, 400) : a);
report.before = cut(report.before);
report.after = cut(report.after);
console.log(JSON.stringify(report));
process.exit(status);
