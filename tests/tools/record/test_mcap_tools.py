"""rsg_record's files checked by MCAP's own tools and by rosbags, and rsg_replay playing a bag that
rosbags wrote. The tools come from `make deps` (nothing is fetched here):

- $DEPS_DIR/bin/rsg-mcap-check (tools/deps/go/mcapcheck): `doctor` applies the MCAP specification's
  rules with MCAP's own Go library, as `mcap doctor` does, and fails on any error or warning; `info`
  reads the summary and every message through the indexes with the library's indexed reader.
- $DEPS_DIR/mcap (tools/deps/python/mcap.txt): the official Python reader `mcap` (both its seeking and
  its streaming reader, CRCs checked), `mcap_ros2` (its ROS 2 decoder) and `rosbags`.
- The official `mcap` CLI as well, when RSG_MCAP_CLI names one (the Go module proxy does not serve it;
  docs/mcap-tested.md): `mcap doctor` must print nothing, `mcap info` must list the channels.

    test_mcap_tools.py --bin build/bin --deps .deps --case files|ros2_decode|rosbags_replay
"""

import json
import os
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]


def argument(name):
    at = sys.argv.index(name)
    value = sys.argv[at + 1]
    del sys.argv[at:at + 2]
    return value


CASE = argument("--case")
DEPS = Path(argument("--deps"))
VENV_PYTHON = DEPS / "mcap" / "bin" / "python"

# The test runs in the project's MCAP environment; ctest starts it with Debian's Python.
if Path(sys.prefix).resolve() != (DEPS / "mcap").resolve():
    if not VENV_PYTHON.exists():
        print(f"FAILED: {VENV_PYTHON} is missing: run `make deps` (tools/deps/python/mcap.txt)", flush=True)
        sys.exit(1)
    os.execv(str(VENV_PYTHON), [str(VENV_PYTHON), __file__, "--case", CASE, "--deps", str(DEPS), *sys.argv[1:]])

from harness import check, free_udp_port, main, read_json_lines, wait_for, wait_for_stats, wait_matched  # noqa: E402
from replay_target import second_gateway_with_echo  # noqa: E402

from mcap.reader import NonSeekingReader, SeekingReader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from rosbags.rosbag2 import Reader as BagReader, StoragePlugin, Writer as BagWriter  # noqa: E402
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode  # noqa: E402
from rosbags.typesys import Stores, get_typestore, get_types_from_msg  # noqa: E402

CHECKER = DEPS / "bin" / "rsg-mcap-check"
MSG_DIR = ROOT / "ros2" / "rsg_msgs" / "msg"
STATE_TYPE = "rsg_msgs/msg/RobotState"
SELECTIONS = ["--every", "1:q,dq,time", "--every", "3:g0", "--every", "10:all"]


# --- The tools.

def doctor(h, path):
    """No error and no warning from the checker (and from the official CLI when there is one)."""
    check(CHECKER.exists(), f"{CHECKER} is missing: run `make deps` (tools/deps/go.sh)")
    result = subprocess.run([str(CHECKER), "doctor", str(path)], capture_output=True, text=True, timeout=60)
    print(f"[{h.name}] rsg-mcap-check doctor {path.name}: {result.stdout.strip()} {result.stderr.strip()}", flush=True)
    check(result.returncode == 0 and "0 errors, 0 warnings" in result.stdout,
          f"rsg-mcap-check doctor {path.name}: {result.stdout.strip()} {result.stderr.strip()}")
    cli = os.environ.get("RSG_MCAP_CLI")
    if cli:
        result = subprocess.run([cli, "doctor", str(path)], capture_output=True, text=True, timeout=60)
        print(f"[{h.name}] mcap doctor {path.name}: exit {result.returncode} {result.stdout.strip()} "
              f"{result.stderr.strip()}", flush=True)
        check(result.returncode == 0 and not result.stdout.strip() and not result.stderr.strip(),
              f"mcap doctor {path.name}: {result.stdout.strip()} {result.stderr.strip()}")


