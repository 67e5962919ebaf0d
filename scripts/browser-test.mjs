// The HTML reports of verne in a real browser: scripts/browser-test.sh writes the reports and
// the cases file, then runs `node browser-test.mjs CASES.json`. Debian's Chromium, headless,
// driven over the DevTools protocol on a pipe (--remote-debugging-pipe): node's own modules
// only, no package to install.
//
// For every page: no console error, no uncaught exception, no failed load; no request but the
// page itself (every other one is failed by the test and counted); the page's script finishes
// (body[data-ready]); each canvas asked for is not blank in a screenshot (pixels other than its
// background, in colour). A report's case may also ask: its verdict text; a finding, clicked
// with the mouse, moves the 3D view to its row and changes its pixels; the drawn machine is the
// kinematics' (rod lengths equal the machine file's, the tool tip drawn from the platform is
// the joints' tip carried by the table); the time the page took to draw.
import { spawn } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { inflateSync } from "node:zlib";

const cases = JSON.parse(readFileSync(process.argv[2], "utf8"));
const failures = [];
let passed = 0;
function check(name, ok, detail) {
  if (ok) {
    passed++;
    console.log(`ok    ${name}`);
  } else {
    failures.push(`${name}: ${detail}`);
    console.log(`FAIL  ${name}: ${detail}`);
  }
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ---- Chromium on a pipe: requests on fd 3, answers and events on fd 4, NUL-terminated JSON.
const profile = mkdtempSync(join(tmpdir(), "verne-chromium-"));
const chromium = spawn(
  process.env.CHROMIUM || "/usr/bin/chromium",
  [
    "--headless",
    "--remote-debugging-pipe",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--hide-scrollbars",
    "--mute-audio",
    `--user-data-dir=${profile}`,
    "about:blank",
  ],
  { stdio: ["ignore", "ignore", "pipe", "pipe", "pipe"] }
);
let chromiumLog = "";
chromium.stderr.on("data", (d) => {
  chromiumLog = (chromiumLog + d).slice(-4000);
});
const toChromium = chromium.stdio[3];
const fromChromium = chromium.stdio[4];
let nextId = 1;
const pending = new Map();
const listeners = [];
let buffered = "";
fromChromium.on("data", (chunk) => {
  buffered += chunk.toString("utf8");
  let end;
  while ((end = buffered.indexOf("\0")) >= 0) {
    const msg = JSON.parse(buffered.slice(0, end));
    buffered = buffered.slice(end + 1);
    if (msg.id !== undefined && pending.has(msg.id)) {
      const { resolve, reject, method } = pending.get(msg.id);
      pending.delete(msg.id);
      if (msg.error) reject(new Error(`${method}: ${msg.error.message}`));
      else resolve(msg.result);
    } else if (msg.method) {
      for (const l of listeners) l(msg);
    }
  }
});
chromium.on("exit", (code, signal) => {
  for (const { reject, method } of pending.values()) {
    reject(new Error(`${method}: chromium exited (${code ?? signal}): ${chromiumLog}`));
  }
  pending.clear();
});
function send(method, params = {}, sessionId, timeoutMs = 30000) {
  const id = nextId++;
  const msg = { id, method, params };
  if (sessionId) msg.sessionId = sessionId;
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      pending.delete(id);
      reject(new Error(`${method}: no answer in ${timeoutMs} ms`));
    }, timeoutMs);
    pending.set(id, {
      method,
      resolve: (r) => (clearTimeout(timer), resolve(r)),
      reject: (e) => (clearTimeout(timer), reject(e)),
    });
    toChromium.write(JSON.stringify(msg) + "\0");
  });
}

