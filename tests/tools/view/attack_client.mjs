// An attacker on rsg_view's port, and the legitimate client it must not lock out (test_view.py,
// view.attack_*; docs/security.md, "What an attacker on the network can and cannot do"). Each mode
// stops by itself and prints one JSON line.
//
//   node attack_client.mjs legit ws://HOST:PORT COUNT TIMEOUT_MS
//       subscribes to the RobotState channels and waits for COUNT messages: {"ms": time to the
//       last of them}; fails after TIMEOUT_MS.
//   node attack_client.mjs subscribe ws://HOST:PORT MESSAGES PER HOLD_MS
//       sends MESSAGES subscribe requests of PER subscriptions each (every advertised channel in
//       turn, new ids), reads for HOLD_MS, leaves: {"errors": error statuses, "binary": messages}.
//   node attack_client.mjs idle ws://HOST:PORT CLIENTS FIRST_SOURCE HOLD_MS
//       opens CLIENTS WebSocket clients from FIRST_SOURCE, FIRST_SOURCE + 1, ... (127.x.y.z) that
//       subscribe to nothing (they answer pings, as any library does), holds them HOLD_MS:
//       {"opened": n, "closed_by_server": n}.
//   node attack_client.mjs chatty ws://HOST:PORT CLIENTS SOURCES FIRST_SOURCE HOLD_MS
//       opens CLIENTS WebSocket clients from SOURCES addresses FIRST_SOURCE, FIRST_SOURCE + 1, ...
//       (in turn) that subscribe to nothing and send a 40-byte message every 0.5 s, renewing each
//       one the server closes or refuses, for HOLD_MS: {"opened": n, "closed_by_server": n,
//       "refused": n (closed with 1013, "too many clients")}.
//   node attack_client.mjs late ws://HOST:PORT SOURCE DELAY_MS COUNT TIMEOUT_MS
//       a legitimate client from SOURCE that subscribes to the RobotState channels DELAY_MS after
//       the server advertised them (a person picking topics) and waits for COUNT messages; fails
//       when the server closes it first or after TIMEOUT_MS: {"ms": time to the last of them}.
//   node attack_client.mjs tcp HOST PORT CONNECTIONS SOURCES HOLD_MS
//       opens CONNECTIONS TCP connections from SOURCES addresses 127.0.1.1... that never send a
//       byte, renewing each one the server closes, for HOLD_MS: {"opened": n, "closed_by_server": n}.
import net from "node:net";
import WebSocket from "ws";
import { checks } from "../../node_common/checks.mjs";

const { fail } = checks("attack_client");
const [mode, ...args] = process.argv.slice(2);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const sourceAt = (first, i) => {
  const parts = first.split(".").map(Number);
  parts[3] += i;
  return parts.join(".");
};

async function legit(url, count, timeoutMs) {
  setTimeout(() => fail(`legit: fewer than ${count} messages within ${timeoutMs} ms`), timeoutMs);
  const start = Date.now();
  const ws = new WebSocket(url, ["foxglove.sdk.v1"]);
  let received = 0;
  ws.on("message", (data, isBinary) => {
    if (isBinary) {
      if (++received === count) {
        console.log(JSON.stringify({ ms: Date.now() - start }));
        process.exit(0);
      }
      return;
    }
    const message = JSON.parse(data.toString());
    if (message.op !== "advertise") return;
    // Every RobotState channel (IDL and ROS 2 flavours), as a plot panel would.
    const subscriptions = message.channels.filter((c) => c.schemaName.includes("RobotState"))
      .map((c) => ({ id: c.id, channelId: c.id }));
    if (subscriptions.length === 0) fail("no RobotState channel");
    ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
  });
  ws.on("close", (code, reason) => fail(`legit: closed by the server (${code} ${reason})`));
  ws.on("error", (error) => fail(`legit: ${error.message}`));
}

