// A screenshot of hikari's page in Debian's headless Chromium (WebGPU on
// SwiftShader), to look at it as a user would: `node web/test/shot.mjs
// QUERY WIDTH HEIGHT DEVICE_PIXELS OUT.png WAIT_MS`, e.g. `"" 390 844 2
// /tmp/phone.png 8000` (a phone, touch on when DEVICE_PIXELS > 1). Serves
// web/dist (`bash scripts/web.sh build`) and prints the page's console.
import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { readFile } from "node:fs/promises";
import { extname, join } from "node:path";
import { fileURLToPath } from "node:url";
const dist = fileURLToPath(new URL("../dist/", import.meta.url));
const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };
const server = createServer(async (q, r) => {
  const p = new URL(q.url, "http://x").pathname.replace(/^\/+/, "") || "index.html";
  try { const b = await readFile(join(dist, p)); r.writeHead(200, { "content-type": types[extname(p)] || "application/octet-stream" }); r.end(b); }
  catch { r.writeHead(404); r.end(); }
});
await new Promise((res) => server.listen(0, "127.0.0.1", res));
const args = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-webgpu-adapter=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"];
const [query, w, h, scale, out, wait] = process.argv.slice(2);
const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args });
const page = await browser.newPage({ viewport: { width: +w, height: +h }, deviceScaleFactor: +scale, hasTouch: +scale > 1, isMobile: +scale > 1 });
page.on("console", (m) => console.log("console:", m.type(), m.text()));
const t0 = Date.now();
await page.goto(`http://127.0.0.1:${server.address().port}/${query}`);
await page.waitForTimeout(+wait);
// A screenshot waits for a frame, which takes seconds on a software adapter.
await page.screenshot({ path: out, timeout: 180000 });
console.log("shot", out, Date.now() - t0, "ms");
await browser.close(); server.close();