// ---- A tab of its own browser context, its requests intercepted, its errors collected.
async function openTab(allowedUrl) {
  const { browserContextId } = await send("Target.createBrowserContext");
  const { targetId } = await send("Target.createTarget", { url: "about:blank", browserContextId });
  const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
  const tab = { browserContextId, sessionId, errors: [], requests: [] };
  const s = (method, params, timeoutMs) => send(method, params, sessionId, timeoutMs);
  tab.send = s;
  listeners.push((m) => {
    if (m.sessionId !== sessionId) return;
    const p = m.params;
    if (m.method === "Fetch.requestPaused") {
      if (p.request.url === allowedUrl) {
        s("Fetch.continueRequest", { requestId: p.requestId }).catch(() => {});
      } else {
        tab.requests.push(p.request.url);
        s("Fetch.failRequest", { requestId: p.requestId, errorReason: "BlockedByClient" }).catch(() => {});
      }
    } else if (m.method === "Network.requestWillBeSent") {
      const u = p.request.url;
      if (u !== allowedUrl && !tab.requests.includes(u)) tab.requests.push(u);
    } else if (m.method === "Runtime.consoleAPICalled" && (p.type === "error" || p.type === "assert")) {
      tab.errors.push(p.args.map((a) => a.value ?? a.description ?? "").join(" "));
    } else if (m.method === "Runtime.exceptionThrown") {
      const d = p.exceptionDetails;
      tab.errors.push(`${d.text} ${d.exception?.description ?? ""}`.trim());
    } else if (m.method === "Log.entryAdded" && p.entry.level === "error") {
      tab.errors.push(`${p.entry.source}: ${p.entry.text}`);
    }
  });
  await s("Page.enable");
  await s("Runtime.enable");
  await s("Log.enable");
  await s("Network.enable");
  await s("Fetch.enable", { patterns: [{ urlPattern: "*" }] });
  await viewport(tab, 1400, 1000);
  return tab;
}
async function viewport(tab, width, height) {
  await tab.send("Emulation.setDeviceMetricsOverride", {
    width,
    height,
    deviceScaleFactor: 1,
    mobile: false,
  });
}
async function evaluate(tab, expression) {
  const r = await tab.send("Runtime.evaluate", {
    expression,
    returnByValue: true,
    awaitPromise: true,
  });
  if (r.exceptionDetails) {
    throw new Error(`evaluate: ${r.exceptionDetails.exception?.description ?? r.exceptionDetails.text}`);
  }
  return r.result.value;
}
// An element scrolled into the middle of the view: its box in the page and in the view.
async function box(tab, selectorExpr) {
  return evaluate(
    tab,
    `(async () => {
      const e = ${selectorExpr};
      if (!e) return null;
      e.scrollIntoView({ block: "center", inline: "nearest" });
      await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
      const b = e.getBoundingClientRect();
      return { x: b.left + scrollX, y: b.top + scrollY, vx: b.left, vy: b.top, width: b.width, height: b.height };
    })()`
  );
}
async function screenshot(tab, clip) {
  const params = { format: "png" };
  if (clip) params.clip = { x: clip.x, y: clip.y, width: clip.width, height: clip.height, scale: 1 };
  const { data } = await tab.send("Page.captureScreenshot", params);
  return Buffer.from(data, "base64");
}
// A real click: the mouse pressed and released at the middle of the element.
async function click(tab, selectorExpr) {
  const b = await box(tab, selectorExpr);
  if (!b) return false;
  const x = b.vx + b.width / 2;
  const y = b.vy + b.height / 2;
  await tab.send("Input.dispatchMouseEvent", { type: "mouseMoved", x, y });
  await tab.send("Input.dispatchMouseEvent", { type: "mousePressed", x, y, button: "left", clickCount: 1 });
  await tab.send("Input.dispatchMouseEvent", { type: "mouseReleased", x, y, button: "left", clickCount: 1 });
  await evaluate(tab, "new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))");
  return true;
}

