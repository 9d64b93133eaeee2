// A real Foxglove client against rsg_view: npm's @foxglove/ws-protocol client (the subprotocol
// foxglove.websocket.v1, as PlotJuggler speaks it) or a plain WebSocket offering foxglove.sdk.v1
// (as the current Foxglove app does). It subscribes to the RobotState, transform and status
// channels, decodes the CDR with the advertised IDL using Foxglove's own decoder
// (@foxglove/omgidl-parser + @foxglove/omgidl-serialization) and compares every state with the
// frames rsg_sim sent (its --record JSON lines).
//
//   node check_view.mjs ws://HOST:PORT --subprotocol legacy|sdk --count N --frames sim.jsonl [--malformed]
//        [--ros2 DIR]   the cdr + ros2msg channels of RobotState and GatewayStatus must be there with
//                       the schemas DIR/RobotState.msg and DIR/GatewayStatus.msg; their messages,
//                       decoded with Foxglove's ROS 2 decoder, equal the IDL ones. The last status
//                       (one that counts all N frames published) is printed for the driver to compare
//                       with the gateway's own counters.
//        [--groups G]   a view: only the frames carrying all groups of the bit mask G arrive (N of them)
//        [--sent M]     rsg_sim sent M frames (default N); the last status must count M published,
//                       and no status may count more (one from another gateway would)
//        [--unsubscribe-after K]  with --ros2: after K states, unsubscribe from the ROS 2 RobotState
//                       channel; once the server has answered a later request, none of its messages
//                       may arrive while the other subscriptions keep flowing
//
// Prints "ready" once subscribed (the driver then starts the simulator) and one JSON line at the
// end; exits 1 with the reason on the first mismatch.
import wsProtocol from "@foxglove/ws-protocol";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { parse as parseMsg } from "@foxglove/rosmsg";
import { MessageReader as Ros2MessageReader } from "@foxglove/rosmsg2-serialization";
import { readFileSync } from "node:fs";
import WebSocket from "ws";
import { checkState, checks, commandLine, waitForFrames } from "../../node_common/checks.mjs";

const { FoxgloveClient } = wsProtocol;
const { fail, check } = checks("check_view");
const { args, option, flag } = commandLine();
const url = args[0];
const flavour = option("--subprotocol") ?? "legacy";
const count = Number(option("--count"));
const framesPath = option("--frames");
const malformed = flag("--malformed");
const ros2Dir = option("--ros2");
const groups = Number(option("--groups") ?? 0);
const sent = Number(option("--sent") ?? count);
const unsubscribeAfter = option("--unsubscribe-after") === undefined ? undefined : Number(option("--unsubscribe-after"));
if (unsubscribeAfter !== undefined && !ros2Dir) fail("--unsubscribe-after needs --ros2");
const timeout = setTimeout(() => fail(`timed out: ${JSON.stringify(progress())}`), Number(option("--timeout") ?? 60) * 1000);

const offered = flavour === "sdk" ? "foxglove.sdk.v1" : FoxgloveClient.SUPPORTED_SUBPROTOCOL;
const ws = new WebSocket(url, [offered]);

// The same events from both clients: serverInfo, advertise, status, message {subscriptionId, data}.
const handlers = {};
const on = (name, handler) => (handlers[name] = handler);
let subscribe, unsubscribe;
let sendRaw = (text) => ws.send(text);
if (flavour === "sdk") {
  ws.binaryType = "nodebuffer";
  let nextId = 1;
  subscribe = (channelId) => {
    const id = nextId++;
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id, channelId }] }));
    return id;
  };
  unsubscribe = (id) => ws.send(JSON.stringify({ op: "unsubscribe", subscriptionIds: [id] }));
  ws.on("open", () => check(ws.protocol === "foxglove.sdk.v1", `server answered subprotocol '${ws.protocol}'`));
  ws.on("message", (data, isBinary) => {
    if (!isBinary) {
      const message = JSON.parse(data.toString());
      if (message.op === "advertise") handlers.advertise?.(message.channels);
      else handlers[message.op]?.(message);
      return;
    }
    check(data[0] === 0x01, `binary opcode ${data[0]}`);
    handlers.message?.({
      subscriptionId: data.readUInt32LE(1),
      timestamp: data.readBigUInt64LE(5),
      data: new DataView(data.buffer, data.byteOffset + 13, data.length - 13),
    });
  });
  ws.on("error", (error) => fail(`WebSocket error: ${error.message}`));
} else {
  const client = new FoxgloveClient({ ws });
  subscribe = (channelId) => client.subscribe(channelId);
  unsubscribe = (id) => client.unsubscribe(id);
  for (const name of ["serverInfo", "advertise", "status", "message"]) client.on(name, (event) => handlers[name]?.(event));
  client.on("error", (error) => fail(`client error: ${error.message}`));
  client.on("open", () => check(ws.protocol === FoxgloveClient.SUPPORTED_SUBPROTOCOL, `subprotocol '${ws.protocol}'`));
}

