// Drives hikari's web page in Debian's headless Chromium (playwright-core,
// which downloads no browser) for crates/cli/tests/web.rs, which makes the
// assertions: `node drive.mjs SCENARIO OUT_DIR` serves web/dist on a free
// localhost port, runs the scenario, and writes OUT_DIR/result.json (and
// any images) for the Rust test to check.
import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { readFile, writeFile } from "node:fs/promises";
import { extname, join, normalize } from "node:path";
import { fileURLToPath } from "node:url";

const [scenario, out] = process.argv.slice(2);
const dist = fileURLToPath(new URL("../dist/", import.meta.url));
const chromiumPath = process.env.HIKARI_CHROMIUM || "/usr/bin/chromium";

// WebGPU on SwiftShader (Chromium's CPU Vulkan), the flags the issue names;
// no network (this machine has none, and a test must not need it). Without
// --use-angle=swiftshader, headless Chromium 156 destroys a device that
// presents to a canvas after a few dozen frames ("Device was destroyed",
// reproduced in plain JavaScript, without hikari).
const webgpuFlags = [
  "--use-angle=swiftshader",
  "--enable-unsafe-webgpu",
  "--enable-features=Vulkan",
  "--use-vulkan=swiftshader",
  "--use-webgpu-adapter=swiftshader",
  "--enable-unsafe-swiftshader",
  "--ignore-gpu-blocklist",
];
// HIKARI_BROWSER=stock: Chromium as a user's is, with only the flag that
// headless Chromium needs to expose WebGPU at all. Headless, it composites
// the page in software and cannot present a WebGPU canvas: the page copies
// its frames into a 2D canvas (crates/web/src/canvas_copy.rs).
const stock = process.env.HIKARI_BROWSER === "stock";
const browserFlags = stock ? ["--enable-unsafe-webgpu"] : webgpuFlags;
const quietFlags = [
  "--no-sandbox",
  "--no-first-run",
  "--disable-background-networking",
  "--disable-component-update",
  "--disable-sync",
  "--disable-quic",
];

const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };

function serve() {
  const server = createServer(async (request, response) => {
    const path = normalize(decodeURIComponent(new URL(request.url, "http://x").pathname)).replace(/^\/+/, "");
    try {
      const body = await readFile(join(dist, path || "index.html"));
      response.writeHead(200, { "content-type": types[extname(path || "index.html")] || "application/octet-stream" });
      response.end(body);
    } catch {
      response.writeHead(404);
      response.end();
    }
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () => resolve(server)));
}

async function open(browser, query, { width = 48, height = 36, log, phone = false } = {}) {
  const device = phone ? { deviceScaleFactor: 2, isMobile: true, hasTouch: true } : { deviceScaleFactor: 1 };
  const context = await browser.newContext({ viewport: { width, height }, ...device, acceptDownloads: true });
  const page = await context.newPage();
  page.on("console", (m) => log.push({ type: m.type(), text: m.text() }));
  page.on("pageerror", (e) => log.push({ type: "pageerror", text: String(e) }));
  const started = Date.now();
  await page.goto(`${base}/${query}`);
  return { page, started };
}

/** Waits until `predicate` (run in the page) is true, at most `seconds`. */
async function until(page, predicate, seconds, arg) {
  await page.waitForFunction(predicate, arg, { timeout: seconds * 1000, polling: 100 });
}

// Frames are in the mean. In stock mode, in the 2D-canvas copy: the page
// draws a few frames to its WebGPU canvas before the browser destroys that
// device, and input during the restart would reach the old page state.
// (Each predicate runs in the page, so it stands alone.)
const framesShown = () => window.hikari && window.hikari.framesInMean && window.hikari.framesInMean() > 0;
const framesCopied = () =>
  window.hikari && window.hikari.framesInMean && window.hikari.framesInMean() > 0 && window.hikari.presentation() === "copy";
const hikariReady = stock ? framesCopied : framesShown;

async function readMean(page) {
  const values = await page.evaluate(async () => Array.from(await window.hikari.readMean()));
  return { width: values[0], height: values[1], rgba: values.slice(2) };
}

function meanOf(rgba) {
  let sum = 0;
  for (let i = 0; i < rgba.length; i += 4) sum += rgba[i] + rgba[i + 1] + rgba[i + 2];
  return sum / (rgba.length / 4) / 3;
}

async function writeMean(file, mean) {
  await writeFile(join(out, file), Buffer.from(new Float32Array([mean.width, mean.height, ...mean.rgba]).buffer));
}

