// Open a test page in headless Chromium (Debian's `chromium`, WebGL2 through
// SwiftShader) with puppeteer-core, and print what the page reports as one JSON line.
//
//   node harness.mjs PAGE [--data DIR] [--query 'a=1&b=2'] [--screenshot FILE] [--timeout S]
//
// A static server on 127.0.0.1 (a free port) serves, read-only:
//   /pages/...         tests/engines/pages
//   /node_modules/...  tests/engines/node_modules (the pinned engines)
//   /pbrkit-js/...     src/pbrkit/js (the modules pbrkit ships)
//   /data/...          DIR (the files under test, e.g. a bake)
// The page sets `window.__pbrkitResult` (any JSON value) when it is done, or
// `window.__pbrkitError` (a string) when it fails.  Output: {"result": ...,
// "console": [...], "errors": [...]}; exit status 0 when the page reported a
// result, 1 otherwise (with the reason on stderr).
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import puppeteer from "puppeteer-core";

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const page = args[0];
const roots = {
  pages: path.join(here, "pages"),
  node_modules: path.join(here, "node_modules"),
  "pbrkit-js": path.resolve(here, "..", "..", "src", "pbrkit", "js"),
  data: opt("--data", null),
};
const types = {
  ".html": "text/html", ".js": "text/javascript", ".mjs": "text/javascript", ".json": "application/json",
  ".wasm": "application/wasm", ".png": "image/png", ".hdr": "application/octet-stream",
};

const server = http.createServer((req, res) => {
  const url = new URL(req.url, "http://127.0.0.1");
  const parts = decodeURIComponent(url.pathname).split("/").filter(Boolean);
  if (url.pathname === "/favicon.ico") {
    res.writeHead(204);
    res.end();
    return;
  }
  const base = roots[parts[0]];
  const file = base ? path.resolve(base, ...parts.slice(1)) : null;
  if (!file || !file.startsWith(path.resolve(base)) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
    res.writeHead(404);
    res.end("not found");
    return;
  }
  res.writeHead(200, { "Content-Type": types[path.extname(file)] || "application/octet-stream" });
  fs.createReadStream(file).pipe(res);
});

async function main() {
  await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
  const port = server.address().port;
  const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
           "--enable-webgl", "--disable-dev-shm-usage", "--window-size=800,600"],
  });
  const consoleLines = [];
  const errors = [];
  try {
    const tab = await browser.newPage();
    tab.on("console", (m) => consoleLines.push(`${m.type()}: ${m.text()}`));
    tab.on("pageerror", (e) => errors.push(String(e && e.message ? e.message : e)));
    tab.on("requestfailed", (r) => errors.push(`request failed: ${r.url()}`));
    const query = opt("--query", "");
    await tab.goto(`http://127.0.0.1:${port}/pages/${page}${query ? "?" + query : ""}`);
    const timeout = 1000 * Number(opt("--timeout", "120"));
    await tab.waitForFunction("window.__pbrkitResult !== undefined || window.__pbrkitError !== undefined",
                              { timeout, polling: 100 });
    const [result, failure] = await tab.evaluate(() => [window.__pbrkitResult, window.__pbrkitError]);
    const shot = opt("--screenshot", null);
    if (shot) {
      const canvas = await tab.$("canvas");
      await (canvas || tab).screenshot({ path: shot });
    }
    process.stdout.write(JSON.stringify({ result: result ?? null, error: failure ?? null, console: consoleLines,
                                          errors }) + "\n");
    return failure == null ? 0 : 1;
  } finally {
    await browser.close();
    server.close();
  }
}

main().then((code) => process.exit(code), (e) => {
  process.stderr.write(`harness: ${e && e.message ? e.message : e}\n`);
  server.close();
  process.exit(1);
});
