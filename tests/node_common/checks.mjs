// What the Node checks of rsg share (tests/tools/view, tests/tools/record): failing with a reason, reading
// the command line, reading rsg_sim's --record JSON lines, and comparing a decoded RobotState with
// the frame rsg_sim sent. No npm package here: each test folder has its own node_modules.
import { readFileSync } from "node:fs";

/// fail(message) prints "<name>: message" and exits 1; check(condition, message) fails unless condition.
export function checks(name) {
  const fail = (message) => {
    console.error(`${name}: ${message}`);
    process.exit(1);
  };
  return { fail, check: (condition, message) => condition || fail(message) };
}

/// The command line after the script: args[i], option("--name") (the word after it), flag("--name").
export function commandLine() {
  const args = process.argv.slice(2);
  const option = (name) => {
    const at = args.indexOf(name);
    return at >= 0 ? args[at + 1] : undefined;
  };
  return { args, option, flag: (name) => args.includes(name) };
}

/// The frames of rsg_sim's --record file, one object per line.
export function readFrames(path) {
  return readFileSync(path, "utf8")
    .split("\n")
    .filter((line) => line.trim())
    .map((line) => JSON.parse(line));
}

/// rsg_sim writes its record as it sends and flushes it when done, which can be after the last
/// sample reached the checker: waits until the file has `count` whole lines.
export async function waitForFrames(path, count) {
  for (;;) {
    const lines = readFileSync(path, "utf8").split("\n").slice(0, -1).filter((line) => line.trim());
    if (lines.length >= count) return lines.map((line) => JSON.parse(line));
    await new Promise((resolve) => setTimeout(resolve, 100));
  }
}

const bits = (value) => value.toString(2).split("").filter((bit) => bit === "1").length;

/// A RobotState decoded by Foxglove's decoder equals the frame rsg_sim sent: packet number,
/// selection, and every field the frame carries (error words by their number of flags, as
/// rsg_sim's record names them).
export function checkState(state, frame, where, check) {
  check(state.packet_number === frame.packet_number, `${where}: packet_number ${state.packet_number} != ${frame.packet_number}`);
  check(state.group_select === frame.group_select, `${where}: group_select`);
  check(JSON.stringify([...state.data_select]) === JSON.stringify(frame.data_select), `${where}: data_select`);
  for (const [name, expected] of Object.entries(frame.fields)) {
    const actual = state[name];
    if (name.endsWith("_errors")) {
      check(bits(actual) === expected.length, `${where}: ${name} has ${bits(actual)} flags, the frame ${expected.length}`);
    } else if (Array.isArray(expected)) {
      check(JSON.stringify([...actual]) === JSON.stringify(expected), `${where}: ${name} ${[...actual]} != ${expected}`);
    } else {
      check(Number(actual) === expected, `${where}: ${name} ${actual} != ${expected}`);
    }
  }
}