const states = [];
const ros2States = [];
const ros2Statuses = [];
let ros2Reader, ros2StatusReader;
const transforms = [];
const statuses = [];
const errors = [];
let serverInfo;
let stateReader, statusReader;
const subscriptions = new Map();  // subscription id -> kind
const progress = () => ({ states: states.length, transforms: transforms.length, statuses: statuses.length, errors });

on("serverInfo", (info) => (serverInfo = info));
on("status", (status) => {
  if (status.level === 2) errors.push(status.message);
  if (malformed && errors.length === 3 && !subscriptions.size) start();
});
let channels;
on("advertise", (advertised) => {
  channels = advertised;
  check(serverInfo?.name === "rsg_view", "no serverInfo before advertise");
  if (malformed) {
    // Not JSON, a subscription with a negative id, and a request for a channel that does not exist:
    // each gets an error status and the connection stays usable.
    sendRaw("{not json");
    sendRaw(JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: 1 }] }));
    sendRaw(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 99, channelId: 12345 }] }));
  } else {
    start();
  }
});

function start() {
  const find = (schemaName, encoding) => channels.find((c) => c.schemaName === schemaName && c.schemaEncoding === encoding);
  const state = find("rsg::RobotState", "omgidl");
  check(state && state.encoding === "cdr", "no RobotState cdr+omgidl channel");
  check(state.schema === readFileSync(new URL("../../../idl/RobotState.idl", import.meta.url), "utf8"),
        "the advertised schema is not idl/RobotState.idl");
  stateReader = new MessageReader("rsg::RobotState", parseIDL(state.schema));
  subscriptions.set(subscribe(state.id), "state");
  const transform = find("foxglove.FrameTransform", "jsonschema");
  check(transform && transform.encoding === "json", "no foxglove.FrameTransform channel");
  subscriptions.set(subscribe(transform.id), "transform");
  const status = find("rsg::GatewayStatus", "omgidl");
  check(status, "no GatewayStatus channel");
  statusReader = new MessageReader("rsg::GatewayStatus", parseIDL(status.schema));
  subscriptions.set(subscribe(status.id), "status");
  if (ros2Dir) {
    const ros2Channel = (idlChannel, type) => {
      const channel = find(`rsg_msgs/msg/${type}`, "ros2msg");
      check(channel && channel.encoding === "cdr" && channel.topic === `/${idlChannel.topic}`, `no /${idlChannel.topic} cdr+ros2msg channel`);
      check(channel.schema === readFileSync(`${ros2Dir}/${type}.msg`, "utf8"), `the ros2msg schema is not ${ros2Dir}/${type}.msg`);
      return channel;
    };
    const ros2 = ros2Channel(state, "RobotState");
    ros2Reader = new Ros2MessageReader(parseMsg(ros2.schema, { ros2: true }));
    subscriptions.set(subscribe(ros2.id), "ros2");
    const ros2Status = ros2Channel(status, "GatewayStatus");
    ros2StatusReader = new Ros2MessageReader(parseMsg(ros2Status.schema, { ros2: true }));
    subscriptions.set(subscribe(ros2Status.id), "ros2_status");
  }
  // The subscriptions are in once the server answers a later request: an unsupported op does.
  sendRaw(JSON.stringify({ op: "getParameters", parameterNames: [] }));
  on("status", (message) => {
    if (message.level === 2) errors.push(message.message);
    if (!message.message.includes("getParameters")) return;
    if (!started) {
      started = true;
      console.log("ready");
    } else if (unsubscription?.answered === false) {
      // Every message written after this answer was queued after the unsubscribe was handled.
      Object.assign(unsubscription, { answered: true, states: states.length, statuses: statuses.length,
                                      ros2: ros2States.length });
    }
  });
}
let started = false;
let unsubscription;  // {id, answered, and the counts when the server's answer arrived}

function unsubscribeRos2States() {
  const id = [...subscriptions].find(([, kind]) => kind === "ros2")[0];
  unsubscription = { id, answered: false };
  unsubscribe(id);
  sendRaw(JSON.stringify({ op: "getParameters", parameterNames: [] }));
}

on("message", ({ subscriptionId, data }) => {
  const kind = subscriptions.get(subscriptionId);
  check(kind, `a message for subscription ${subscriptionId}, which is not ours`);
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  if (kind === "state") states.push(stateReader.readMessage(bytes));
  else if (kind === "status") statuses.push(statusReader.readMessage(bytes));
  else if (kind === "ros2") {
    check(!unsubscription?.answered, `a message of subscription ${subscriptionId} after it was unsubscribed`);
    ros2States.push(ros2Reader.readMessage(bytes));
  }
  else if (kind === "ros2_status") ros2Statuses.push(ros2StatusReader.readMessage(bytes));
  else transforms.push(JSON.parse(new TextDecoder().decode(bytes)));
  if (kind === "state" && states.length === unsubscribeAfter) unsubscribeRos2States();
  if (states.length >= count && lastStatusArrived() && !finishing) {
    finishing = true;
    finish();
  }
});
let finishing = false;

