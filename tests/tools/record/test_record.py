"""rsg_record and rsg_replay with real components: rsg_sim -> rsg_gateway -> rsg_record, the file
read by the reference MCAP reader (@mcap/core, in check_recording.mjs), and played back through a
gateway to rsg_echo. Each case is one ctest test (record.<case>), in its own DDS domain and ports.

    test_record.py --bin build/bin --case reference_reader
"""

import json
import os
import re
import resource
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
from harness import (UdpRelay, check, free_udp_port, main, read_json, read_json_lines, receive_timed,  # noqa: E402
                     timed_receiver, wait_for, wait_for_stats, wait_matched)
from replay_target import second_gateway_with_echo  # noqa: E402

CASE = sys.argv[sys.argv.index("--case") + 1]
del sys.argv[sys.argv.index("--case"):sys.argv.index("--case") + 2]


def node_check(h, mcap, *args):
    """Runs check_recording.mjs; fails the test (never skips) when Node or its packages are missing."""
    node = shutil.which("node")
    check(node is not None, "node is not installed: run `make deps`")
    check((HERE / "node_modules" / "@mcap" / "core").is_dir(),
          "tests/tools/record/node_modules is missing: run `make deps` (npm ci --prefix tests/tools/record)")
    result = subprocess.run([node, str(HERE / "check_recording.mjs"), str(mcap), *map(str, args)],
                            capture_output=True, text=True, timeout=60)
    print(f"[{h.name}] check_recording: {result.stdout.strip()} {result.stderr.strip()}", flush=True)
    check(result.returncode == 0, f"the reference reader rejected {mcap}: {result.stderr.strip()}")
    return json.loads(result.stdout)


def recorder(h, label, out, *flags, preexec_fn=None):
    argv = [h.binary("rsg_record"), "--domain", str(h.domain), "--out", str(out), *flags]
    print(f"[{h.name}] start {label}: {' '.join(argv)}", flush=True)
    stdout = open(h.dir / f"{label}.out", "wb")
    stderr = open(h.dir / f"{label}.err", "wb")
    process = subprocess.Popen(argv, stdout=stdout, stderr=stderr, preexec_fn=preexec_fn)
    h.children.append((label, process))
    return process


def stderr_of(h, label):
    return (h.dir / f"{label}.err").read_text(errors="replace")