// ---- PNG (8-bit greyscale, RGB or RGBA, not interlaced, as Chromium writes): its pixels.
function decodePng(png) {
  let pos = 8;
  let width = 0, height = 0, type = 0;
  const idat = [];
  while (pos < png.length) {
    const len = png.readUInt32BE(pos);
    const kind = png.toString("latin1", pos + 4, pos + 8);
    const body = png.subarray(pos + 8, pos + 8 + len);
    if (kind === "IHDR") {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      type = body[9];
      if (body[8] !== 8 || body[12] !== 0 || ![0, 2, 6].includes(type)) {
        throw new Error(`PNG depth ${body[8]}, colour type ${type}, interlace ${body[12]}`);
      }
    } else if (kind === "IDAT") {
      idat.push(body);
    }
    pos += 12 + len;
  }
  const channels = { 0: 1, 2: 3, 6: 4 }[type];
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(width * height * 3);
  const line = Buffer.alloc(stride);
  const prev = Buffer.alloc(stride);
  for (let y = 0; y < height; y++) {
    const f = raw[y * (stride + 1)];
    const src = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? line[i - channels] : 0;
      const b = prev[i];
      const c = i >= channels ? prev[i - channels] : 0;
      let p = 0;
      if (f === 1) p = a;
      else if (f === 2) p = b;
      else if (f === 3) p = (a + b) >> 1;
      else if (f === 4) {
        const q = a + b - c;
        const pa = Math.abs(q - a), pb = Math.abs(q - b), pc = Math.abs(q - c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      line[i] = (src[i] + p) & 255;
    }
    for (let x = 0; x < width; x++) {
      for (let k = 0; k < 3; k++) {
        out[3 * (y * width + x) + k] = line[x * channels + (channels === 1 ? 0 : k)];
      }
    }
    line.copy(prev);
  }
  return { width, height, rgb: out };
}
// Pixels that differ from the background, pixels in colour, and colours (4 bits a channel).
function pixels(png, bg) {
  const { width, height, rgb } = decodePng(png);
  let drawn = 0, colored = 0;
  const colors = new Set();
  for (let i = 0; i < rgb.length; i += 3) {
    const [r, g, b] = [rgb[i], rgb[i + 1], rgb[i + 2]];
    if (Math.abs(r - bg[0]) + Math.abs(g - bg[1]) + Math.abs(b - bg[2]) > 24) drawn++;
    if (Math.max(r, g, b) - Math.min(r, g, b) > 60) colored++;
    colors.add((r >> 4) * 256 + (g >> 4) * 16 + (b >> 4));
  }
  return { total: width * height, drawn, colored, colors: colors.size };
}

const q = (s) => JSON.stringify(s);
async function runCase(c) {
  const url = pathToFileURL(c.file).href;
  const tab = await openTab(url);
  const t0 = Date.now();
  const nav = await tab.send("Page.navigate", { url });
  check(`${c.name}: loads`, !nav.errorText, nav.errorText);
  let ready = false;
  while (!ready && Date.now() - t0 < 20000) {
    ready = await evaluate(tab, "document.body?.dataset.ready === '1'");
    if (!ready) await sleep(25);
  }
  check(`${c.name}: the page's script finishes`, ready, "body[data-ready] not set in 20 s");
  const drawMs = Number(await evaluate(tab, "document.body?.dataset.drawMs"));
  console.log(`--    ${c.name}: ${c.file} drawn ${drawMs} ms after navigation (wait ${Date.now() - t0} ms)`);
  const text = (sel) => evaluate(tab, `document.querySelector(${q(sel)})?.textContent ?? ""`);
  for (const sel of c.canvases || []) {
    const n = await evaluate(tab, `document.querySelectorAll(${q(sel)}).length`);
    check(`${c.name}: ${sel} present`, n > 0, "no such element");
    for (let k = 0; k < n; k++) {
      const b = await box(tab, `document.querySelectorAll(${q(sel)})[${k}]`);
      const bg = sel === "#view3d" || sel.includes("branch") ? [251, 252, 253] : [255, 255, 255];
      const p = pixels(await screenshot(tab, b), bg);
      const share = p.drawn / p.total;
      check(
        `${c.name}: ${sel} #${k} not blank`,
        share > (c.minDrawn || 0.01) && p.colored > 50 && p.colors > 4,
        `drawn ${(100 * share).toFixed(2)}% of ${p.total} px, ${p.colored} coloured, ${p.colors} colours`
      );
    }
  }
  if (c.verdict) {
    const v = await text("#verdict");
    check(`${c.name}: verdict`, v.includes(c.verdict), `"${v}" lacks "${c.verdict}"`);
  }
  for (const t of c.texts || []) {
    const body = await text("body");
    check(`${c.name}: says "${t}"`, body.includes(t), "not in the page");
  }
  if (c.findings !== undefined) {
    const n = await evaluate(tab, "document.querySelectorAll('#findings tbody tr').length");
    check(`${c.name}: ${c.findings} findings listed`, n === c.findings, `${n} listed`);
  }
  if (c.click) {
    // A finding of the given check at the given row, clicked, moves the 3D view there.
    const rows = q(`#findings tbody tr[data-check=${q(c.click.check)}]`);
    const row = `[...document.querySelectorAll(${rows})]
      .find((tr) => tr.firstElementChild?.textContent === ${q(c.click.row)})`;
    const listed = await evaluate(tab, `!!(${row})`);
    check(`${c.name}: finding ${c.click.check} at row ${c.click.row} listed`, listed, "not listed");
    if (listed) {
      // Start elsewhere: the first row.
      await evaluate(tab, "window.verneReport.go(0)");
      const view = await box(tab, "document.getElementById('view3d')");
      const before = await screenshot(tab, view);
      await click(tab, `(${row}).firstElementChild`);
      const shown = await evaluate(tab, "document.body.dataset.row");
      const frame = await evaluate(tab, "document.body.dataset.frame");
      const wanted = await evaluate(tab, `(${row}).dataset.frame`);
      check(
        `${c.name}: clicking the finding shows row ${c.click.row} in 3D`,
        shown === c.click.row && frame === wanted && wanted !== "0",
        `row ${shown}, frame ${frame} (the finding's frame ${wanted})`
      );
      const after = await screenshot(tab, await box(tab, "document.getElementById('view3d')"));
      check(`${c.name}: the 3D view moved`, !before.equals(after), "the same pixels");
      const info = await text("#rowinfo");
      check(
        `${c.name}: the row's panel names its line`,
        info.includes(`row ${c.click.row}`) && info.includes("joint program line"),
        info
      );
    }
  }
  if (c.closeUp) {
    // The close-up follows the tool: another picture, not blank.
    const view = await box(tab, "document.getElementById('view3d')");
    const whole = await screenshot(tab, view);
    await click(tab, "document.getElementById('closeup')");
    const checked = await evaluate(tab, "document.getElementById('closeup').checked");
    const close = await screenshot(tab, await box(tab, "document.getElementById('view3d')"));
    const p = pixels(close, [251, 252, 253]);
    check(
      `${c.name}: the close-up is drawn and differs from the whole machine`,
      checked && !whole.equals(close) && p.drawn / p.total > 0.01 && p.colored > 50,
      `checked ${checked}, drawn ${p.drawn} of ${p.total} px, ${p.colored} coloured`
    );
    await click(tab, "document.getElementById('closeup')");
  }
  if (c.geometry) {
    // The machine drawn is the machine of the kinematics, at every frame sampled.
    const g = await evaluate(
      tab,
      `(() => {
        const R = window.verneReport;
        const D = JSON.parse(document.getElementById("verne-data").textContent);
        const M = D.machine;
        const L = [M.L1, M.L1, M.L2, M.L3];
        let rod = 0, tip = 0, n = 0;
        const step = Math.max(1, Math.floor(R.frames / 200));
        for (let i = 0; i < R.frames; i += step) {
          const s = R.state(i);
          if (!isFinite(s.P[0])) continue;
          const md = VerneView.module(M, s.rho, s.P, s.alpha);
          for (let k = 0; k < 4; k++) {
            const d = Math.hypot(md.B[k][0] - md.A[k][0], md.B[k][1] - md.A[k][1], md.B[k][2] - md.A[k][2]);
            rod = Math.max(rod, Math.abs(d - L[k]));
          }
          const fk = [s.actual[3 * i], s.actual[3 * i + 1], s.actual[3 * i + 2]];
          const t = VerneView.table(M, s.theta1, s.theta2).apply(fk);
          tip = Math.max(tip, Math.hypot(t[0] - md.tip[0], t[1] - md.tip[1], t[2] - md.tip[2]));
          n++;
        }
        return { rod, tip, n };
      })()`
    );
    check(
      `${c.name}: the drawn rods have the machine file's lengths`,
      g.n > 0 && g.rod < 0.05,
      `${g.n} frames, worst |rod - L| ${g.rod} mm`
    );
    check(
      `${c.name}: the drawn tool tip is the joints' tip on the drawn table`,
      g.n > 0 && g.tip < 0.05,
      `${g.n} frames, worst ${g.tip} mm`
    );
  }
  if (c.maxDrawMs) {
    check(`${c.name}: drawn within ${c.maxDrawMs} ms`, drawMs > 0 && drawMs < c.maxDrawMs, `${drawMs} ms`);
  }
  if (c.screenshot) {
    await viewport(tab, 1400, 1500);
    await evaluate(tab, "window.scrollTo(0, 0)");
    await evaluate(tab, "new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))");
    writeFileSync(c.screenshot, await screenshot(tab));
    console.log(`--    ${c.name}: screenshot ${c.screenshot}`);
  }
  // Late messages (a failed load is logged after the event that caused it).
  await sleep(100);
  check(`${c.name}: no console error`, tab.errors.length === 0, tab.errors.join(" | "));
  check(`${c.name}: no request`, tab.requests.length === 0, tab.requests.join(" "));
  await send("Target.disposeBrowserContext", { browserContextId: tab.browserContextId });
}

let code = 1;
try {
  // The checks can fail: a page that fetches, logs an error and throws is caught.
  const bad = join(profile, "bad.html");
  writeFileSync(
    bad,
    `<!DOCTYPE html><html><head><meta charset="utf-8"><title>bad</title></head><body>
     <img src="http://192.0.2.1/x.png"><script>console.error("logged"); fetch("https://example.invalid/");
     document.body.dataset.ready = "1"; null.x;</script></body></html>`
  );
  const selfTest = await openTab(pathToFileURL(bad).href);
  await selfTest.send("Page.navigate", { url: pathToFileURL(bad).href });
  await sleep(500);
  const caught = selfTest.errors.length >= 2 && selfTest.requests.length >= 2;
  console.log(`--    self-test: ${selfTest.errors.length} errors, ${selfTest.requests.length} requests caught`);
  await send("Target.disposeBrowserContext", { browserContextId: selfTest.browserContextId });
  check("the test catches a console error, an exception and requests", caught,
    `${selfTest.errors.join(" | ")} / ${selfTest.requests.join(" ")}`);
  const blank = pixels(
    await (async () => {
      const t = await openTab("about:blank");
      const p = await screenshot(t, { x: 0, y: 0, width: 200, height: 100 });
      await send("Target.disposeBrowserContext", { browserContextId: t.browserContextId });
      return p;
    })(),
    [255, 255, 255]
  );
  check("a blank page is seen blank", blank.drawn === 0 && blank.total === 20000, JSON.stringify(blank));
  for (const c of cases) {
    await runCase(c);
  }
  code = failures.length ? 1 : 0;
} catch (e) {
  console.log(`FAIL  ${e.stack || e}`);
  failures.push(String(e));
} finally {
  console.log(`browser-test: ${passed} passed, ${failures.length} failed`);
  await send("Browser.close", {}, undefined, 5000).catch(() => chromium.kill());
  await sleep(200);
  if (chromium.exitCode === null) chromium.kill("SIGKILL");
  rmSync(profile, { recursive: true, force: true });
}
process.exit(code);