def info(h, path):
    """The summary as MCAP's Go library reads it, every message read again through the indexes."""
    result = subprocess.run([str(CHECKER), "info", str(path)], capture_output=True, text=True, timeout=60)
    check(result.returncode == 0, f"rsg-mcap-check info {path.name}: {result.stderr.strip()}")
    summary = json.loads(result.stdout)
    check(summary["indexed_messages"] == summary["messages"] == sum(c["messages"] for c in summary["channels"]),
          f"{path.name}: the statistics and the indexes disagree: {summary}")
    check(all(c["indexed_messages"] == c["messages"] for c in summary["channels"]),
          f"{path.name}: a channel's count differs from its indexed messages: {summary['channels']}")
    check(summary["chunks"] > 0 and set(summary["compression"]) == {"zstd"},
          f"{path.name}: chunks {summary['chunks']}, compression {summary['compression']}")
    cli = os.environ.get("RSG_MCAP_CLI")
    if cli:
        text = subprocess.run([cli, "info", str(path)], capture_output=True, text=True, timeout=60).stdout
        print(f"[{h.name}] mcap info {path.name}:\n{text}", flush=True)
        check(f"messages:  {summary['messages']}" in text, f"mcap info {path.name} counts otherwise: {text}")
        for channel in summary["channels"]:
            check(re.search(rf"\({channel['id']}\) {re.escape(channel['topic'])}\s+{channel['messages']} msgs", text),
                  f"mcap info {path.name} does not list channel {channel}: {text}")
    return summary


def python_reader(path):
    """Every message through the official Python reader, seeking (summary and indexes) and streaming
    (record by record), CRCs checked; the two must agree. Returns [(channel topic, log time, data)]."""
    with open(path, "rb") as stream:
        reader = SeekingReader(stream, validate_crcs=True)
        summary = reader.get_summary()
        seeking = [(channel.topic, message.log_time, bytes(message.data))
                   for _, channel, message in reader.iter_messages(log_time_order=False)]
    with open(path, "rb") as stream:
        streaming = [(channel.topic, message.log_time, bytes(message.data))
                     for _, channel, message in NonSeekingReader(stream, validate_crcs=True).iter_messages()]
    check(summary is not None and summary.statistics.message_count == len(seeking),
          f"{path.name}: the Python reader's statistics do not count {len(seeking)} messages")
    check(seeking == streaming, f"{path.name}: the seeking and the streaming reader read different messages")
    check([t for _, t, _ in seeking] == sorted(t for _, t, _ in seeking), f"{path.name}: log times go back")
    return seeking


def check_file(h, path, states, statuses=None, profile=""):
    """doctor, info and the Python reader; `states` RobotState messages (statuses: None = any)."""
    doctor(h, path)
    summary = info(h, path)
    check(summary["library"] == "rsg_record" and summary["profile"] == profile, f"{path.name}: header {summary}")
    by_schema = {c["schema"]: c for c in summary["channels"]}
    state = by_schema.get(STATE_TYPE if profile == "ros2" else "rsg::RobotState")
    check(state is not None and state["messages"] == states, f"{path.name}: {states} states expected: {summary}")
    status_schema = "rsg_msgs/msg/GatewayStatus" if profile == "ros2" else "rsg::GatewayStatus"
    if statuses is not None:
        got = by_schema.get(status_schema, {"messages": 0})["messages"]
        check(got == statuses if statuses == 0 else got >= statuses, f"{path.name}: statuses {got}: {summary}")
    messages = python_reader(path)
    check(len(messages) == summary["messages"], f"{path.name}: Python read {len(messages)} of {summary['messages']}")
    print(f"[{h.name}] {path.name}: {summary['messages']} messages in {summary['chunks']} chunks, channels "
          f"{[(c['topic'], c['schema'], c['messages']) for c in summary['channels']]}", flush=True)
    return summary


# --- Recording.