// With --ros2: a status counting every frame published, in both flavours (the gateway sends one
// within a second of the last frame); without: any status.
function lastStatusArrived() {
  if (!ros2Dir) return statuses.length >= 1;
  const complete = (list) => list.length > 0 && Number(list[list.length - 1].frames_published) === sent;
  return complete(statuses) && complete(ros2Statuses);
}

// The IDL's nested structs, spelled out as the .msg does: invalid.bad_crc -> invalid_bad_crc.
function flatten(message, prefix = "", out = {}) {
  for (const [name, value] of Object.entries(message)) {
    if (value !== null && typeof value === "object" && !ArrayBuffer.isView(value) && !Array.isArray(value))
      flatten(value, `${prefix}${name}_`, out);
    else out[`${prefix}${name}`] = typeof value === "bigint" ? Number(value) : value;
  }
  return out;
}

async function finish() {
  const frames = (await waitForFrames(framesPath, sent)).filter((frame) => (frame.group_select & groups) === groups);
  clearTimeout(timeout);
  check(states.length === frames.length, `${states.length} states received for ${frames.length} frames sent`);
  const most = Math.max(...statuses.map((status) => Number(status.frames_published)));
  check(most <= sent, `a status counts ${most} frames published of ${sent} sent: another gateway's?`);
  const translations = new Set();
  states.forEach((state, index) => {
    const frame = frames[index];
    checkState(state, frame, `state ${index}`, check);
    if (frame.fields.O_T_EE) translations.add(JSON.stringify(frame.fields.O_T_EE.slice(12, 15)));
  });
  check(transforms.length === translations.size || transforms.length > 0, "no transform");
  for (const t of transforms) {
    check(t.parent_frame_id === "base" && t.child_frame_id === "end_effector", "transform frame ids");
    check(translations.has(JSON.stringify([t.translation.x, t.translation.y, t.translation.z])),
          `transform translation ${JSON.stringify(t.translation)} is no O_T_EE sent`);
    const { x, y, z, w } = t.rotation;
    check(Math.abs(x * x + y * y + z * z + w * w - 1) < 1e-9, "transform rotation is no unit quaternion");
  }
  let lastStatus;
  if (ros2Dir) {
    // Same CDR bytes, two schemas: every ROS 2 message equals its IDL twin, member by member.
    const text = (value) => JSON.stringify(ArrayBuffer.isView(value) ? [...value] : value,
                                           (key, v) => (typeof v === "bigint" ? v.toString() : v));
    check(ros2States.length > 0 && ros2States.length <= states.length, `${ros2States.length} ROS 2 messages`);
    if (unsubscription) {
      check(unsubscription.answered, "the server never answered the request after the unsubscribe");
      check(ros2States.length === unsubscription.ros2 && ros2States.length < states.length,
            `${ros2States.length} ROS 2 messages for ${states.length} states, ${unsubscription.ros2} when unsubscribed`);
      check(states.length > unsubscription.states && statuses.length > unsubscription.statuses,
            `the other subscriptions stopped with the unsubscribe: ${JSON.stringify(unsubscription)}`);
    }
    ros2States.forEach((message, index) => {
      for (const [name, value] of Object.entries(states[index]))
        check(text(message[name.toLowerCase()]) === text(value), `ROS 2 message ${index}: ${name} differs`);
    });
    check(ros2Statuses.length > 0 && ros2Statuses.length <= statuses.length, `${ros2Statuses.length} ROS 2 statuses`);
    // A status published while the two subscriptions were being made is in one list only: match
    // each ROS 2 status to an IDL one with every member equal (the nested struct spelled out).
    const idlStatuses = new Set(statuses.map((status) => text(flatten(status))));
    ros2Statuses.forEach((message, index) =>
      check(idlStatuses.has(text(flatten(message))), `ROS 2 status ${index} ${text(flatten(message))} equals no IDL status`));
    lastStatus = flatten(ros2Statuses[ros2Statuses.length - 1]);
  }
  check(typeof statuses[0].frames_published === "bigint" && typeof statuses[0].link_up === "boolean", "a status does not decode");
  if (malformed) {
    check(errors.some((e) => e.includes("not JSON")), `no error status for invalid JSON: ${errors}`);
    check(errors.some((e) => e.includes("unsigned 32-bit")), `no error status for a negative id: ${errors}`);
    check(errors.some((e) => e.includes("no channel 12345")), `no error status for an unknown channel: ${errors}`);
  }
  console.log(JSON.stringify({ subprotocol: ws.protocol, ros2: ros2States.length, ros2_statuses: ros2Statuses.length,
                               ...progress(), unsubscription, last_status: lastStatus }));
  ws.close();
  process.exit(0);
}
