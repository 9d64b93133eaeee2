// A client subscribed to every channel rsg_view advertises that, with --pause-ms, reads slowly: it
// leaves its socket unread for PAUSE ms, then reads for READ ms, over and over, so that rsg_view's
// queues for it overflow on the big channels. Without --pause-ms it reads everything at once (the
// reference). Either way it counts what arrives per channel; once the file STOP exists it reads
// freely, waits until the RobotState channels are quiet and the drop report (if any) is final,
// then prints {"received": {"topic (schema)": n, ...}, "drop_report": text or null}.
//
//   node fair_client.mjs ws://HOST:PORT --stop FILE [--pause-ms PAUSE --read-ms READ]
import { existsSync } from "node:fs";
import WebSocket from "ws";
import { checks, commandLine } from "../../node_common/checks.mjs";

const { fail, check } = checks("fair_client");
const { args, option } = commandLine();
const stopFile = option("--stop");
const pauseMs = Number(option("--pause-ms") ?? 0);
const readMs = Number(option("--read-ms") ?? 100);
setTimeout(() => fail("not finished within 120 s"), 120_000);

const ws = new WebSocket(args[0], ["foxglove.sdk.v1"]);
ws.binaryType = "nodebuffer";
const names = new Map();  // subscription id (= channel id) -> "topic (schema)"
const received = {};
let dropReport = null;
let lastState = Date.now();
let lastDropReport = 0;

ws.on("message", (data, isBinary) => {
  if (isBinary) {
    check(data[0] === 0x01, `binary opcode ${data[0]}`);
    const name = names.get(data.readUInt32LE(1));
    check(name, `a message for subscription ${data.readUInt32LE(1)}, which is not ours`);
    received[name] = (received[name] ?? 0) + 1;
    if (name.includes("RobotState")) lastState = Date.now();
    return;
  }
  const message = JSON.parse(data.toString());
  if (message.op === "advertise") {
    for (const channel of message.channels) {
      const name = `${channel.topic} (${channel.schemaName})`;
      names.set(channel.id, name);
      received[name] = 0;
    }
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: message.channels.map((c) => ({ id: c.id, channelId: c.id })) }));
    // The subscriptions are in once the server answers a later request: an unsupported op does.
    ws.send(JSON.stringify({ op: "getParameters", parameterNames: [] }));
  } else if (message.op === "status" && message.message.includes("getParameters")) {
    console.log("ready");
    if (pauseMs > 0) stall();
    waitForStop();
  } else if (message.op === "status" && message.id === "rsg_view.dropped") {
    dropReport = message.message;
    lastDropReport = Date.now();
  } else if (message.op === "status" && message.level === 2) {
    fail(`error status: ${message.message}`);
  }
});
ws.on("error", (error) => fail(error.message));

let stopping = false;
function stall() {
  if (stopping) return;
  ws._socket.pause();  // the kernel's buffers fill, then rsg_view's queues for this client
  setTimeout(() => {
    ws._socket.resume();
    setTimeout(stall, readMs);
  }, pauseMs);
}

function waitForStop() {
  if (!existsSync(stopFile)) return setTimeout(waitForStop, 100);
  stopping = true;
  ws._socket.resume();
  lastState = Date.now();  // a paused client saw none for a while: count the quiet from now
  // rsg_view reports drops once a second: quiet for 2.5 s covers the last report.
  const quiet = () => {
    const now = Date.now();
    if (now - lastState < 2500 || (dropReport !== null && now - lastDropReport < 1500)) return setTimeout(quiet, 100);
    console.log(JSON.stringify({ received, drop_report: dropReport }));
    ws.close();
    process.exit(0);
  };
  quiet();
}
