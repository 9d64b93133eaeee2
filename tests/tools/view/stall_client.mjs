// A client that stops reading: it offers foxglove.sdk.v1, subscribes to the RobotState channel,
// then leaves its socket unread for a while so that rsg_view's queue for it overflows. Once it
// reads again it must get a warning status saying how many messages were dropped for it.
//
//   node stall_client.mjs ws://HOST:PORT STALL_MS
import WebSocket from "ws";
import { checks } from "../../node_common/checks.mjs";

const [url, stallMs] = process.argv.slice(2);
const { fail } = checks("stall_client");
setTimeout(() => fail("no drop report within 60 s"), 60_000);
const ws = new WebSocket(url, ["foxglove.sdk.v1"]);
let received = 0;
let stalled = false;
ws.on("message", (data, isBinary) => {
  if (isBinary) {
    received++;
    if (!stalled) {
      stalled = true;
      ws._socket.pause();  // the kernel buffers fill, then rsg_view's queue for this client
      setTimeout(() => ws._socket.resume(), Number(stallMs));
    }
    return;
  }
  const message = JSON.parse(data.toString());
  if (message.op === "advertise") {
    const state = message.channels.find((c) => c.schemaName === "rsg::RobotState" && c.schemaEncoding === "omgidl");
    if (!state) fail("no RobotState channel");
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: state.id }] }));
    console.log("ready");
  } else if (message.op === "status" && message.id === "rsg_view.dropped") {
    if (message.level !== 1) fail(`drop report at level ${message.level}`);
    const dropped = Number(/dropped (\d+)/.exec(message.message)?.[1]);
    if (!(dropped > 0)) fail(`drop report without a count: ${message.message}`);
    console.log(JSON.stringify({ dropped, received }));
    process.exit(0);
  }
});
ws.on("error", (error) => fail(error.message));
