// Reads an rsg_record MCAP file with the reference reader (@mcap/core, zstd from
// @foxglove/wasm-zstd) and decodes its CDR messages with Foxglove's own IDL decoder
// (@foxglove/omgidl-parser + @foxglove/omgidl-serialization), then compares them with the frames
// rsg_sim sent (its --record JSON lines). A --profile ros2 file is decoded a second time as
// Foxglove opens a ROS 2 recording: with the file's own ros2msg schema (@foxglove/rosmsg +
// @foxglove/rosmsg2-serialization).
//
//   node check_recording.mjs FILE.mcap --frames sim.jsonl [--idl idl/RobotState.idl] [--profile ros2]
//        [--truncated]   a killed recorder's file: no summary; read it as a stream, record by record
//        [--unindexed]   a file finished without a summary (no room was left for one): read it as a
//                        stream, and it must end with a footer
//        [--prefix]      the file may hold only the first frames (a recorder stopped by an error)
//        [--skip N]      the file's first state is frame N (the second and later files of --split-size)
//        [--groups G]    only frames carrying all groups of the bit mask G (a recorder on a view)
//        [--msg-dir DIR] with --profile ros2: each schema rsg_msgs/msg/X must be DIR/X.msg
//
// Prints one JSON line describing what it read (first_sequence: the first state's DDS sequence
// number; sequence_breaks: states whose sequence number is not one more than the one before's);
// exits 1 with the reason on the first mismatch.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { crc32 } from "@foxglove/crc";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { parse as parseMsg } from "@foxglove/rosmsg";
import { MessageReader as Ros2MessageReader } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import { readFileSync } from "node:fs";
import { open } from "node:fs/promises";
import { checkState, checks, commandLine, readFrames } from "../../node_common/checks.mjs";

const { check } = checks("check_recording");
const { args, option, flag } = commandLine();
const file = args[0];
const framesPath = option("--frames");
const idlPath = option("--idl");
const profile = option("--profile") ?? "";
const truncated = flag("--truncated");
const unindexed = flag("--unindexed");

await zstd.isLoaded;
const decompressHandlers = { zstd: (buffer, size) => new Uint8Array(zstd.decompress(buffer, Number(size))) };

const stateSchemaName = profile === "ros2" ? "rsg_msgs/msg/RobotState" : "rsg::RobotState";
const stateSchemaEncoding = profile === "ros2" ? "ros2msg" : "omgidl";

