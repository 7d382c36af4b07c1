// Shows a GIF in headless Chromium and takes screenshots at several real times after the page
// loads, to see that the browser plays it. Also asks Chromium's own decoder (WebCodecs
// ImageDecoder) how many frames, which durations and which loop count it reads.
//
// node check.mjs GIF OUT_DIR [TIMES_MS]   (TIMES_MS: comma-separated, default 100,400,700)
// Writes OUT_DIR/page.html, OUT_DIR/shot_<ms>ms.png per time, OUT_DIR/report.json.
// Exit 0 when every screenshot differs from the others (the GIF animates) and the decoder read
// more than one frame; 1 otherwise; 2 on a usage or browser error.
//
// Chromium is driven over the DevTools protocol on a pipe (--remote-debugging-pipe: commands on
// fd 3, replies on fd 4, each message a JSON text ended by a NUL byte), so no WebSocket library
// or network port is needed. `--virtual-time-budget` cannot do this: virtual time does not
// advance GIF animation, so every screenshot shows the first frame.

import { spawn } from "node:child_process";
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { basename, join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [gifArg, outArg, timesArg] = process.argv.slice(2);
if (!gifArg || !outArg) {
  console.error("usage: node check.mjs GIF OUT_DIR [TIMES_MS]");
  process.exit(2);
}
const times = (timesArg ?? "100,400,700").split(",").map(Number);
if (times.some((t) => !Number.isFinite(t) || t < 0)) {
  console.error(`bad times ${timesArg}: expected comma-separated milliseconds`);
  process.exit(2);
}
const out = resolve(outArg);
mkdirSync(out, { recursive: true });
const gifName = basename(gifArg);
copyFileSync(gifArg, join(out, gifName));
const gifBytes = readFileSync(gifArg);
// Logical screen size: bytes 6–9 of a GIF, little-endian.
const width = gifBytes.readUInt16LE(6);
const height = gifBytes.readUInt16LE(8);

// The GIF at its own size on a checkerboard, so transparent pixels show as such.
writeFileSync(
  join(out, "page.html"),
  `<!doctype html><html><head><style>
html, body { margin: 0; }
body { background: repeating-conic-gradient(#bbb 0 25%, #fff 0 50%) 0 0 / 16px 16px; }
img { display: block; }
</style></head><body><img id="gif" src="${gifName}" width="${width}" height="${height}"></body></html>`,
);

const chromium = process.env.CHROMIUM ?? "chromium";
const profile = mkdtempSync(join(tmpdir(), "sinew-browser-check-"));
const args = [
  "--headless",
  "--disable-gpu",
  "--hide-scrollbars",
  "--no-first-run",
  "--mute-audio",
  "--remote-debugging-pipe",
  `--user-data-dir=${profile}`,
  `--window-size=${width},${height}`,
  "about:blank",
];
// Chromium refuses to run as root with its sandbox on.
if (process.getuid?.() === 0) args.unshift("--no-sandbox");
const browser = spawn(chromium, args, { stdio: ["ignore", "ignore", "pipe", "pipe", "pipe"] });
let stderr = "";
browser.stderr.on("data", (d) => (stderr += d));
browser.on("error", (e) => fail(`cannot start ${chromium}: ${e.message}`));

const toBrowser = browser.stdio[3];
const fromBrowser = browser.stdio[4];
let nextId = 1;
const pending = new Map();
const listeners = [];
let buffered = Buffer.alloc(0);
fromBrowser.on("data", (chunk) => {
  buffered = Buffer.concat([buffered, chunk]);
  let end;
  while ((end = buffered.indexOf(0)) >= 0) {
    const message = JSON.parse(buffered.subarray(0, end).toString("utf8"));
    buffered = buffered.subarray(end + 1);
    if (message.id && pending.has(message.id)) {
      const { resolve, reject } = pending.get(message.id);
      pending.delete(message.id);
      message.error ? reject(new Error(JSON.stringify(message.error))) : resolve(message.result);
    } else if (message.method) {
      listeners.forEach((l) => l(message));
    }
  }
});

function send(method, params = {}, sessionId) {
  const id = nextId++;
  toBrowser.write(JSON.stringify({ id, method, params, sessionId }) + "\0");
  return new Promise((resolve, reject) => pending.set(id, { resolve, reject }));
}

function once(method, sessionId) {
  return new Promise((resolve) => {
    const listener = (m) => {
      if (m.method === method && m.sessionId === sessionId) {
        listeners.splice(listeners.indexOf(listener), 1);
        resolve(m.params);
      }
    };
    listeners.push(listener);
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

function fail(message) {
  console.error(message);
  if (stderr) console.error(stderr.split("\n").slice(-5).join("\n"));
  browser.kill();
  rmSync(profile, { recursive: true, force: true });
  process.exit(2);
}

const watchdog = setTimeout(() => fail("browser check timed out after 60 s"), 60_000);

try {
  const { targetInfos } = await send("Target.getTargets");
  const page = targetInfos.find((t) => t.type === "page");
  if (!page) fail("no page target in the browser");
  const { sessionId } = await send("Target.attachToTarget", { targetId: page.targetId, flatten: true });
  await send("Page.enable", {}, sessionId);
  // The window size flag does not fix the viewport in new headless mode; this does.
  await send(
    "Emulation.setDeviceMetricsOverride",
    { width, height, deviceScaleFactor: 1, mobile: false },
    sessionId,
  );
  const loaded = once("Page.loadEventFired", sessionId);
  await send("Page.navigate", { url: pathToFileURL(join(out, "page.html")).href }, sessionId);
  await loaded;
  const loadedAt = Date.now();

  const shots = [];
  for (const t of [...times].sort((a, b) => a - b)) {
    await sleep(Math.max(0, loadedAt + t - Date.now()));
    const takenMs = Date.now() - loadedAt;
    const { data } = await send("Page.captureScreenshot", { format: "png" }, sessionId);
    const file = join(out, `shot_${t}ms.png`);
    writeFileSync(file, Buffer.from(data, "base64"));
    shots.push({ requested_ms: t, taken_ms: takenMs, file, png: data });
  }

  // The browser's own GIF decoder: frame count, durations, loop count.
  const { result, exceptionDetails } = await send(
    "Runtime.evaluate",
    {
      awaitPromise: true,
      returnByValue: true,
      expression: `(async () => {
        if (typeof ImageDecoder === "undefined") return { available: false };
        // fetch() cannot read file:// pages' neighbours, so the bytes come inline.
        const data = Uint8Array.from(atob(${JSON.stringify(gifBytes.toString("base64"))}),
                                     (c) => c.charCodeAt(0));
        const decoder = new ImageDecoder({ data, type: "image/gif" });
        await decoder.tracks.ready;
        await decoder.completed;
        const track = decoder.tracks.selectedTrack;
        const durations_ms = [];
        for (let i = 0; i < track.frameCount; i++) {
          const { image } = await decoder.decode({ frameIndex: i });
          durations_ms.push(image.duration / 1000);
          image.close();
        }
        return { available: true, frame_count: track.frameCount,
                 // Infinity (loop forever) has no JSON form.
                 repetition_count: track.repetitionCount === Infinity ? "infinite"
                                                                      : track.repetitionCount,
                 durations_ms };
      })()`,
    },
    sessionId,
  );
  const decoded = exceptionDetails
    ? { available: false, error: exceptionDetails.exception?.description ?? exceptionDetails.text }
    : result.value;

  // Identical PNG bytes mean identical pixels (same encoder, same size); distinct bytes, a
  // different frame on screen.
  const distinct = new Set(shots.map((s) => s.png)).size;
  const animates = distinct === shots.length && shots.length > 1;
  const report = {
    gif: resolve(gifArg),
    size_px: [width, height],
    chromium: (await send("Browser.getVersion")).product,
    screenshots: shots.map(({ png, ...s }) => s),
    distinct_screenshots: distinct,
    animates,
    decoder: decoded,
  };
  writeFileSync(join(out, "report.json"), JSON.stringify(report, null, 2) + "\n");
  console.log(JSON.stringify(report, null, 2));
  clearTimeout(watchdog);
  const exited = new Promise((r) => browser.once("exit", r));
  await send("Browser.close").catch(() => {});
  await exited;
  rmSync(profile, { recursive: true, force: true });
  const ok = animates && (!decoded.available || decoded.frame_count > 1);
  console.log(ok ? "OK: the GIF plays in Chromium" : "FAIL: the GIF does not animate in Chromium");
  process.exit(ok ? 0 : 1);
} catch (e) {
  fail(`browser check failed: ${e.message}`);
}