async function late(url, source, delayMs, count, timeoutMs) {
  setTimeout(() => fail(`late ${source}: fewer than ${count} messages within ${timeoutMs} ms`), timeoutMs);
  const start = Date.now();
  const ws = new WebSocket(url, ["foxglove.sdk.v1"], { localAddress: source });
  let received = 0;
  ws.on("message", (data, isBinary) => {
    if (isBinary) {
      if (++received === count) {
        console.log(JSON.stringify({ ms: Date.now() - start }));
        process.exit(0);
      }
      return;
    }
    const message = JSON.parse(data.toString());
    if (message.op !== "advertise") return;
    const subscriptions = message.channels.filter((c) => c.schemaName.includes("RobotState"))
      .map((c) => ({ id: c.id, channelId: c.id }));
    if (subscriptions.length === 0) fail("no RobotState channel");
    setTimeout(() => ws.send(JSON.stringify({ op: "subscribe", subscriptions })), delayMs);
  });
  ws.on("close", (code, reason) => fail(`late ${source}: closed by the server (${code} ${reason})`));
  ws.on("error", (error) => fail(`late ${source}: ${error.message}`));
}

async function chatty(url, clients, sources, firstSource, holdMs) {
  // 40 bytes, an operation rsg_view does not know: answered with an error status, otherwise ignored.
  const chatter = JSON.stringify({ op: "x", pad: "" });
  const message = JSON.stringify({ op: "x", pad: "p".repeat(40 - chatter.length) });
  if (message.length !== 40) fail(`chatter of ${message.length} bytes`);
  let opened = 0, closedByServer = 0, refused = 0, stopping = false;
  const open = (i) => {
    const ws = new WebSocket(url, ["foxglove.sdk.v1"], { localAddress: sourceAt(firstSource, i % sources) });
    let timer = null;
    ws.on("open", () => {
      opened++;
      timer = setInterval(() => ws.readyState === WebSocket.OPEN && ws.send(message), 500);
    });
    ws.on("close", (code) => {
      clearInterval(timer);
      if (stopping) return;
      if (code === 1013) refused++;
      else closedByServer++;
      setTimeout(() => open(i), 200);  // renewed as it closes
    });
    ws.on("error", () => {});
  };
  for (let i = 0; i < clients; i++) {
    open(i);
    await sleep(20);
  }
  await sleep(holdMs);
  stopping = true;
  console.log(JSON.stringify({ opened, closed_by_server: closedByServer, refused }));
  process.exit(0);
}

async function subscribe(url, messages, per, holdMs) {
  const ws = new WebSocket(url, ["foxglove.sdk.v1"]);
  let errors = 0, binary = 0;
  ws.on("message", (data, isBinary) => {
    if (isBinary) return void binary++;
    const message = JSON.parse(data.toString());
    if (message.op === "advertise") {
      let id = 1;
      for (let m = 0; m < messages; m++) {
        const subscriptions = [];
        for (let i = 0; i < per; i++, id++)
          subscriptions.push({ id, channelId: message.channels[id % message.channels.length].id });
        ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
      }
      setTimeout(() => {
        console.log(JSON.stringify({ errors, binary }));
        process.exit(0);
      }, holdMs);
    } else if (message.op === "status" && message.level === 2) {
      errors++;
    }
  });
  ws.on("error", (error) => fail(`subscribe: ${error.message}`));
}

async function idle(url, clients, firstSource, holdMs) {
  let opened = 0, closedByServer = 0;
  for (let i = 0; i < clients; i++) {
    const ws = new WebSocket(url, ["foxglove.sdk.v1"], { localAddress: sourceAt(firstSource, i) });
    ws.on("open", () => opened++);
    ws.on("close", () => closedByServer++);
    ws.on("error", () => {});
    await sleep(20);
  }
  await sleep(holdMs);
  console.log(JSON.stringify({ opened, closed_by_server: closedByServer }));
  process.exit(0);
}

async function tcp(host, port, connections, sources, holdMs) {
  let opened = 0, closedByServer = 0, stopping = false;
  const open = (i) => {
    const socket = net.connect({ host, port: Number(port), localAddress: `127.0.1.${1 + (i % sources)}` });
    socket.on("connect", () => opened++);
    socket.on("error", () => {});
    socket.on("close", () => {
      if (stopping) return;
      closedByServer++;
      setTimeout(() => open(i), 50);  // renewed as it closes
    });
  };
  for (let i = 0; i < connections; i++) {
    open(i);
    if (i % 100 === 99) await sleep(10);
  }
  await sleep(holdMs);
  stopping = true;
  console.log(JSON.stringify({ opened, closed_by_server: closedByServer }));
  process.exit(0);
}

const modes = { legit, subscribe, idle, chatty, late, tcp };
if (!modes[mode]) fail(`unknown mode ${mode}`);
await modes[mode](...args.map((a) => (/^\d+$/.test(a) ? Number(a) : a)));