const server = await serve();
const base = `http://127.0.0.1:${server.address().port}`;
const result = { scenario };
const log = [];
let browser;
try {
  if (scenario === "no-webgpu") {
    // A browser without WebGPU: the page says so in one line.
    browser = await chromium.launch({ executablePath: chromiumPath, args: [...quietFlags, "--disable-webgpu"] });
    const { page } = await open(browser, "", { width: 640, height: 480, log });
    await until(page, () => getComputedStyle(document.getElementById("no-webgpu")).display !== "none", 30);
    result.message = await page.textContent("#no-webgpu");
    result.canvasHidden = await page.evaluate(() => getComputedStyle(document.getElementById("hikari-canvas")).display === "none");
  } else {
    browser = await chromium.launch({ executablePath: chromiumPath, args: [...quietFlags, ...browserFlags] });
    if (scenario === "converge") {
      // The default scene, 3000 photons a set, 30 frames: the mean and
      // how long the first frame took (HIKARI_SCENE, HIKARI_FRAMES and
      // HIKARI_TRACE change them).
      const frames = Number(process.env.HIKARI_FRAMES || 30);
      const scene = process.env.HIKARI_SCENE ? `&scene=${process.env.HIKARI_SCENE}` : "";
      const trace = process.env.HIKARI_TRACE ? `&trace=${process.env.HIKARI_TRACE}` : "";
      const { page, started } = await open(browser, `?photons=3000&frames=${frames}&panel=0${scene}${trace}`, { log });
      await until(page, hikariReady, 120);
      result.firstFrameMs = Date.now() - started;
      result.adapter = await page.evaluate(() => window.hikari.adapter());
      await until(page, (n) => window.hikari.framesInMean() >= n, 300, frames);
      result.frames = await page.evaluate(() => window.hikari.framesInMean());
      result.tracer = await page.evaluate(() => window.hikari.tracer());
      // The status line ("drawing the first image…") is gone once it is drawn.
      result.status = await page.evaluate(() => {
        const s = document.getElementById("status");
        return s && getComputedStyle(s).display !== "none" ? s.textContent : "";
      });
      await writeMean(`web-${frames}.f32`, await readMean(page));
      result.error = await page.evaluate(() => window.hikari.lastError());
      // Where the frames went, and (through a 2D canvas) how many of its
      // pixels are lit: what the user sees, not only the mean.
      result.presentation = await page.evaluate(() => window.hikari.presentation());
      result.copyLit = await page.evaluate(() => {
        const copy = document.getElementById("hikari-copy");
        if (!copy) return null;
        const { data } = copy.getContext("2d").getImageData(0, 0, copy.width, copy.height);
        let lit = 0;
        for (let i = 0; i < data.length; i += 4) lit += Math.max(data[i], data[i + 1], data[i + 2]) > 40 ? 1 : 0;
        return lit / (data.length / 4);
      });
    } else if (scenario === "drop") {
      // A .glb dropped on the page renders; a broken one shows its error
      // and leaves the scene as it was.
      const { page } = await open(browser, "?photons=3000&panel=0", { log });
      await until(page, hikariReady, 120);
      const drop = async (name, bytes) => {
        const transfer = await page.evaluateHandle(
          ({ name, bytes }) => {
            const t = new DataTransfer();
            t.items.add(new File([new Uint8Array(bytes)], name));
            return t;
          },
          { name, bytes: Array.from(bytes) },
        );
        await page.dispatchEvent("body", "drop", { dataTransfer: transfer });
      };
      const glb = await readFile(process.env.HIKARI_GLB);
      await drop("fixture.glb", glb);
      await until(page, () => window.hikari.sceneName() === "fixture.glb" && window.hikari.framesInMean() > 2, 120);
      result.afterGood = await page.evaluate(() => [window.hikari.sceneName(), window.hikari.lastError()]);
      await writeMean("web-dropped.f32", await readMean(page));
      await drop("broken.glb", glb.subarray(0, Math.floor(glb.length / 2)));
      await until(page, () => window.hikari.lastError() !== "", 60);
      const framesBefore = await page.evaluate(() => window.hikari.framesInMean());
      await page.waitForTimeout(500);
      result.afterBroken = await page.evaluate(() => [
        window.hikari.sceneName(),
        window.hikari.lastError(),
        document.getElementById("error").textContent,
        getComputedStyle(document.getElementById("error")).display,
      ]);
      result.framesGoOn = (await page.evaluate(() => window.hikari.framesInMean())) >= framesBefore;
      // A .gltf dropped with its buffer and texture (three files at once).
      const dir = process.env.HIKARI_GLTF_DIR;
      const transfer = await page.evaluateHandle(() => new DataTransfer());
      for (const name of ["checker.gltf", "checker.bin", "checker texture.png"]) {
        const bytes = Array.from(await readFile(join(dir, name)));
        await page.evaluate(({ t, name, bytes }) => t.items.add(new File([new Uint8Array(bytes)], name)), { t: transfer, name, bytes });
      }
      await page.dispatchEvent("body", "drop", { dataTransfer: transfer });
      await until(page, () => window.hikari.sceneName() === "checker.gltf" && window.hikari.framesInMean() > 1, 120);
      result.afterGltf = await page.evaluate(() => [window.hikari.sceneName(), window.hikari.lastError()]);
    } else if (scenario === "controls") {
      // A mouse drag moves the view (the mean starts over, the image
      // changes), the panel's checkbox switches a term off, and the save
      // button downloads a PNG.
      const { page } = await open(browser, "?photons=3000", { width: 640, height: 480, log });
      await until(page, hikariReady, 120);
      await until(page, () => window.hikari.framesInMean() >= 4, 120);
      // The panel's per-pass times and noise estimate.
      await until(page, () => window.hikari.noise() > 0, 60);
      result.noise = await page.evaluate(() => window.hikari.noise());
      result.passTimes = JSON.parse(await page.evaluate(() => window.hikari.passTimes()));
      const before = await readMean(page);
      const framesBefore = await page.evaluate(() => window.hikari.framesInMean());
      // Drag on the right half, away from the panel.
      await page.mouse.move(560, 240);
      await page.mouse.down();
      await page.mouse.move(600, 250, { steps: 4 });
      await page.mouse.up();
      // The mean starts over once the frame in flight is done.
      await until(page, (n) => window.hikari.framesInMean() >= 1 && window.hikari.framesInMean() < n, 60, framesBefore);
      result.framesAfterDrag = await page.evaluate(() => window.hikari.framesInMean());
      const after = await readMean(page);
      let diff = 0;
      for (let i = 0; i < before.rgba.length; i++) diff += Math.abs(before.rgba[i] - after.rgba[i]);
      result.dragChange = diff / before.rgba.length;
      result.termsBefore = await page.evaluate(() => window.hikari.terms());
      // Where a widget is once the panel's layout has settled (lines such
      // as the noise estimate and the pass times appear after a few
      // frames and push what is below them down).
      const settledRect = async (name) => {
        let last = await page.evaluate((n) => window.hikari.widgetRect(n), name);
        for (let i = 0; i < 10; i++) {
          const frames = await page.evaluate(() => window.hikari.framesInMean());
          await until(page, (f) => window.hikari.framesInMean() !== f, 60, frames);
          const now = await page.evaluate((n) => window.hikari.widgetRect(n), name);
          if (JSON.stringify(now) === JSON.stringify(last)) return now;
          last = now;
        }
        return last;
      };
      // The panel's lines can still move between the frame that gave the
      // rect and the one that handles the click (a readout appearing
      // above), and a click that lands beside the box changes nothing.
      // A click that lands switches the term off by the next frame; if two
      // frames went by with the term still on, the box is found again and
      // clicked again (three tries). Frames are slow here (seconds each,
      // more with the other browser tests running), so no fixed wait.
      for (let attempt = 1; ; attempt++) {
        const box = await settledRect("indirect");
        result.checkbox = box;
        await page.mouse.click(box[0] + 6, (box[1] + box[3]) / 2);
        const off = () => !window.hikari.terms().includes("indirect");
        for (let frame = 0; frame < 2 && !(await page.evaluate(off)); frame++) {
          const frames = await page.evaluate(() => window.hikari.framesInMean());
          await until(page, (f) => !window.hikari.terms().includes("indirect") || window.hikari.framesInMean() !== f,
            120, frames);
        }
        if (await page.evaluate(off)) break;
        if (attempt === 3) throw new Error(`three clicks on "indirect" left it on (${await page.evaluate(() => window.hikari.terms())})`);
        log.push({ type: "log", text: `driver: the click on "indirect" missed (attempt ${attempt})` });
      }
      result.termsAfter = await page.evaluate(() => window.hikari.terms());
      const save = await settledRect("save PNG");
      const [download] = await Promise.all([
        page.waitForEvent("download", { timeout: 60000 }),
        page.mouse.click((save[0] + save[2]) / 2, (save[1] + save[3]) / 2),
      ]);
      result.download = download.suggestedFilename();
      await download.saveAs(join(out, "saved.png"));
      await page.waitForTimeout(300);
    } else if (scenario === "phone") {
      // A phone-sized window (390×844 CSS pixels, 2 device pixels each,
      // touch): the canvas fills it, the panel starts folded to its title,
      // and a tap on the title opens it.
      const { page } = await open(browser, "?photons=3000", { width: 390, height: 844, log, phone: true });
      await until(page, hikariReady, 180);
      result.canvas = await page.evaluate(() => {
        const c = document.getElementById("hikari-canvas");
        return [c.clientWidth, c.clientHeight, c.width, c.height];
      });
      result.folded = await page.evaluate(() => [window.hikari.widgetRect("panel"), window.hikari.widgetRect("save PNG")]);
      const title = result.folded[0];
      // The fold arrow at the title's left.
      await page.touchscreen.tap(title[0] + 14, (title[1] + title[3]) / 2);
      await until(page, () => window.hikari.widgetRect("save PNG").length === 4, 120);
      // egui unfolds the panel over a few frames: its contents exist before
      // it reaches its full height. Wait for that height (the test asserts
      // it); a panel that never grows is still recorded and fails there.
      const tall = () => {
        const r = window.hikari.widgetRect("panel");
        return r.length === 4 && r[3] - r[1] > 200;
      };
      await until(page, tall, 30).catch(() => {});
      result.opened = await page.evaluate(() => window.hikari.widgetRect("panel"));
      result.error = await page.evaluate(() => window.hikari.lastError());
    } else {
      throw new Error(`unknown scenario ${scenario}`);
    }
  }
} catch (e) {
  result.failure = String(e && e.stack ? e.stack : e);
} finally {
  result.console = log;
  await writeFile(join(out, "result.json"), JSON.stringify(result, null, 1));
  if (browser) await browser.close();
  server.close();
}