def gateway_with_recorder(h, *record_flags, preexec_fn=None):
    """A gateway on a free port and a recorder matched to its writer (and status writer)."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    out = h.dir / "run.mcap"
    rec = recorder(h, "record", out, *record_flags, preexec_fn=preexec_fn)
    wait_matched(h, stats, ["record"], "rsg_record")
    return port, gateway, stats, rec, out


def run_sim(h, port, count, rate, *flags):
    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(rate),
                           "--count", str(count), "--record", str(record), *flags])
    check(status == 0, f"rsg_sim exited {status}")
    return record


SELECTIONS = ["--every", "1:q,dq,time", "--every", "3:g0", "--every", "10:all"]


def set_files(h, stem):
    """The files of a numbered set (--split-size, --trigger), oldest first: their names sort by time
    (STEM_<run's start>_<index>.mcap)."""
    name = re.compile(rf"{re.escape(stem)}_\d{{8}}T\d{{6}}\.\d{{3}}Z_\d{{6}}\.mcap")
    return sorted(path for path in h.dir.glob(f"{stem}_*.mcap") if name.fullmatch(path.name))


def index_of(path):
    """The index of a numbered file in its run (the last part of its name)."""
    return int(path.stem.rsplit("_", 1)[1])


def reference_reader(h):
    """Every frame sent is in the file, decoded by Foxglove's decoder to the values sent; the summary
    (statistics, chunk indexes, message indexes) is what @mcap/core needs to seek."""
    port, gateway, stats, rec, out = gateway_with_recorder(h)
    record = run_sim(h, port, 1500, 1000, *SELECTIONS)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 1500, "the gateway to publish every frame")
    wait_for(lambda: out.stat().st_size > 0, "the recording")
    time.sleep(1.5)  # the last samples and a status sample reach the recorder
    check(h.stop("record", rec) == 0, f"rsg_record did not exit 0 on SIGTERM: {stderr_of(h, 'record')}")
    check("dropped 0 (sequence gaps), 0 (lost in DDS)" in stderr_of(h, "record"), stderr_of(h, "record"))
    seen = node_check(h, out, "--frames", record)
    check(seen["states"] == 1500 and seen["statuses"] >= 1, f"read {seen}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def sigkill(h):
    """A recorder killed with SIGKILL leaves a file that the reference reader reads, record by record,
    up to its last finished chunk; rsg_replay plays it with a warning."""
    port, gateway, stats, rec, out = gateway_with_recorder(h)
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "4000",
                          "--record", str(h.dir / "sim.record.jsonl")])
    # At 1 kHz a chunk (1 MiB of full frames) is finished about every half second.
    wait_for(lambda: out.stat().st_size > 400_000, "two finished chunks in the file")
    rec.send_signal(signal.SIGKILL)
    rec.wait()
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    seen = node_check(h, out, "--truncated", "--frames", h.dir / "sim.record.jsonl")
    check(seen["states"] >= 400, f"only {seen['states']} states readable after the kill")
    status = h.run("replay", [h.binary("rsg_replay"), str(out), "--to", f"127.0.0.1:{free_udp_port()}",
                              "--speed", "50"])
    check(status == 0, f"rsg_replay exited {status}: {stderr_of(h, 'replay')}")
    check(f"sent {seen['states']} samples" in stderr_of(h, "replay") and "ends early" in stderr_of(h, "replay"),
          f"rsg_replay: {stderr_of(h, 'replay')}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def write_errors(h):
    """An --out in a directory that does not exist is a usage error (exit 2: checked before anything
    starts, tools.flag_errors); a full disk (a file size limit: the kernel refuses writes past it)
    is a clear error with exit 1; what was recorded stays readable by the reference reader."""
    status = h.run("unwritable", [h.binary("rsg_record"), "--domain", str(h.domain), "--out",
                                  str(h.dir / "no" / "such" / "dir.mcap")])
    check(status == 2, f"rsg_record exited {status} for an --out in a missing directory")
    check("--out" in stderr_of(h, "unwritable") and "No such file or directory" in stderr_of(h, "unwritable"),
          stderr_of(h, "unwritable"))

    limit = 700_000

    def limit_file_size():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    # Chunks far smaller than the limit, so that whole chunks are on disk before the write that fails
    # (with the default 1 MiB a single chunk, finished late on a loaded host, can outgrow the limit).
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--chunk-size", "65536", preexec_fn=limit_file_size)
    record = run_sim(h, port, 3000, 1000)
    check(h.wait("record", rec, 20) == 1, f"rsg_record did not exit 1 on a full disk: {stderr_of(h, 'record')}")
    err = stderr_of(h, "record")
    check("File too large" in err and "the file was finished" in err, err)
    check(out.stat().st_size <= limit, "the file outgrew the limit")
    # Whether the summary fits between the last whole chunk and the limit depends on a few hundred
    # bytes (the schemas' size moves every chunk boundary): without it the file ends with a footer
    # alone, which the reference reader reads as a stream.
    unindexed = ["--unindexed"] if "finished without an index" in err else []
    seen = node_check(h, out, "--frames", record, "--prefix", *unindexed)
    check(seen["states"] > 100, f"read {seen}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def replay_roundtrip(h):
    """record -> replay -> gateway -> rsg_echo --json gives the original stream exactly, and the
    replayed datagrams are byte for byte the ones the first gateway received; --domain replays the
    samples over DDS to the same effect. The frames keep the recording's spacing divided by --speed
    (2 and 0.5; a lower bound on the span from the first to the last arrival), and --loop plays the
    file again, the same frames, the second pass starting one mean gap of the recording (divided by
    --speed) after the first one's last frame (a lower bound: at least half a mean gap)."""
    count = 1200
    # Small chunks: starting the file over then costs rsg_replay a fraction of a millisecond (unpacking
    # a default 1 MiB first chunk takes about one mean gap of this stream), so that the gap at the wrap
    # that --loop's check sees is the one rsg_replay leaves on purpose.
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--chunk-size", "65536")
    tap_port = free_udp_port()
    tap = UdpRelay(tap_port, forward_to=("127.0.0.1", port))
    tap.start()
    try:
        record = run_sim(h, tap_port, count, 1000, *SELECTIONS)
        wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway to publish every frame")
    finally:
        tap.stop()
    time.sleep(1.0)
    check(h.stop("record", rec) == 0, f"rsg_record did not exit 0: {stderr_of(h, 'record')}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    sent = read_json_lines(record)
    recorded = node_check(h, out, "--frames", record)
    check(recorded["states"] == count, f"read {recorded}")

    # Raw: replay -> tap -> second gateway -> rsg_echo --json.
    gateway2, port2, echo = second_gateway_with_echo(h, count, "echo")
    tap2_port = free_udp_port()
    tap2 = UdpRelay(tap2_port, forward_to=("127.0.0.1", port2))
    tap2.start()
    try:
        status = h.run("replay", [h.binary("rsg_replay"), str(out), "--to", f"127.0.0.1:{tap2_port}", "--speed", "2"])
        check(status == 0, f"rsg_replay exited {status}: {stderr_of(h, 'replay')}")
        check(h.wait("echo", echo, 30) == 0, "rsg_echo did not get every replayed sample")
    finally:
        tap2.stop()
    check(len(tap2.datagrams) == len(tap.datagrams) == count,
          f"{len(tap.datagrams)} frames recorded, {len(tap2.datagrams)} replayed")
    for index, (original, replayed) in enumerate(zip(tap.datagrams, tap2.datagrams)):
        check(original == replayed, f"replayed frame {index} differs from the frame the gateway received")
    received = read_json_lines(h.output("echo"))
    check(received == sent, "rsg_echo's stream after the replay differs from what rsg_sim sent")
    check(h.stop("gateway2", gateway2) == 0, "the second gateway did not exit 0")
    # The file's publish times are the first gateway's, stamped as it received each frame from the tap.
    span_s = tap.times[-1] - tap.times[0]
    took = tap2.times[-1] - tap2.times[0]
    print(f"[{h.name}] recorded over {span_s:.3f} s, replayed at --speed 2 in {took:.3f} s", flush=True)
    check(took >= 0.8 * span_s / 2, f"--speed 2 replayed {span_s:.3f} s of frames in {took:.3f} s")

    # --loop at half speed, until SIGINT: a second pass of the same frames follows the first.
    speed = 0.5
    receiver = timed_receiver()
    looping = h.start("replay_loop", [h.binary("rsg_replay"), str(out), "--to",
                                      f"127.0.0.1:{receiver.getsockname()[1]}", "--loop", "--speed", str(speed)])
    again = count // 4
    looped = receive_timed(receiver, count + again, timeout_s=30, quiet_s=None)
    looping.send_signal(signal.SIGINT)
    check(h.wait("replay_loop", looping, 10) == 0, f"rsg_replay --loop did not exit 0 on SIGINT: "
          f"{stderr_of(h, 'replay_loop')}")
    receiver.close()
    frames = [data for _, data in looped]
    check(frames[:count] == tap.datagrams, "the first pass of --loop differs from the frames the gateway received")
    check(frames[count:] == tap.datagrams[:again], "the second pass of --loop does not play the file from its start")
    took = looped[count - 1][0] - looped[0][0]
    print(f"[{h.name}] the first pass of --loop at --speed {speed} took {took:.3f} s", flush=True)
    check(took >= 0.8 * span_s / speed,
          f"rsg_replay played {span_s:.3f} s of frames in {took:.3f} s at --speed {speed}")
    # The second pass is due one mean gap (divided by --speed) after the first pass's last frame was due,
    # and nothing is sent before it is due; the first frame goes out at once. So from the first arrival
    # to the first of the second pass is at least the file's span and one mean gap, divided by --speed
    # (half a mean gap here: slack for the first send), whatever the host's load. A second pass started
    # right after the last frame falls short unless that frame went out late by more than that.
    file_span_s = recorded["publish_span_ns"] / 1e9
    mean_gap_s = file_span_s / (count - 1)
    second_pass_s = looped[count][0] - looped[0][0]
    print(f"[{h.name}] the file spans {file_span_s:.4f} s (mean gap {mean_gap_s * 1e3:.3f} ms); --loop's second "
          f"pass started {second_pass_s:.4f} s after the first, "
          f"{(looped[count][0] - looped[count - 1][0]) * 1e3:.3f} ms after the first pass's last frame", flush=True)
    check(second_pass_s >= (file_span_s + mean_gap_s / 2) / speed,
          f"--loop --speed {speed} started the second pass {second_pass_s:.4f} s after the first; the file spans "
          f"{file_span_s:.4f} s with a mean gap of {mean_gap_s * 1e3:.3f} ms")

    # DDS: replay --domain -> rsg_echo --json.
    echo2 = h.start("echo2", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "dds_replayed", "--json",
                              "--count", str(count), "--timeout", "30"])
    status = h.run("replay_dds", [h.binary("rsg_replay"), str(out), "--domain", str(h.domain), "--topic",
                                  "dds_replayed", "--wait-for-readers", "1", "--speed", "4"])
    check(status == 0, f"rsg_replay --domain exited {status}: {stderr_of(h, 'replay_dds')}")
    check(h.wait("echo2", echo2, 30) == 0, "rsg_echo did not get every sample replayed over DDS")
    check(read_json_lines(h.output("echo2")) == sent, "the DDS replay differs from what rsg_sim sent")


def split_and_view(h):
    """--split-size starts a new complete file when one is full; --view records only the samples
    carrying the view's groups (view_poses: group 0, every third and every tenth frame here)."""
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--split-size", "0.1")
    viewed = h.dir / "poses.mcap"
    rec2 = recorder(h, "record_view", viewed, "--view", "view_poses", "--status-topic", "")
    wait_matched(h, stats, ["record", "record_view"], "rsg_record")
    record = run_sim(h, port, 1500, 1000, *SELECTIONS)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 1500, "the gateway to publish every frame")
    time.sleep(1.0)
    check(h.stop("record", rec) == 0 and h.stop("record_view", rec2) == 0, "a recorder did not exit 0")
    files = set_files(h, "run")
    check(len(files) >= 2, f"--split-size 0.1 gave {len(files)} files")
    check([index_of(path) for path in files] == list(range(len(files))), f"the split files: {files}")
    states = 0
    for path in files:
        check(path.stat().st_size < 600_000, f"{path.name} is {path.stat().st_size} bytes")
        states += node_check(h, path, "--frames", record, "--skip", states)["states"]
    check(states == 1500, f"the split files hold {states} states for 1500 frames")
    seen = node_check(h, viewed, "--frames", record, "--groups", 1)
    check(seen["statuses"] == 0 and seen["states"] == len([i for i in range(1500) if i % 3 == 0 or i % 10 == 0]),
          f"view_poses recorded {seen}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def duration(h):
    """--duration S stops the recorder by itself with exit 0 and a finished file holding the first
    frames of the stream."""
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--duration", "2")
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "20000",
                          "--record", str(h.dir / "sim.record.jsonl")])
    check(h.wait("record", rec, 20) == 0, f"rsg_record did not exit 0 after --duration: {stderr_of(h, 'record')}")
    sim.send_signal(signal.SIGTERM)
    h.wait("sim", sim)
    seen = node_check(h, out, "--frames", h.dir / "sim.record.jsonl", "--prefix")
    check(0 < seen["states"] < 2100, f"a 2 s recording of a 1 kHz stream holds {seen['states']} states")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def ros2_profile(h):
    """--profile ros2: the MCAP ros2 profile (header, ros2msg schema rsg_msgs/msg/RobotState with the
    .msg text, /topic names, offered_qos_profiles as rosbag2 writes them); the CDR bytes are the
    same, so Foxglove's decoder reads the values sent both with the IDL and with the
    file's own ros2msg schema (as Foxglove opens a ROS 2 recording)."""
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--profile", "ros2")
    record = run_sim(h, port, 600, 1000, *SELECTIONS)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 600, "the gateway to publish every frame")
    time.sleep(1.5)
    check(h.stop("record", rec) == 0, f"rsg_record did not exit 0: {stderr_of(h, 'record')}")
    msg_dir = ROOT / "ros2" / "rsg_msgs" / "msg"
    seen = node_check(h, out, "--frames", record, "--profile", "ros2", "--idl", ROOT / "idl" / "RobotState.idl",
                      "--msg-dir", msg_dir)
    check(seen["states"] == 600 and seen["statuses"] >= 1, f"read {seen}")
    # The schemas are those .msg files; rosidl's own parser (Debian's, under /usr/bin/python3) reads them.
    for name in ("RobotState", "GatewayStatus"):
        parsed = subprocess.run(["/usr/bin/python3", "-c",
                                 "import sys; from rosidl_adapter.parser import parse_message_string as p; "
                                 "print(len(p('rsg_msgs', sys.argv[1], open(sys.argv[2]).read()).fields))",
                                 name, str(msg_dir / f"{name}.msg")], capture_output=True, text=True)
        check(parsed.returncode == 0, f"rosidl rejects {name}.msg: {parsed.stderr.strip()}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def gateway_with_traced_recorder(h, inject, *record_flags):
    """A gateway on a free port and rsg_record under strace (started as "record"), matched to its
    writers: strace logs the recorder's fdatasync calls to fdatasync.trace and injects `inject`
    into them (-y names each descriptor's file; --seccomp-bpf stops the recorder for fdatasync only)."""
    strace = shutil.which("strace")
    check(strace is not None, "strace is not installed: run `make deps`")
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    out = h.dir / "run.mcap"
    traced = h.start("record", [strace, "-f", "-y", "--seccomp-bpf", "-e", "trace=fdatasync",
                                "-e", f"inject=fdatasync:{inject}", "-o", str(h.dir / "fdatasync.trace"),
                                h.binary("rsg_record"), "--domain", str(h.domain), "--out", str(out), *record_flags])
    wait_matched(h, stats, ["record"], "rsg_record")
    return port, gateway, stats, traced, out


def wait_until_quiet(measure, quiet_s, what, timeout_s=30):
    """Waits until `measure()` has kept its value for `quiet_s` seconds."""
    value, since = measure(), time.monotonic()
    deadline = since + timeout_s
    while time.monotonic() < deadline:
        now_value = measure()
        if now_value != value:
            value, since = now_value, time.monotonic()
        elif time.monotonic() - since >= quiet_s:
            return
        time.sleep(0.05)
    check(False, f"timed out after {timeout_s} s waiting for {what}")


def strace_child(traced):
    """The pid of the one process strace (started as `traced`) runs."""
    children = Path(f"/proc/{traced.pid}/task/{traced.pid}/children").read_text().split()
    check(len(children) == 1, f"strace has children {children}")
    return int(children[0])


def chunk_size_fsync(h):
    """--chunk-size 65536 finishes a chunk as soon as its records reach 64 KiB (the reference reader
    finds no larger one, and as many as the recorder reports); --fsync calls fdatasync on the file
    after every finished chunk and once at the end (strace, Debian's, counts the calls). strace also
    makes every fdatasync take 50 ms, a slow disk: the recorder falls seconds behind the stream and
    still records every frame, stopped once its file has stopped growing. (What it writes on SIGTERM
    is drain_on_sigterm's test.)"""
    chunk = 65536
    port, gateway, stats, traced, out = gateway_with_traced_recorder(h, "delay_enter=50000", "--chunk-size", str(chunk),
                                                                     "--fsync")
    record = run_sim(h, port, 2000, 1000)  # every field in every frame: about 2 KB a message
    wait_for_stats(stats, lambda s: s["frames_published"] >= 2000, "the gateway to publish every frame")
    # The file is seconds behind, and on a loaded host the DDS reader may be too (the gateway repairs
    # what a full reader history refused): stopped once the recorder has caught up, when its chunks
    # (each one fdatasync) no longer follow each other 50 ms apart but come with the gateway's 1 Hz
    # status samples (a chunk spans at most 1 s).
    trace = h.dir / "fdatasync.trace"
    wait_until_quiet(lambda: trace.read_text().count("fdatasync(") if trace.exists() else 0, 0.6,
                     "the recorder to catch up with the stream")
    # SIGTERM to rsg_record itself (strace's child), as an operator would; strace then exits with it.
    os.kill(strace_child(traced), signal.SIGTERM)
    check(h.wait("record", traced, 30) == 0, f"rsg_record did not exit 0 on SIGTERM: {stderr_of(h, 'record')}")
    err = stderr_of(h, "record")
    seen = node_check(h, out, "--frames", record)
    check(seen["states"] == 2000, f"read {seen}")
    # A chunk ends with the first message that takes it to the limit: at most one message over it.
    check(seen["largest_chunk"] <= chunk + 4096, f"a chunk of {seen['largest_chunk']} bytes for --chunk-size {chunk}")
    check(seen["chunks"] >= 2000 * 1500 // (chunk + 4096), f"only {seen['chunks']} chunks of at most {chunk} bytes")
    check(f" in {seen['chunks']} chunks, " in err, f"the recorder reports other chunks than the file has: {err}")
    # A call another thread interrupts shows as "fdatasync(3</path> <unfinished ...>", then "<... fdatasync resumed>".
    lines = (h.dir / "fdatasync.trace").read_text().splitlines()
    syncs = [line for line in lines if "fdatasync(" in line and f"{out}>" in line]
    failed = [line for line in lines if "fdatasync" in line and "= -1" in line]
    check(len(syncs) == seen["chunks"] + 1 and not failed,
          f"{len(syncs)} fdatasync calls on the file for {seen['chunks']} chunks; failed: {failed}")
    check(f"; {seen['chunks'] + 1} fsyncs in " in err, f"the recorder's summary does not count its fsyncs: {err}")
    print(f"[{h.name}] {err.strip()}", flush=True)
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def drain_on_sigterm(h):
    """On SIGTERM rsg_record writes what its DDS reader had already received before it closes the
    file. strace holds the recorder's main thread in its first fdatasync (--fsync: the chunk holding
    the gateway's first status samples, finished a second later) for 20 s, a stalled disk; meanwhile
    rsg_sim sends 400 frames, the reliable reader receives them (DDS's own threads run on) and the
    recorder gets SIGTERM. Its last take was before the stall, so only the drain at the stop puts
    those frames in the file. The test checks (in /proc) that the main thread stayed in that stop,
    not running once, from before the first frame until after the stop request."""
    count = 400
    # when=1: only the first fdatasync stalls; the ones that finish the file at the stop are quick.
    port, gateway, stats, traced, out = gateway_with_traced_recorder(h, "delay_enter=20000000:when=1", "--fsync")
    pid = strace_child(traced)
    main_thread = Path(f"/proc/{pid}/task/{pid}")

    def stalled():
        """The main thread's state ('t': stopped by strace) and how often it has been switched out."""
        # The state follows the command name in parentheses (which may hold spaces).
        state = (main_thread / "stat").read_text().rsplit(")", 1)[1].split()[0]
        switches = sum(int(line.split()[1]) for line in (main_thread / "status").read_text().splitlines()
                       if line.startswith(("voluntary_ctxt_switches:", "nonvoluntary_ctxt_switches:")))
        return state == "t", switches

    wait_for(lambda: stalled()[0], "the recorder to stall in its first fdatasync")
    before = stalled()
    record = run_sim(h, port, count, 2000)
    wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway to publish every frame")
    time.sleep(1.0)  # the frames reach the recorder's reliable reader (same host: milliseconds)
    os.kill(pid, signal.SIGTERM)
    time.sleep(0.5)  # StopOnSignal's thread takes the signal at once and asks the main thread to stop
    check(stalled() == before, "the recorder's main thread ran between the first frame and SIGTERM (a host "
          f"too slow for the 20 s stall?), so this run cannot tell the drain apart: {before} then {stalled()}")
    check(h.wait("record", traced, 60) == 0, f"rsg_record did not exit 0 on SIGTERM: {stderr_of(h, 'record')}")
    err = stderr_of(h, "record")
    print(f"[{h.name}] {err.strip()}", flush=True)
    seen = node_check(h, out, "--frames", record)
    check(seen["states"] == count, f"the file holds {seen['states']} of the {count} frames the reader had at SIGTERM")
    check(f"received {count} states" in err, f"the recorder's summary: {err}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def cpu_hogs(h, count, seconds):
    """`count` processes that spin for `seconds` (then exit by themselves): a busy host."""
    spin = f"import time\nend = time.monotonic() + {seconds}\nwhile time.monotonic() < end: pass"
    return [h.start(f"hog{i}", [sys.executable, "-c", spin]) for i in range(count)]


def mid_stream_under_load(h):
    """A recorder that joins a running 1 kHz stream on a host kept busy by CPU hogs writes the states
    in publication order from its first one on (each DDS sequence number one more than the one
    before, the values those frames carried), says it dropped and lost nothing, and its file,
    replayed into a second gateway, gives that gateway 0 lost, duplicated and reordered frames: the
    counters of the clean original stream. (The reader gets the writer's history after the first
    live samples as it joins; written in arrival order, the file jumped back.)"""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    wait_for_stats(stats, lambda s: True, "the gateway to start", timeout_s=60)
    count = 9000
    record = h.dir / "sim.record.jsonl"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", str(count),
                          "--record", str(record)])
    hogs = cpu_hogs(h, 3, 8)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 1000, "the stream to run")
    out = h.dir / "run.mcap"
    rec = recorder(h, "record", out, "--duration", "4", "--chunk-size", "65536")
    check(h.wait("record", rec, 30) == 0, f"rsg_record did not exit 0 after --duration: {stderr_of(h, 'record')}")
    err = stderr_of(h, "record")
    print(f"[{h.name}] {err.strip()}", flush=True)
    check("dropped 0 (sequence gaps), 0 (lost in DDS)" in err, f"the recorder lost states: {err}")
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    for hog in hogs:
        hog.wait(timeout=30)
    final = wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway to publish every frame")
    check((final["lost"], final["duplicated"], final["reordered"]) == (0, 0, 0), f"the source was not clean: {final}")
    seen = node_check(h, out)
    check(seen["states"] >= 1000 and seen["sequence_breaks"] == 0,
          f"the file's states are not in publication order from the first on: {seen}")
    # The gateway's writer numbers its samples from 1, one per frame: sequence n is frame n - 1.
    node_check(h, out, "--frames", record, "--skip", seen["first_sequence"] - 1, "--prefix")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")

    port2 = free_udp_port()
    gateway2, stats2 = h.gateway("gateway2", "--listen", f"127.0.0.1:{port2}", "--topic", "replayed",
                                 "--status-topic", "replayed_status", "--expected-rate", "1000")
    wait_for_stats(stats2, lambda s: True, "the second gateway to start", timeout_s=60)  # listening
    status = h.run("replay", [h.binary("rsg_replay"), str(out), "--to", f"127.0.0.1:{port2}"])
    check(status == 0, f"rsg_replay exited {status}: {stderr_of(h, 'replay')}")
    wait_for_stats(stats2, lambda s: s["frames_received"] >= seen["states"], "the replayed frames")
    time.sleep(1.2)  # the next stats period: counters settled
    replayed = wait_for_stats(stats2, lambda s: True, "the second gateway's stats")
    print(f"[{h.name}] replayed {seen['states']} states: the second gateway received {replayed['frames_received']}, "
          f"lost {replayed['lost']}, duplicated {replayed['duplicated']}, reordered {replayed['reordered']}",
          flush=True)
    check((replayed["frames_received"], replayed["lost"], replayed["duplicated"], replayed["reordered"])
          == (seen["states"], 0, 0, 0), f"the replay is not the clean stream it recorded: {replayed}")
    check(h.stop("gateway2", gateway2) == 0, "the second gateway did not exit 0")


