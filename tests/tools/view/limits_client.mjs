// rsg_view's limits, seen from clients: with --max-clients 1 a second client is refused; a burst
// of requests past the per-second limit gets one error status; a text message over 64 KiB closes
// that connection; HTTP answers 404 for unknown paths and 405 for other methods than GET.
//
//   node limits_client.mjs HOST:PORT
import http from "node:http";
import WebSocket from "ws";
import { checks } from "../../node_common/checks.mjs";

const [hostPort] = process.argv.slice(2);
const { fail } = checks("limits_client");
setTimeout(() => fail("timed out"), 30_000);
const opened = (ws) => new Promise((resolve, reject) => {
  ws.once("open", resolve);
  ws.once("error", reject);
});
const closed = (ws) => new Promise((resolve) => ws.once("close", (code, reason) => resolve({ code, reason: reason.toString() })));
const result = {};

// HTTP first.
result.unknown_path = (await fetch(`http://${hostPort}/no/such/file`)).status;
result.post = (await fetch(`http://${hostPort}/`, { method: "POST", body: "x" })).status;
// A WebSocket upgrade offering no Foxglove subprotocol (fetch refuses upgrade headers: node:http).
result.no_subprotocol = await new Promise((resolve, reject) => {
  const [host, port] = hostPort.split(":");
  const request = http.get({ host, port, path: "/", headers: {
    Connection: "Upgrade", Upgrade: "websocket", "Sec-WebSocket-Version": "13", "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==" } });
  request.on("response", (response) => resolve(response.statusCode));
  request.on("upgrade", () => resolve(101));
  request.on("error", reject);
});

const first = new WebSocket(`ws://${hostPort}/`, ["foxglove.sdk.v1"]);
const statuses = [];
first.on("message", (data, isBinary) => {
  if (!isBinary) {
    const message = JSON.parse(data.toString());
    if (message.op === "status") statuses.push(message);
  }
});
await opened(first);
await new Promise((resolve) => setTimeout(resolve, 300));  // counted as a client once accepted

const second = new WebSocket(`ws://${hostPort}/`, ["foxglove.websocket.v1"]);
second.on("error", () => {});
result.second_client = await closed(second);

for (let i = 0; i < 150; i++) first.send(JSON.stringify({ op: "unsubscribe", subscriptionIds: [] }));
const deadline = Date.now() + 10_000;
while (!statuses.some((s) => s.message.includes("too many messages")) && Date.now() < deadline)
  await new Promise((resolve) => setTimeout(resolve, 50));
result.rate_errors = statuses.filter((s) => s.level === 2 && s.message.includes("too many messages")).length;

first.send("x".repeat(70 * 1024));
result.big_message = await closed(first);
console.log(JSON.stringify(result));
process.exit(0);
