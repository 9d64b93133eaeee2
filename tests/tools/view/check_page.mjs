// Drives Debian's headless Chromium over the DevTools protocol: opens rsg_view's page, waits until
// the page shows live data (its sample counter grows, the last q is shown, Chart.js has points,
// the gateway panel says the link is up), saves a screenshot, and prints what the page showed.
//
//   node check_page.mjs DEVTOOLS_PORT http://HOST:PORT/ SCREENSHOT.png
import { writeFileSync } from "node:fs";
import WebSocket from "ws";
import { checks } from "../../node_common/checks.mjs";

const [devtoolsPort, pageUrl, screenshotPath] = process.argv.slice(2);
const { fail } = checks("check_page");
const deadline = Date.now() + 45_000;
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// Chromium opens its DevTools port a moment after start.
let target;
while (!target) {
  if (Date.now() > deadline) fail("Chromium's DevTools port never answered");
  try {
    const response = await fetch(`http://127.0.0.1:${devtoolsPort}/json/new?${pageUrl}`, { method: "PUT" });
    if (response.ok) target = await response.json();
  } catch {
    await sleep(200);
  }
}

const ws = new WebSocket(target.webSocketDebuggerUrl);
await new Promise((resolve, reject) => { ws.on("open", resolve); ws.on("error", reject); });
let nextId = 1;
const pending = new Map();
ws.on("message", (data) => {
  const message = JSON.parse(data.toString());
  if (message.id && pending.has(message.id)) {
    pending.get(message.id)(message);
    pending.delete(message.id);
  }
});
const send = (method, params = {}) => new Promise((resolve) => {
  const id = nextId++;
  pending.set(id, resolve);
  ws.send(JSON.stringify({ id, method, params }));
});
const evaluate = async (expression) => {
  const reply = await send("Runtime.evaluate", { expression, returnByValue: true });
  if (reply.result?.exceptionDetails) fail(`page script failed: ${JSON.stringify(reply.result.exceptionDetails)}`);
  return reply.result?.result?.value;
};

await send("Page.bringToFront");  // a background tab would not repaint for the screenshot
await send("Emulation.setDeviceMetricsOverride", { width: 1400, height: 1050, deviceScaleFactor: 1, mobile: false });
const read = () => evaluate(`JSON.stringify({
  connection: document.getElementById("connection")?.textContent,
  samples: Number(document.getElementById("samples")?.textContent),
  last_q: document.getElementById("last-q")?.textContent,
  mode: document.getElementById("robot-mode")?.textContent,
  link: document.getElementById("link")?.textContent,
  rate: document.getElementById("rate")?.textContent,
  published: document.getElementById("published")?.textContent,
  dropped: document.getElementById("dropped")?.textContent,
  chart_js: typeof Chart !== "undefined",
  q_points: typeof Chart !== "undefined" && Chart.getChart("plot-q") ? Chart.getChart("plot-q").data.labels.length : 0,
})`);

let shown, first;
for (;;) {
  if (Date.now() > deadline) fail(`the page never showed live data: ${JSON.stringify(shown)}`);
  const text = await read();
  shown = text ? JSON.parse(text) : undefined;
  if (shown && shown.samples > 0 && !first) first = shown;
  if (shown && first && shown.samples > first.samples && shown.last_q !== "–" && shown.q_points >= 50 &&
      shown.link === "up" && shown.connection === "open")
    break;
  await sleep(250);
}
const png = await send("Page.captureScreenshot", { format: "png" });
writeFileSync(screenshotPath, Buffer.from(png.result.data, "base64"));
console.log(JSON.stringify({ first_samples: first.samples, ...shown }));
ws.close();
process.exit(0);