def recorder(h, label, out, *flags, file_limit=None):
    """rsg_record started as `label`; with file_limit, on a disk that is full at that many bytes (a file
    size limit: the kernel refuses writes past it)."""
    argv = [h.binary("rsg_record"), "--domain", str(h.domain), "--out", str(out), *flags]
    if file_limit is None:
        return h.start(label, argv)

    def limit_file_size():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_limit, file_limit))

    print(f"[{h.name}] start {label} (files of at most {file_limit} bytes): {' '.join(argv)}", flush=True)
    process = subprocess.Popen(argv, stdout=open(h.dir / f"{label}.out", "wb"), stderr=open(h.dir / f"{label}.err", "wb"),
                               preexec_fn=limit_file_size)
    h.children.append((label, process))
    return process


def record(h, recorders, count, rate=1000, limits={}):
    """A gateway, the recorders {label: (file, flags)} matched to it, and rsg_sim sending `count`
    frames; returns (the running recorders, sim's record file, the gateway)."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    running = {label: recorder(h, label, out, *flags, file_limit=limits.get(label))
               for label, (out, flags) in recorders.items()}
    wait_matched(h, stats, list(running), "rsg_record")
    sent = h.dir / "sim.record.jsonl"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(rate), "--count", str(count),
                          "--record", str(sent), *SELECTIONS])
    return running, sim, sent, stats, gateway


def stop_all(h, running, stats, count, gateway):
    wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway to publish every frame")
    time.sleep(1.5)  # the last samples and a status sample reach the recorders
    for label, process in running.items():
        check(h.stop(label, process) == 0, f"{label} did not exit 0: {(h.dir / f'{label}.err').read_text()}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


# --- Comparing with what rsg_sim sent.

def field_name(frame_field):
    """rsg_sim's record names fields as the robot does (O_T_EE); rsg_msgs lowercases them (o_t_ee)."""
    return frame_field.lower()


def check_state(state, frame, where):
    """A decoded RobotState (attributes as in RobotState.msg) equals the frame rsg_sim sent."""
    check(state.packet_number == frame["packet_number"], f"{where}: packet_number")
    check(state.group_select == frame["group_select"], f"{where}: group_select")
    check(list(state.data_select) == frame["data_select"], f"{where}: data_select")
    check(list(state.group_present) == [bool(frame["group_select"] >> g & 1) for g in range(6)],
          f"{where}: group_present")
    for name, expected in frame["fields"].items():
        actual = getattr(state, field_name(name))
        if name.endswith("_errors"):
            check(bin(actual).count("1") == len(expected), f"{where}: {name} {actual:#x}, the frame {expected}")
        elif isinstance(expected, list):
            check([float(x) for x in actual] == expected, f"{where}: {name} {list(actual)} != {expected}")
        else:
            check(float(actual) == expected, f"{where}: {name} {actual} != {expected}")


# --- The cases.

