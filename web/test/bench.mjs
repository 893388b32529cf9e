// Frame rate of hikari's web page in Debian's headless Chromium (WebGPU on
// SwiftShader) for BENCHMARKS.md: `node web/test/bench.mjs [SCENE] [WxH]
// [PHOTONS] [SECONDS]` serves web/dist, opens the page at that size and
// prints the time to the first frame and the page's mean fps. With
// HIKARI_PASSES=1 the panel shows, and the last timed frame's passes are
// printed too (a timed frame waits for each pass: fps reads lower).
// HIKARI_TRACE=gpu|cpu|auto sets the page's trace= option; HIKARI_FLAGS adds
// Chromium flags (space-separated).
import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { readFile } from "node:fs/promises";
import { extname, join } from "node:path";
import { fileURLToPath } from "node:url";

const [scene = "cornell-box", size = "640x480", photons = "20000", seconds = "20"] = process.argv.slice(2);
const [width, height] = size.split("x").map(Number);
const dist = fileURLToPath(new URL("../dist/", import.meta.url));
const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };
const server = createServer(async (request, response) => {
  const path = new URL(request.url, "http://x").pathname.replace(/^\/+/, "") || "index.html";
  try {
    const body = await readFile(join(dist, path));
    response.writeHead(200, { "content-type": types[extname(path)] || "application/octet-stream" });
    response.end(body);
  } catch {
    response.writeHead(404);
    response.end();
  }
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const browser = await chromium.launch({
  executablePath: process.env.HIKARI_CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--no-first-run", "--disable-background-networking", "--use-angle=swiftshader",
         "--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader",
         "--use-webgpu-adapter=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", ...(process.env.HIKARI_FLAGS ? process.env.HIKARI_FLAGS.split(" ") : [])],
});
const page = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
const started = Date.now();
const panel = process.env.HIKARI_PASSES === "1" ? 1 : 0;
const trace = process.env.HIKARI_TRACE ? `&trace=${process.env.HIKARI_TRACE}` : "";
await page.goto(`http://127.0.0.1:${server.address().port}/?scene=${scene}&photons=${photons}&panel=${panel}${trace}`);
await page.waitForFunction(() => window.hikari && window.hikari.framesInMean() > 0, null, { timeout: 120000, polling: 20 });
const firstFrame = Date.now() - started;
const framesBefore = await page.evaluate(() => window.hikari.framesInMean());
await page.waitForTimeout(Number(seconds) * 1000);
const [fps, adapter, error, framesAfter] = await page.evaluate(() =>
  [window.hikari.fps(), window.hikari.adapter(), window.hikari.lastError(), window.hikari.framesInMean()]);
// Frames added to the mean over the window: each renders a new photon set.
const added = (framesAfter - framesBefore) / Number(seconds);
console.log(`${scene} ${size}, ${photons} photons a set: first frame ${firstFrame} ms after navigation, ` +
  `${added.toFixed(3)} frames/s added to the mean (panel: ${fps.toFixed(2)} fps) over ${seconds} s ` +
  `on ${adapter}${error ? "; error: " + error : ""}`);
if (panel) {
  const timed = JSON.parse(await page.evaluate(() => window.hikari.passTimes()));
  console.log(`passes (${timed.timed}): ` + timed.passes.map((p) => `${p.pass} ${p.ms.toFixed(1)} ms`).join(", "));
}
await browser.close();
server.close();