// --- Read every record: indexed (with its summary) or as a stream (without one).
const schemas = new Map();
const channels = new Map();
const messages = [];
let summary = {};
if (truncated || unindexed) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(readFileSync(file));
  let footer = false;
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    else if (record.type === "Channel") channels.set(record.id, record);
    else if (record.type === "Message") messages.push(record);
    else if (record.type === "Footer") footer = true;
  }
  if (unindexed) check(footer, "the file has no footer: it was cut off, not finished");
  else check(!footer, "the file has a footer: it was finished, not cut off");
  summary = { leftover_bytes: reader.bytesRemaining() };
} else {
  const handle = await open(file, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const buffer = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(buffer, 0, buffer.length, Number(offset));
      check(bytesRead === buffer.length, `short read at ${offset}`);
      return buffer;
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  check(reader.header.profile === profile, `header profile '${reader.header.profile}', expected '${profile}'`);
  const stats = reader.statistics;
  check(stats !== undefined, "the summary has no statistics");
  check(reader.chunkIndexes.length > 0, "the summary has no chunk indexes");
  check(stats.chunkCount === reader.chunkIndexes.length, `${stats.chunkCount} chunks counted, ${reader.chunkIndexes.length} indexed`);
  for (const index of reader.chunkIndexes) {
    check(index.compression === "zstd", `a chunk is compressed with '${index.compression}'`);
    check(index.messageIndexOffsets.size > 0, "a chunk has no message index");
  }
  for (const [id, schema] of reader.schemasById) schemas.set(id, schema);
  for (const [id, channel] of reader.channelsById) channels.set(id, channel);
  for await (const message of reader.readMessages({ validateCrcs: true })) messages.push(message);
  check(BigInt(messages.length) === stats.messageCount, `${messages.length} messages read, statistics say ${stats.messageCount}`);
  // Seeking: a time window in the middle, read through the index, is exactly that part of the file.
  const from = messages[Math.floor(messages.length / 3)].logTime;
  const to = messages[Math.floor((2 * messages.length) / 3)].logTime;
  const window = [];
  for await (const message of reader.readMessages({ startTime: from, endTime: to })) window.push(message);
  const expected = messages.filter((message) => message.logTime >= from && message.logTime <= to);
  check(window.length === expected.length && window.length > 0, `seeking [${from}, ${to}] gave ${window.length} messages, not ${expected.length}`);
  check(window.every((message, i) => message.logTime === expected[i].logTime && message.sequence === expected[i].sequence),
        "seeking gave other messages than a full read");
  let counted = 0n;
  for (const count of stats.channelMessageCounts.values()) counted += count;
  check(counted === stats.messageCount, "per-channel message counts do not add up");
  // The Data End record's CRC covers every byte before it (the reader reports it, we check it).
  check(reader.dataSectionCrc !== undefined && reader.dataSectionCrc !== 0, "no data section CRC");
  const dataSection = await readable.read(0n, reader.dataEndOffset);
  check(crc32(dataSection) === reader.dataSectionCrc, "the data section CRC does not match");
  const compressed = reader.chunkIndexes.reduce((sum, index) => sum + index.compressedSize, 0n);
  const uncompressed = reader.chunkIndexes.reduce((sum, index) => sum + index.uncompressedSize, 0n);
  const largest = reader.chunkIndexes.reduce((max, index) => (index.uncompressedSize > max ? index.uncompressedSize : max), 0n);
  summary = { chunks: reader.chunkIndexes.length, ratio: Number(uncompressed) / Number(compressed), largest_chunk: Number(largest) };
  await handle.close();
}

// --- Channels and schemas as the profile says.
const stateChannel = [...channels.values()].find((channel) => schemas.get(channel.schemaId)?.name === stateSchemaName);
check(stateChannel, `no channel with schema ${stateSchemaName}`);
const stateSchema = schemas.get(stateChannel.schemaId);
check(stateSchema.encoding === stateSchemaEncoding, `schema encoding ${stateSchema.encoding}`);
check(stateChannel.messageEncoding === "cdr", `message encoding ${stateChannel.messageEncoding}`);
if (profile === "ros2") {
  check(stateChannel.topic.startsWith("/"), `ROS 2 topic ${stateChannel.topic}`);
  const qos = stateChannel.metadata.get("offered_qos_profiles");
  check(qos && qos.includes("reliability: 1") && qos.includes("durability: 1"), `offered_qos_profiles: ${qos}`);
  const msgDir = option("--msg-dir");
  for (const schema of schemas.values()) {
    check(schema.encoding === "ros2msg" && schema.name.startsWith("rsg_msgs/msg/"), `schema ${schema.name} (${schema.encoding})`);
    const path = `${msgDir}/${schema.name.split("/").pop()}.msg`;
    if (msgDir) check(new TextDecoder().decode(schema.data) === readFileSync(path, "utf8"), `schema ${schema.name} is not ${path}`);
  }
}
const statusChannel = [...channels.values()].find((channel) => channel !== stateChannel);

// --- Decode with the IDL (the ros2 flavour carries the same CDR bytes; decode it with the IDL too).
const idl = idlPath ? readFileSync(idlPath, "utf8") : new TextDecoder().decode(stateSchema.data);
const stateReader = new MessageReader("rsg::RobotState", parseIDL(idl));
const states = messages.filter((message) => message.channelId === stateChannel.id);
const statuses = messages.filter((message) => statusChannel && message.channelId === statusChannel.id);
for (const channel of [states, statuses])
  for (let i = 1; i < channel.length; i++)
    check(channel[i].logTime >= channel[i - 1].logTime, `message ${i} of a channel is older than the one before it`);

if (statusChannel) {
  const statusSchema = schemas.get(statusChannel.schemaId);
  if (statusSchema.encoding === "omgidl") {
    const statusReader = new MessageReader(statusSchema.name, parseIDL(new TextDecoder().decode(statusSchema.data)));
    for (const message of statuses) {
      const status = statusReader.readMessage(message.data);
      check(typeof status.frames_received === "bigint" && typeof status.link_up === "boolean", "a status does not decode");
    }
  }
}

if (framesPath) {
  const groups = Number(option("--groups") ?? 0);
  const frames = readFrames(framesPath)
    .filter((frame) => (frame.group_select & groups) === groups)
    .slice(Number(option("--skip") ?? 0));
  check(states.length <= frames.length, `${states.length} states recorded for ${frames.length} frames sent`);
  if (!truncated && !flag("--prefix") && !flag("--skip")) check(states.length === frames.length, `${states.length} states recorded for ${frames.length} frames sent`);
  states.forEach((message, index) => checkState(stateReader.readMessage(message.data), frames[index], `state ${index}`, check));
  if (profile === "ros2") {
    // ROS field names are the spec's in lower case (O_T_EE -> o_t_ee).
    const rosReader = new Ros2MessageReader(parseMsg(new TextDecoder().decode(stateSchema.data), { ros2: true }));
    const bySpecName = (message) => new Proxy(message, { get: (target, name) => target[String(name).toLowerCase()] });
    states.forEach((message, index) =>
      checkState(bySpecName(rosReader.readMessage(message.data)), frames[index], `state ${index} (ros2msg)`, check));
  }
}

// The latest publish time of a state after the first one's: the span rsg_replay plays a pass over.
const publishSpan = states.reduce((span, message) => {
  const offset = message.publishTime - states[0].publishTime;
  return offset > span ? offset : span;
}, 0n);
// The states in publication order: each DDS sequence number one more than the one before.
let sequenceBreaks = 0;
for (let i = 1; i < states.length; i++) if (states[i].sequence !== states[i - 1].sequence + 1) sequenceBreaks++;
console.log(JSON.stringify({ ...summary, messages: messages.length, states: states.length, statuses: statuses.length,
                             publish_span_ns: Number(publishSpan), first_sequence: states.length ? states[0].sequence : 0,
                             sequence_breaks: sequenceBreaks }));