def files(h):
    """Every kind of file rsg_record writes, from one stream: the default (omgidl, 1 MiB zstd chunks),
    --profile ros2 (default and 64 KiB chunks), --split-size files, a --view recording, the file of a
    recorder whose disk filled up, and a file whose recorder was killed with SIGKILL, recovered with
    rsg_record --recover (and with `mcap recover` when RSG_MCAP_CLI is set); each passes doctor with no
    error or warning, and info and the Python reader count what was recorded."""
    count = 1500
    out = {name: h.dir / f"{name}.mcap" for name in ("default", "ros2", "ros2_small", "split", "view", "killed",
                                                     "full")}
    recorders = {
        "default": (out["default"], []),
        "ros2": (out["ros2"], ["--profile", "ros2"]),
        "ros2_small": (out["ros2_small"], ["--profile", "ros2", "--chunk-size", "65536"]),
        "split": (out["split"], ["--split-size", "0.15"]),
        "view": (out["view"], ["--view", "view_poses", "--status-topic", ""]),
        "killed": (out["killed"], ["--profile", "ros2", "--chunk-size", "65536"]),
        "full": (out["full"], ["--chunk-size", "65536"]),
    }
    running, sim, sent, stats, gateway = record(h, recorders, count, limits={"full": 250_000})
    full = running.pop("full")
    # Killed halfway: some chunks are whole, the last one is cut or not begun.
    killed = running.pop("killed")
    wait_for(lambda: out["killed"].stat().st_size > 150_000, "finished chunks in the file to kill")
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    check(h.wait("full", full, 20) == 1, "rsg_record did not exit 1 on a full disk")
    stop_all(h, running, stats, count, gateway)

    # The disk filled up: the file was finished with a summary, or (no room left for one) without.
    err = (h.dir / "full.err").read_text()
    check("File too large" in err and "the file was finished" in err, f"full disk: {err}")
    doctor(h, out["full"])
    if "finished without an index" in err:
        with open(out["full"], "rb") as stream:
            states = sum(c.topic == "robot_state" for _, c, _ in NonSeekingReader(stream, validate_crcs=True).iter_messages())
    else:
        states = next(c["messages"] for c in info(h, out["full"])["channels"] if c["topic"] == "robot_state")
        python_reader(out["full"])
    check(100 < states < count, f"the file of the full disk holds {states} states")

    check_file(h, out["default"], count, statuses=1)
    check_file(h, out["ros2"], count, statuses=1, profile="ros2")
    summary = check_file(h, out["ros2_small"], count, statuses=1, profile="ros2")
    check(summary["chunks"] >= 20, f"--chunk-size 65536 gave {summary['chunks']} chunks")
    parts = sorted(h.dir.glob("split_*.mcap"))  # split_<run's start>_<index>.mcap: by name is by time
    check(len(parts) >= 2, f"--split-size 0.15 gave {len(parts)} files")
    states = 0
    for part in parts:
        doctor(h, part)
        part_summary = info(h, part)
        python_reader(part)
        states += next(c["messages"] for c in part_summary["channels"] if c["topic"] == "robot_state")
    check(states == count, f"the split files hold {states} states for {count} frames")
    check_file(h, out["view"], len([i for i in range(count) if i % 3 == 0 or i % 10 == 0]), statuses=0)

    # The killed file itself has no summary: doctor must say so (it is not a finished file) ...
    result = subprocess.run([str(CHECKER), "doctor", str(out["killed"])], capture_output=True, text=True, timeout=60)
    check(result.returncode == 1 and "no Data End record" in result.stdout,
          f"doctor on the killed file: {result.stdout.strip()}")
    # ... and rsg_record --recover makes it one, holding every message of its whole chunks.
    recovered = h.dir / "recovered.mcap"
    status = h.run("recover", [h.binary("rsg_record"), "--recover", str(out["killed"]), "--out", str(recovered)])
    err = (h.dir / "recover.err").read_text()
    check(status == 0 and "ends early" in err, f"rsg_record --recover exited {status}: {err}")
    whole = int(re.search(r"recovered (\d+) messages", err).group(1))
    doctor(h, recovered)
    summary = info(h, recovered)
    messages = python_reader(recovered)
    check(summary["profile"] == "ros2" and summary["messages"] == whole == len(messages) and whole > 300,
          f"the recovered file holds {summary['messages']} messages, --recover said {whole}: {summary}")
    cli = os.environ.get("RSG_MCAP_CLI")
    if cli:  # the official `mcap recover` makes a file `mcap doctor` accepts too
        official = h.dir / "recovered_by_mcap.mcap"
        result = subprocess.run([cli, "recover", str(out["killed"]), "-o", str(official)], capture_output=True,
                                text=True, timeout=60)
        print(f"[{h.name}] mcap recover: {result.stdout.strip()} {result.stderr.strip()}", flush=True)
        check(result.returncode == 0 and f"Recovered {whole} messages" in result.stderr,
              f"mcap recover: {result.stderr.strip()}")
        doctor(h, official)
    # The recovered messages are the killed recording's first ones, byte for byte.
    with open(out["ros2_small"], "rb") as stream:
        full = [bytes(m.data) for _, c, m in SeekingReader(stream).iter_messages(log_time_order=False)
                if c.topic == "/robot_state"]
    recovered_states = [data for topic, _, data in messages if topic == "/robot_state"]
    check(recovered_states == full[:len(recovered_states)],
          "the recovered states are not the first states of the same stream")