def no_writer(h):
    """A recorder that never matches a writer (here: the wrong partition) exits 1 and says why and
    what discovery shows instead, rather than exit 0 with an empty file."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--partition", "robot1")
    out = h.dir / "run.mcap"
    rec = recorder(h, "record", out, "--partition", "robot2", "--duration", "4")
    # A triggered recorder writes no file before an event: it says so, naming none.
    triggered = recorder(h, "record_trigger", h.dir / "trig.mcap", "--partition", "robot2", "--duration", "4",
                         "--trigger", "signal")
    status = h.wait("record", rec, 30)
    err = stderr_of(h, "record")
    check(status == 1, f"rsg_record exited {status} without a writer: {err}")
    check("no writer of 'robot_state' matched" in err and f"{out} holds no state" in err and "robot1" in err, err)
    status = h.wait("record_trigger", triggered, 30)
    err = stderr_of(h, "record_trigger")
    check(status == 1 and "no writer of 'robot_state' matched" in err and "no file was written" in err
          and "trig.mcap" not in err and not list(h.dir.glob("trig*")), f"--trigger without a writer: {status}: {err}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def restart(h):
    """A recorder restarted on the same --out (as compose's restart: on-failure does) never overwrites
    a file: the second run's files take new names, which sort after the first run's; retention
    counts both runs' files, removing the oldest first (the first run's), so that --max-files holds
    across the restart; a file of the directory that is not of the set stays. The same --out of a
    single file twice: the second recorder refuses to start rather than overwrite it."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    out = h.dir / "robot.mcap"
    flags = ["--split-size", "0.1", "--max-files", "3", "--chunk-size", "65536", "--status-topic", ""]
    # Not the recorder's: a name that only starts like the set's, and an older rsg's numbering.
    (h.dir / "robot_notes.mcap").write_bytes(b"notes")
    legacy = h.dir / "robot_7.mcap"
    legacy.write_bytes(b"an older rsg's file")
    first = recorder(h, "record1", out, *flags)
    wait_matched(h, stats, ["record1"], "rsg_record")
    run_sim(h, port, 1000, 1000)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 1000, "the first 1000 frames")
    time.sleep(1.0)
    check(h.stop("record1", first) == 0, f"the first recorder did not exit 0: {stderr_of(h, 'record1')}")
    run1 = set_files(h, "robot")
    stamps1 = {path.stem.rsplit("_", 1)[0] for path in run1}
    check(len(run1) == 3 and len(stamps1) == 1, f"the first run kept {[p.name for p in run1]}")
    check(not legacy.exists() and f"removed {legacy} (--max-files)" in stderr_of(h, "record1"),
          f"the older rsg's file of the set was not counted (removed first): {stderr_of(h, 'record1')}")
    before = {path: path.stat().st_ino for path in run1}

    second = recorder(h, "record2", out, *flags)
    wait_matched(h, stats, ["record2"], "rsg_record")
    check("3 earlier files of" in stderr_of(h, "record2"), f"the restart did not count the earlier files: "
          f"{stderr_of(h, 'record2')}")
    run_sim(h, port, 1000, 1000)
    wait_for_stats(stats, lambda s: s["frames_published"] >= 2000, "the next 1000 frames")
    time.sleep(1.0)
    check(h.stop("record2", second) == 0, f"the second recorder did not exit 0: {stderr_of(h, 'record2')}")
    after = set_files(h, "robot")
    names = [path.name for path in after]
    check(len(after) == 3, f"--max-files 3 across the restart left {names}")
    run2 = [path for path in after if path not in before]
    check(run2 and all(path.name > max(p.name for p in run1) for path in run2),
          f"the second run's files {[p.name for p in run2]} do not sort after the first's {[p.name for p in run1]}")
    for path in after:
        if path in before:
            check(path.stat().st_ino == before[path], f"{path.name} was rewritten")
    removed = [path for path in run1 if path not in after]
    check(removed and removed == run1[:len(removed)], f"retention removed {removed}, not the oldest of {run1}")
    for path in after:
        node_check(h, path)
    check((h.dir / "robot_notes.mcap").read_bytes() == b"notes", "a file not of the set was touched")
    print(f"[{h.name}] restart: first run {[p.name for p in run1]}, then {names}", flush=True)

    # One file, twice: the second refuses, the first stays as it was.
    single = h.dir / "single.mcap"
    status = h.run("single1", [h.binary("rsg_record"), "--domain", str(h.domain), "--out", str(single),
                               "--duration", "1", "--status-topic", ""])
    size = single.stat().st_size
    status = h.run("single2", [h.binary("rsg_record"), "--domain", str(h.domain), "--out", str(single),
                               "--duration", "1", "--status-topic", ""])
    err = stderr_of(h, "single2")
    check(status == 1 and "will not overwrite" in err and single.stat().st_size == size,
          f"a second recorder on {single.name}: exit {status}: {err}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def trigger_bounds(h):
    """Issue 51's attack on --trigger invalid: one 14-byte junk datagram every 1.5 s from an allowed
    address, beside the robot's stream, with `--pre 1 --post 2 --max-size 5 --max-files 3`. Each
    datagram extends the event, which grew past --max-size and was then removed by retention: no
    file left. Now an event is closed, and kept, at its own bound (--event-max-size, at most half of
    --max-size; --event-max-duration), the next trigger starts a new event, retention never removes
    the newest event, and the files together stay within --max-size.

    The control: a recorder without the bounds (--event-max-size and --event-max-duration large, no
    --max-size) records the same attack as one event extended by every datagram: the attack keeps an
    event open."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    bounded = recorder(h, "bounded", h.dir / "bounded.mcap", "--trigger", "invalid", "--pre", "1", "--post", "2",
                       "--max-size", "5", "--max-files", "3")
    open_ended = recorder(h, "open", h.dir / "open.mcap", "--trigger", "invalid", "--pre", "1", "--post", "2",
                          "--event-max-size", "10000", "--event-max-duration", "10000")
    wait_matched(h, stats, ["bounded", "open"], "rsg_record")
    # Every field in every frame (about 2 KB a message): the events reach their size bound in seconds.
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--duration", "16",
                          "--every", "1:all"])
    wait_for_stats(stats, lambda s: s["link_up"], "the robot's stream")
    junk = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sent = 0
    try:
        deadline = time.monotonic() + 12
        while time.monotonic() < deadline:
            junk.sendto(b"\x00" * 14, ("127.0.0.1", port))
            sent += 1
            time.sleep(1.5)
    finally:
        junk.close()
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    time.sleep(3.0)  # the last event's --post and the order's hold
    for label, process in (("bounded", bounded), ("open", open_ended)):
        check(h.stop(label, process) == 0, f"{label} did not exit 0: {stderr_of(h, label)}")
    final = read_json(stats)
    check(sum(final["invalid"].values()) >= sent - 1, f"the gateway counted {final['invalid']} of {sent} junk datagrams")

    err = stderr_of(h, "open")
    check("; 1 event (" in err and err.count("event 0 extended") >= 3,
          f"the control: the attack should keep one event open, extended by every datagram: {err[-1500:]}")
    err = stderr_of(h, "bounded")
    files = set_files(h, "bounded")
    sizes = [path.stat().st_size for path in files]
    check(files, f"the attack left no event file: {err[-1500:]}")
    check("closed at --event-max-size" in err, f"no event was closed at its bound: {err[-1500:]}")
    summary = re.search(r"; (\d+) events? \((\d+) triggers?\)", err)
    events = int(summary.group(1)) if summary else 0
    check(events >= 2, f"one event for the whole attack: {err[-1500:]}")
    # An event file ends at the first chunk (1 MiB) after its bound: 2.5 MB + a chunk.
    check(all(size <= 2_500_000 + 1_200_000 for size in sizes) and sum(sizes) <= 5_000_000 + 1_200_000,
          f"event files {dict(zip((p.name for p in files), sizes))}")
    for path in files:
        node_check(h, path)
    print(f"[{h.name}] {sent} junk datagrams: {events} events, kept {dict(zip((p.name for p in files), sizes))}; "
          f"the control kept one event open", flush=True)
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def retention(h):
    """--split-size with --max-files keeps the newest files, the rest removed oldest first, and what
    they hold is the end of the stream, exact; with --max-size the files together stay within the
    limit (and one file's overshoot: a file ends at the first chunk boundary after its size); with
    --max-age a file finished longer ago than that is removed while the recorder runs."""
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--split-size", "0.1", "--max-files", "3",
                                                           "--chunk-size", "65536")
    sized = h.dir / "sized.mcap"
    rec2 = recorder(h, "record_sized", sized, "--split-size", "0.1", "--max-size", "0.3", "--chunk-size", "65536",
                    "--status-topic", "")
    aged = h.dir / "aged.mcap"
    rec3 = recorder(h, "record_aged", aged, "--split-size", "0.1", "--max-age", "1", "--chunk-size", "65536",
                    "--status-topic", "")
    wait_matched(h, stats, ["record", "record_sized", "record_aged"], "rsg_record")
    count = 2000
    record = run_sim(h, port, count, 1000)
    wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway to publish every frame")
    time.sleep(1.5)
    check(h.stop("record", rec) == 0 and h.stop("record_sized", rec2) == 0 and h.stop("record_aged", rec3) == 0,
          "a recorder did not exit 0")
    # The first file was finished early in the stream, well over a second before the stop.
    aged_files = set_files(h, "aged")
    check(aged_files and index_of(aged_files[0]) > 0 and "_000000.mcap (--max-age)" in stderr_of(h, "record_aged"),
          f"--max-age 1 kept the first file: {aged_files}: {stderr_of(h, 'record_aged')}")
    files = set_files(h, "run")
    indexes = [index_of(path) for path in files]
    err = stderr_of(h, "record")
    check(len(files) == 3 and indexes == list(range(indexes[0], indexes[0] + 3)) and indexes[0] >= 3,
          f"--max-files 3 left {[path.name for path in files]}: {err}")
    first = str(files[0]).rsplit("_", 1)[0] + "_000000.mcap"
    check(f"removed {first} (--max-files)" in err and f"; {indexes[0]} oldest files removed" in err, err)
    kept = [node_check(h, path)["states"] for path in files]
    skip = count - sum(kept)
    for path, states in zip(files, kept):
        node_check(h, path, "--frames", record, "--skip", skip)
        skip += states
    sized_files = list(h.dir.glob("sized_*.mcap"))
    total = sum(path.stat().st_size for path in sized_files)
    print(f"[{h.name}] --max-files 3: {[path.name for path in files]}; --max-size 0.3: {len(sized_files)} files, "
          f"{total} bytes", flush=True)
    check(len(sized_files) >= 2 and total <= 300_000 + 100_000, f"--max-size 0.3 left {len(sized_files)} files of "
          f"{total} bytes: {stderr_of(h, 'record_sized')}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


def trigger(h):
    """--trigger: nothing is written before an event. SIGUSR1 writes the --pre seconds before it and
    the --post seconds after it to FILE_0.mcap, the frames exact and in order (another SIGUSR1 just
    after that event gets FILE_1.mcap, with its whole --pre window); the gateway's link going
    down is an event too (every flap of a loaded host's stream as well), the last file ending with the
    last frame, and so are invalid frames the gateway counted (here from rsg_flood, beside the
    stream); --trigger-buffer bounds the --pre window in memory (the file then starts later, with a
    warning)."""
    port, gateway, stats, rec, out = gateway_with_recorder(h, "--trigger", "signal", "--pre", "1", "--post", "1")
    down = recorder(h, "record_down", h.dir / "down.mcap", "--trigger", "link-down", "--pre", "1", "--post", "0.5")
    small = recorder(h, "record_small", h.dir / "small.mcap", "--trigger", "signal", "--pre", "5", "--post", "1",
                     "--trigger-buffer", "0.5", "--status-topic", "")
    # The gateway's status, once a second, says what it counted: the event comes up to a second after
    # the invalid frames, so --pre covers that second too.
    invalid = recorder(h, "record_invalid", h.dir / "invalid.mcap", "--trigger", "invalid", "--pre", "2", "--post",
                       "0.5")
    wait_matched(h, stats, ["record", "record_down", "record_small", "record_invalid"], "rsg_record")
    count, record = 5000, h.dir / "sim.record.jsonl"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", str(count),
                          "--record", str(record)])
    wait_for_stats(stats, lambda s: s["frames_published"] >= 2000, "2 s of the stream")
    early = [path for name in ("run", "small", "invalid") for path in h.dir.glob(f"{name}_*.mcap")]
    check(not early, f"a triggered recorder wrote before its event: {early}")
    rec.send_signal(signal.SIGUSR1)
    small.send_signal(signal.SIGUSR1)
    check(h.run("flood", [h.binary("rsg_flood"), "--to", f"127.0.0.1:{port}", "--count", "5", "--sizes", "10"]) == 0,
          "rsg_flood failed")
    # Another event right after one (the stream still running): its file has the whole --pre window
    # too, overlapping the first's.
    wait_for(lambda: "event 0 recorded" in stderr_of(h, "record"), "the file of the first SIGUSR1", timeout_s=20)
    rec.send_signal(signal.SIGUSR1)
    wait_for(lambda: all("event 0 recorded" in stderr_of(h, label) for label in ("record_small", "record_invalid")),
             "the files of the other SIGUSR1 and the invalid-frame events", timeout_s=20)
    wait_for(lambda: "event 1 recorded" in stderr_of(h, "record"), "the file of the second SIGUSR1", timeout_s=20)
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    wait_for_stats(stats, lambda s: not s["link_up"], "the gateway to see the link down")
    # Its status sample reaches the recorder, whose event ends --post (0.5 s) and the order's hold
    # (0.5 s) after it: by then every event it started is recorded.
    time.sleep(1.5)

    def events_recorded():
        err = stderr_of(h, "record_down")
        return err.count(", writing ") == err.count(" recorded: ") > 0
    wait_for(events_recorded, "the file of the link-down event", timeout_s=20)
    for label, process in (("record", rec), ("record_down", down), ("record_small", small),
                           ("record_invalid", invalid)):
        check(h.stop(label, process) == 0, f"{label} did not exit 0: {stderr_of(h, label)}")
    files = {stem: [index_of(path) for path in set_files(h, stem)] for stem in ("invalid", "run", "small")}
    check(files == {"invalid": [0], "run": [0, 1], "small": [0]} and len(list(h.dir.glob("*.mcap"))) == 4 +
          len(set_files(h, "down")), f"the events wrote {sorted(path.name for path in h.dir.glob('*.mcap'))}")
    check("; 2 events (2 triggers)" in stderr_of(h, "record"), stderr_of(h, "record"))

    def in_order(path, values=False):
        """Read by the reference reader: states in sequence order, and with `values` the frames sent."""
        seen = node_check(h, path)
        check(seen["states"] > 0 and seen["sequence_breaks"] == 0, f"{path.name}: {seen}")
        if values:
            node_check(h, path, "--frames", record, "--skip", seen["first_sequence"] - 1)
        return seen

    signalled = in_order(set_files(h, "run")[0], values=True)
    check(1500 <= signalled["states"] <= 2500 and signalled["statuses"] >= 1,
          f"--pre 1 --post 1 of a 1 kHz stream: {signalled}")
    again = in_order(set_files(h, "run")[1])
    check(again["states"] >= 800 and again["first_sequence"] < signalled["first_sequence"] + signalled["states"],
          f"the second event's file {again} after the first's {signalled}")
    downs = set_files(h, "down")
    last = in_order(downs[-1], values=True)
    check(last["first_sequence"] - 1 + last["states"] == count and last["statuses"] >= 1,
          f"the link-down event's file of a stream that stopped at frame {count}: {last}")
    check("the link went down: event 0" in stderr_of(h, "record_down"), stderr_of(h, "record_down"))
    flooded = in_order(set_files(h, "invalid")[0])
    err = stderr_of(h, "record_invalid")
    check("invalid frames: event 0" in err and "; 1 event (" in err and flooded["statuses"] >= 1,
          f"{flooded}: {err}")
    # Unbounded, 2 s before the event and 1 s after; 0.5 MB holds well under a second of full frames
    # (the last 0.5 s before the event wait in the publication-order hold, not in the window).
    bounded = in_order(set_files(h, "small")[0])
    err = stderr_of(h, "record_small")
    check(bounded["states"] < 2500 and "--trigger-buffer 0.5 MB holds" in err
          and "samples of the --pre window left out (--trigger-buffer)" in err, f"{bounded}: {err}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


CASES = {f.__name__: f for f in (reference_reader, sigkill, write_errors, replay_roundtrip, split_and_view, duration,
                                 ros2_profile, chunk_size_fsync, drain_on_sigterm, mid_stream_under_load, no_writer,
                                 retention, trigger, restart, trigger_bounds)}

if __name__ == "__main__":
    sys.exit(main(f"record_{CASE}", CASES[CASE]))