def ros2_decode(h):
    """A --profile ros2 file decoded by the official ROS 2 decoder (mcap_ros2, from the file's own
    ros2msg schemas) and by rosbags (the file opened as a rosbag2 MCAP bag, a typestore built from
    the embedded .msg text): every RobotState equals the frame rsg_sim sent, every GatewayStatus
    decodes, and the topics carry the QoS rosbag2 stores."""
    count = 600
    path = h.dir / "ros2.mcap"
    running, sim, sent, stats, gateway = record(h, {"record": (path, ["--profile", "ros2"])}, count)
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    stop_all(h, running, stats, count, gateway)
    check_file(h, path, count, statuses=1, profile="ros2")
    frames = read_json_lines(sent)
    check(len(frames) == count, f"rsg_sim recorded {len(frames)} frames")

    # mcap + mcap_ros2.
    states = statuses = 0
    with open(path, "rb") as stream:
        reader = SeekingReader(stream, validate_crcs=True, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            check(schema.encoding == "ros2msg" and channel.message_encoding == "cdr", f"{schema}, {channel}")
            if schema.name == STATE_TYPE:
                check_state(decoded, frames[states], f"mcap_ros2, state {states}")
                states += 1
            else:
                check(schema.name == "rsg_msgs/msg/GatewayStatus", f"schema {schema.name}")
                check(isinstance(decoded.rate_hz, float) and decoded.frames_published <= count,
                      f"GatewayStatus {decoded}")
                statuses += 1
    check(states == count and statuses >= 1, f"mcap_ros2 decoded {states} states and {statuses} statuses")

    # rosbags: the .mcap opened as a rosbag2 bag; types from the .msg text embedded in the file.
    typestore = get_typestore(Stores.EMPTY)
    bag_states = bag_statuses = 0
    with BagReader(path) as bag:
        for connection in bag.connections:
            check(connection.msgdef.data.strip(), f"{connection.topic} carries no .msg text")
            typestore.register(get_types_from_msg(connection.msgdef.data, connection.msgtype))
            qos = connection.ext.offered_qos_profiles
            check(len(qos) == 1 and qos[0].reliability.name.lower() == "reliable"
                  and qos[0].durability.name.lower() == "transient_local",
                  f"{connection.topic}: offered QoS {qos}")
        check(sorted(c.topic for c in bag.connections) == ["/robot_state", "/rsg_gateway_status"],
              f"rosbags sees topics {[c.topic for c in bag.connections]}")
        check(bag.message_count == count + sum(1 for c in bag.connections if c.topic == "/rsg_gateway_status"
                                               for _ in range(c.msgcount)), f"rosbags counts {bag.message_count}")
        for connection, timestamp, rawdata in bag.messages():
            message = typestore.deserialize_cdr(rawdata, connection.msgtype)
            if connection.msgtype == STATE_TYPE:
                check_state(message, frames[bag_states], f"rosbags, state {bag_states}")
                bag_states += 1
            else:
                check(isinstance(message.rate_hz, float), f"GatewayStatus {message}")
                bag_statuses += 1
    check(bag_states == count and bag_statuses == statuses, f"rosbags deserialized {bag_states} states, "
          f"{bag_statuses} statuses")
    print(f"[{h.name}] mcap_ros2 and rosbags decoded {count} states and {statuses} statuses as sent", flush=True)


def rosbags_replay(h):
    """rsg_replay plays bags that rosbags wrote (its own MCAP writer: schemas and channels inside the
    chunks, uncompressed chunks or zstd ones): the RobotStates, decoded from a recording with rosbags
    and serialized again by rosbags' own CDR serializer, arrive at rsg_echo over DDS exactly as
    rsg_sim sent them; replayed as raw frames to a gateway, rsg_echo sees the same."""
    count = 300
    path = h.dir / "ros2.mcap"
    running, sim, sent, stats, gateway = record(h, {"record": (path, ["--profile", "ros2",
                                                                      "--status-topic", ""])}, count, rate=500)
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    stop_all(h, running, stats, count, gateway)
    frames = read_json_lines(sent)

    # Messages as Python objects (rosbags' own classes), with the recording's timestamps.
    typestore = get_typestore(Stores.EMPTY)
    typestore.register(get_types_from_msg((MSG_DIR / "RobotState.msg").read_text(), STATE_TYPE))
    with BagReader(path) as bag:
        raws = [(timestamp, bytes(raw)) for _, timestamp, raw in bag.messages()]
    decoded = [(timestamp, typestore.deserialize_cdr(raw, STATE_TYPE)) for timestamp, raw in raws]
    check(len(decoded) == count, f"rosbags read {len(decoded)} states")
    # rosbags' serializer gives the very bytes rsg_record wrote (padding included).
    for index, ((_, raw), (_, message)) in enumerate(zip(raws, decoded)):
        check(bytes(typestore.serialize_cdr(message, STATE_TYPE)) == raw,
              f"state {index}: rosbags serializes it to other bytes than rsg_record wrote")

    for mode in (CompressionMode.NONE, CompressionMode.STORAGE):
        bag_dir = h.dir / f"bag_{mode.name.lower()}"
        writer = BagWriter(bag_dir, version=9, storage_plugin=StoragePlugin.MCAP)
        if mode != CompressionMode.NONE:
            writer.set_compression(mode, CompressionFormat.ZSTD)
        with writer:
            connection = writer.add_connection("/robot_state", STATE_TYPE, typestore=typestore)
            for timestamp, message in decoded:
                writer.write(connection, timestamp, typestore.serialize_cdr(message, STATE_TYPE))
        mcap_files = list(bag_dir.glob("*.mcap"))
        check(len(mcap_files) == 1, f"rosbags wrote {list(bag_dir.iterdir())}")
        label = f"{mode.name.lower()}"
        # Over DDS: rsg_replay --domain -> rsg_echo --json.
        topic = f"bag_{label}"
        echo = h.start(f"echo_{label}", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", topic, "--json",
                                         "--count", str(count), "--timeout", "30"])
        status = h.run(f"replay_{label}", [h.binary("rsg_replay"), str(mcap_files[0]), "--domain", str(h.domain),
                                           "--topic", topic, "--wait-for-readers", "1", "--speed", "4"])
        err = (h.dir / f"replay_{label}.err").read_text()
        check(status == 0 and f"sent {count} samples" in err, f"rsg_replay of rosbags' bag ({label}): {status} {err}")
        check(h.wait(f"echo_{label}", echo, 30) == 0, f"rsg_echo did not get every sample of rosbags' bag ({label})")
        check(read_json_lines(h.output(f"echo_{label}")) == frames,
              f"what rsg_replay played of rosbags' bag ({label}) differs from what rsg_sim sent")
        print(f"[{h.name}] rosbags' bag ({label}) replayed over DDS: {count} samples as sent", flush=True)

    # As raw frames: rsg_replay --to a second gateway -> rsg_echo --json.
    gateway2, port, echo = second_gateway_with_echo(h, count, "echo_udp")
    status = h.run("replay_udp", [h.binary("rsg_replay"), str(mcap_files[0]), "--to", f"127.0.0.1:{port}",
                                  "--speed", "2"])
    check(status == 0, f"rsg_replay --to exited {status}: {(h.dir / 'replay_udp.err').read_text()}")
    check(h.wait("echo_udp", echo, 30) == 0, "rsg_echo did not get every frame replayed from rosbags' bag")
    check(read_json_lines(h.output("echo_udp")) == frames,
          "the frames rsg_replay sent from rosbags' bag differ from what rsg_sim sent")
    check(h.stop("gateway2", gateway2) == 0, "the second gateway did not exit 0")


CASES = {f.__name__: f for f in (files, ros2_decode, rosbags_replay)}

if __name__ == "__main__":
    if not CHECKER.exists():
        print(f"[mcap_tools_{CASE}] FAILED: {CHECKER} is missing: run `make deps` (tools/deps/go.sh)", flush=True)
        sys.exit(1)
    sys.exit(main(f"mcap_tools_{CASE}", CASES[CASE]))
