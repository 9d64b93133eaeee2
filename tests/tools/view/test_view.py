"""rsg_view with real clients: rsg_sim -> rsg_gateway -> rsg_view, then npm's @foxglove/ws-protocol
client and Foxglove's CDR decoder (check_view.mjs), or Debian's headless Chromium on the page
(check_page.mjs). Each case is one ctest test (view.<case>), in its own DDS domain and ports.

    test_view.py --bin build/bin --case foxglove_legacy
"""

import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path


HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
from harness import check, free_tcp_port, free_udp_port, main, read_json_lines, wait_for, wait_for_stats, wait_reader_matched  # noqa: E402

CASE = sys.argv[sys.argv.index("--case") + 1]
del sys.argv[sys.argv.index("--case"):sys.argv.index("--case") + 2]
SCREENSHOT = None
if "--screenshot" in sys.argv:
    SCREENSHOT = sys.argv[sys.argv.index("--screenshot") + 1]
    del sys.argv[sys.argv.index("--screenshot"):sys.argv.index("--screenshot") + 2]
SELECTIONS = ["--every", "1:q,dq,time", "--every", "3:g0", "--every", "10:all"]


def node():
    """Node and the packages of tests/tools/view; fails the test (never skips) when they are missing."""
    path = shutil.which("node")
    check(path is not None, "node is not installed: run `make deps`")
    check((HERE / "node_modules" / "@foxglove" / "ws-protocol").is_dir(),
          "tests/tools/view/node_modules is missing: run `make deps` (npm ci --prefix tests/tools/view)")
    return path


def flatten(value, prefix=""):
    """{"invalid": {"bad_crc": 1}} -> {"invalid_bad_crc": 1}, as rsg_msgs/msg/GatewayStatus spells it."""
    out = {}
    for name, item in value.items():
        if isinstance(item, dict):
            out.update(flatten(item, f"{prefix}{name}_"))
        else:
            out[f"{prefix}{name}"] = item
    return out


def start_view(h, *flags, gateway_flags=()):
    """A gateway and an rsg_view matched to its writer; returns (udp port, gateway, stats, view, ws port)."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000", *gateway_flags)
    ws_port = free_tcp_port()
    view = h.start("view", [h.binary("rsg_view"), "--domain", str(h.domain), "--listen", f"127.0.0.1:{ws_port}",
                            *flags])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_view's reader to match the gateway's writer")
    wait_reader_matched(h, "view", "rsg_view")
    wait_for(lambda: "serving" in (h.dir / "view.err").read_text(), "rsg_view to listen")
    return port, gateway, stats, view, ws_port


def foxglove_client(h, subprotocol, *flags, count=600, rate=500, view_flags=(), gateway_flags=(), before_sim=None,
                    groups=0):
    """Every frame sent (of those carrying all `groups`, a bit mask, for a view) arrives through
    rsg_view, decoded by Foxglove's decoder to the values sent. `before_sim(ws_port)` runs once the
    client has subscribed."""
    port, gateway, stats, view, ws_port = start_view(h, *view_flags, gateway_flags=gateway_flags)
    # The frames SELECTIONS puts group 0 in (the only group a view here selects) or every group in.
    check(groups in (0, 1), f"groups {groups}")
    states = len([i for i in range(count) if not groups or i % 3 == 0 or i % 10 == 0])
    record = h.dir / "sim.record.jsonl"
    # The ros2msg channels exist when the build embedded rsg_msgs' .msg files (it does from this tree).
    msg_dir = ROOT / "ros2" / "rsg_msgs" / "msg"
    ros2 = ["--ros2", str(msg_dir)] if (msg_dir / "GatewayStatus.msg").exists() else []
    client = h.start("client", [node(), str(HERE / "check_view.mjs"), f"ws://127.0.0.1:{ws_port}", "--subprotocol",
                                subprotocol, "--count", str(states), "--sent", str(count), "--groups", str(groups),
                                "--frames", str(record), *ros2, *flags])
    wait_for(lambda: "ready" in h.output("client").read_text() or client.poll() is not None, "the client to subscribe")
    check(client.poll() is None, f"the client failed: {(h.dir / 'client.err').read_text()}")
    if before_sim:
        before_sim(ws_port)
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(rate), "--count", str(count),
                           "--record", str(record), *SELECTIONS])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("client", client, 60) == 0, f"check_view failed: {(h.dir / 'client.err').read_text()}")
    result = json.loads(h.output("client").read_text().splitlines()[-1])
    print(f"[{h.name}] client: {result}", flush=True)
    expected = "foxglove.sdk.v1" if subprotocol == "sdk" else "foxglove.websocket.v1"
    check(result["subprotocol"] == expected and result["states"] == states, f"client saw {result}")
    if ros2:
        # The last GatewayStatus, decoded from the ros2msg channel, holds the gateway's own counters
        # (its --stats-file; the nested invalid counts spelled out as in the .msg). Rate, link state
        # and the ingress delay of the current period (0 in a period without frames) change with
        # time, so they are left out: on a loaded host the link flaps and the last sample the client
        # saw is of an earlier period than the file (seen under ctest -j2).
        gateway_stats = flatten(wait_for_stats(stats, lambda s: s["frames_published"] >= count, "the gateway's stats"))
        status = result["last_status"]
        check(set(status) == set(gateway_stats), f"status members {sorted(status)} != stats {sorted(gateway_stats)}")
        for name, value in gateway_stats.items():
            check(name in ("rate_hz", "link_up", "ingress_delay_us") or status[name] == value,
                  f"GatewayStatus over ros2msg: {name} = {status[name]}, the gateway says {value}")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    return result


def foxglove_legacy(h):
    """npm's @foxglove/ws-protocol client (foxglove.websocket.v1); malformed requests get error
    statuses and the connection keeps working."""
    foxglove_client(h, "legacy", "--malformed")
    err = (h.dir / "view.err").read_text()
    check("malformed message: not JSON" in err, f"rsg_view did not log the malformed message: {err}")


def foxglove_sdk(h):
    """A client offering foxglove.sdk.v1 (the current Foxglove app) gets that subprotocol and the same
    data. It unsubscribes from /robot_state (ROS 2) after 200 samples: no message of that
    subscription arrives after the server's answer to its next request, while every sample keeps
    arriving on the IDL channel, and statuses too."""
    result = foxglove_client(h, "sdk", "--unsubscribe-after", "200")
    check(result["unsubscription"]["answered"] and result["ros2"] < result["states"], f"unsubscribe: {result}")


def view_and_partition(h):
    """rsg_view --partition robot1 --view view_poses, with a second gateway on partition robot2 on the
    same domain and topics, fed at the same time: the client gets exactly robot1's frames that carry
    group 0 (view_poses), decoded to the values sent, and no status of robot2's gateway (which counts
    more frames than robot1's)."""
    other_port = free_udp_port()
    other, other_stats = h.gateway("gateway_robot2", "--listen", f"127.0.0.1:{other_port}", "--expected-rate", "1000",
                                   "--partition", "robot2")
    wait_for_stats(other_stats, lambda s: True, "robot2's gateway to start")
    other_sim = {}

    def feed_robot2(ws_port):
        other_sim["process"] = h.start("sim_robot2", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{other_port}", "--rate",
                                                      "1000", "--count", "900", "--seed", "7", "--every", "1:g0"])

    foxglove_client(h, "legacy", view_flags=("--partition", "robot1", "--view", "view_poses"),
                    gateway_flags=("--partition", "robot1"), before_sim=feed_robot2, groups=1)
    check(h.wait("sim_robot2", other_sim["process"], 30) == 0, "robot2's rsg_sim failed")
    wait_for_stats(other_stats, lambda s: s["frames_published"] == 900, "robot2's gateway to publish its 900 frames")
    check(h.stop("gateway_robot2", other) == 0, "robot2's gateway did not exit 0")


def slow_client(h):
    """A client that stops reading loses its own oldest messages (the default --queue-depth, 256), is told
    how many in a warning status, and rsg_view logs it; a client reading at the same time gets every
    sample, and rsg_view's DDS reader misses none."""
    stalled = {}

    def start_stalled(ws_port):
        stalled["process"] = h.start("stalled", [node(), str(HERE / "stall_client.mjs"), f"ws://127.0.0.1:{ws_port}",
                                                 "4000"])
        wait_for(lambda: "ready" in h.output("stalled").read_text(), "the stalled client to subscribe")

    foxglove_client(h, "legacy", count=5000, rate=1000, before_sim=start_stalled)
    check(h.wait("stalled", stalled["process"], 60) == 0,
          f"the stalled client got no drop report: {(h.dir / 'stalled.err').read_text()}")
    report = json.loads(h.output("stalled").read_text().splitlines()[-1])
    print(f"[{h.name}] stalled client: {report}", flush=True)
    check(report["dropped"] > 0, f"nothing dropped for the stalled client: {report}")
    err = (h.dir / "view.err").read_text()
    check("messages: this connection reads slower than the data arrives" in err, f"rsg_view did not log the drops: {err}")
    check("received 5000 states" in err, f"rsg_view's reader missed samples: {err}")


def fair_share(h):
    """Big channels do not starve small ones: of two clients subscribed to every channel, one reads
    slowly (its socket left unread for 3 s at a time), so rsg_view drops RobotState messages for it.
    Counted against the other client, which reads everything: the slow one still gets every
    GatewayStatus (all three flavours), and the end-effector transform (a tenth of the frames carry
    O_T_EE) loses no larger a share than RobotState does. The drop report it gets and rsg_view's
    per-channel counters name the RobotState channels only."""
    stop = h.dir / "stop"
    clients = {}

    def start_clients(ws_port):
        for label, flags in (("reference", []), ("slow", ["--pause-ms", "3000", "--read-ms", "50"])):
            clients[label] = h.start(label, [node(), str(HERE / "fair_client.mjs"), f"ws://127.0.0.1:{ws_port}",
                                             "--stop", str(stop), *flags])
        for label in clients:
            wait_for(lambda: "ready" in h.output(label).read_text(), f"the {label} client to subscribe")

    port, gateway, stats, view, ws_port = start_view(h)
    start_clients(ws_port)
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "8000",
                           "--every", "1:q,dq,tau_J,time", "--every", "10:all"], timeout_s=60)
    check(status == 0, f"rsg_sim exited {status}")
    wait_for_stats(stats, lambda s: s["frames_published"] >= 8000, "the gateway to publish every frame")
    stop.touch()
    results = {}
    for label, process in clients.items():
        check(h.wait(label, process, 60) == 0, f"the {label} client failed: {(h.dir / f'{label}.err').read_text()}")
        results[label] = json.loads(h.output(label).read_text().splitlines()[-1])
        print(f"[{h.name}] {label} client: {results[label]}", flush=True)
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")

    reference, slow = results["reference"]["received"], results["slow"]["received"]
    share = {name: slow[name] / reference[name] for name in reference if reference[name] > 0}
    print(f"[{h.name}] share the slow client got: {share}", flush=True)
    states = [name for name in reference if "RobotState" in name]
    statuses = [name for name in reference if "GatewayStatus" in name]
    transform = next(name for name in reference if "FrameTransform" in name)
    # On a loaded machine even the reference may fall behind for a moment and lose a few.
    check(len(states) >= 1 and all(reference[name] >= 7600 for name in states),
          f"the reference client missed RobotState messages: {results['reference']}")
    check(all(share[name] < 0.9 for name in states), f"the slow client was not slow enough to lose RobotState: {share}")
    check(len(statuses) >= 2 and all(reference[name] >= 5 and slow[name] >= reference[name] - 1 for name in statuses),
          f"the slow client lost GatewayStatus messages: {slow} vs {reference}")
    check(reference[transform] >= 700 and share[transform] >= min(share[name] for name in states),
          f"the transform lost a larger share than RobotState: {share}")
    report = results["slow"]["drop_report"] or ""
    check(all(f"{name}: " in report for name in states) and "GatewayStatus" not in report,
          f"the slow client's drop report: {report!r}")
    # rsg_view's own per-channel counters, in its log at exit.
    counters = {f"{m[1]} ({m[2]})": int(m[3]) for m in
                re.finditer(r"channel \d+ (\S+) \((\S+), \w+\): published \d+, dropped (\d+)", (h.dir / "view.err").read_text())}
    check(all(counters[name] > 0 for name in states) and all(counters[name] == 0 for name in statuses),
          f"rsg_view's drop counters: {counters}")


def limits(h):
    """--max-clients refuses the client too many; a burst past 100 requests a second gets one error
    status; a client message over 64 KiB closes that connection (and is logged); HTTP refuses unknown
    paths, other methods than GET, and WebSocket upgrades without a Foxglove subprotocol."""
    port, gateway, stats, view, ws_port = start_view(h, "--max-clients", "1")
    status = h.run("limits", [node(), str(HERE / "limits_client.mjs"), f"127.0.0.1:{ws_port}"])
    check(status == 0, f"limits_client failed: {(h.dir / 'limits.err').read_text()}")
    result = json.loads(h.output("limits").read_text().splitlines()[-1])
    print(f"[{h.name}] {result}", flush=True)
    check(result["unknown_path"] == 404 and result["post"] == 405 and result["no_subprotocol"] == 400, f"HTTP: {result}")
    check(result["second_client"]["code"] == 1013 and result["second_client"]["reason"] == "too many clients",
          f"the second client was not refused: {result}")
    check(result["rate_errors"] == 1, f"rate limit: {result}")
    check(result["big_message"]["code"] != 1000, f"a 70 KiB message did not close the connection: {result}")
    err = (h.dir / "view.err").read_text()
    check("sent a message over 65536 bytes: closed" in err and "already 1 clients" in err, f"rsg_view's log: {err}")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


ATTACK = str(HERE / "attack_client.mjs")


def rss_kb(pid):
    with open(f"/proc/{pid}/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))


def cpu_s(pid):
    """User and system CPU seconds of a process so far."""
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def open_fds(pid):
    return len(os.listdir(f"/proc/{pid}/fd"))


def limit_counts(h, label="view"):
    """rsg_view's `limits:` line at exit, as {name: count}."""
    match = re.search(r"limits: (.*)", (h.dir / f"{label}.err").read_text())
    check(match is not None, f"{label} logged no limits line at exit")
    return {name: int(value) for name, value in (item.split() for item in match.group(1).split(", "))}


def legit_client(h, label, ws_port, count, timeout_ms):
    """A Foxglove client that subscribes to RobotState and must get `count` messages in time."""
    status = h.run(label, [node(), ATTACK, "legit", f"ws://127.0.0.1:{ws_port}/", str(count), str(timeout_ms)],
                   timeout_s=timeout_ms / 1000 + 15)
    check(status == 0, f"the legitimate client got no data: {(h.dir / f'{label}.err').read_text()}")
    result = json.loads(h.output(label).read_text().splitlines()[-1])
    print(f"[{h.name}] {label}: {count} messages in {result['ms']} ms", flush=True)


def attack_subscriptions(h):
    """One client sends 40 subscribe requests of 1,024 subscriptions each while rsg_sim streams at
    1 kHz: rsg_view keeps --max-subscriptions (16) of them, answers each request with one error
    status, counts the 40,944 it refused and logs the limit once; a legitimate client subscribed
    meanwhile gets its messages; and once the attacker left, rsg_view's memory is back within 8 MB
    of what it was."""
    port, gateway, stats, view, ws_port = start_view(h)
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "60000"])
    legit_client(h, "warmup", ws_port, 500, 15000)  # the baseline holds a client's allocations too
    rss_before, cpu_before, start = rss_kb(view.pid), cpu_s(view.pid), time.monotonic()
    attacker = h.start("attacker", [node(), ATTACK, "subscribe", f"ws://127.0.0.1:{ws_port}/", "40", "1024", "5000"])
    time.sleep(1.0)
    rss_during = rss_kb(view.pid)
    legit_client(h, "legit", ws_port, 1000, 10000)
    check(h.wait("attacker", attacker, 30) == 0, f"the attacker failed: {(h.dir / 'attacker.err').read_text()}")
    cpu = (cpu_s(view.pid) - cpu_before) / (time.monotonic() - start)
    result = json.loads(h.output("attacker").read_text().splitlines()[-1])
    time.sleep(2.0)
    rss_after = rss_kb(view.pid)
    print(f"[{h.name}] attacker: {result}; rsg_view CPU {cpu:.0%} of a core during the attack; "
          f"RSS {rss_before} kB before, {rss_during} kB during, {rss_after} kB after", flush=True)
    check(h.stop("sim", sim) == 0, "rsg_sim did not exit 0 on SIGTERM")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    check(result["errors"] == 40, f"one error status per refused request expected: {result}")
    counts = limit_counts(h)
    check(counts["subscriptions"] == 40 * 1024 - 16, f"subscriptions refused: {counts}")
    check((h.dir / "view.err").read_text().count("limit subscriptions:") == 1, "the limit was not logged once")
    check(rss_after - rss_before < 8 * 1024, f"rsg_view's memory did not come back: {rss_before} -> {rss_after} kB")


def attack_idle_clients(h):
    """16 WebSocket clients from 16 addresses connect and subscribe to nothing (answering pings):
    they take every place of --max-clients 16, yet a legitimate client arriving after them gets its
    data (the longest idle one makes room: counted as `clients`), and with --idle-timeout 4 every
    idle one is closed 4 s after it connected (counted as `idle_timeout`)."""
    port, gateway, stats, view, ws_port = start_view(h, "--idle-timeout", "4")
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "60000"])
    idle = h.start("idle", [node(), ATTACK, "idle", f"ws://127.0.0.1:{ws_port}/", "16", "127.0.0.30", "9000"])
    time.sleep(2.5)  # connected, and idle for longer than the grace a new client gets
    legit_client(h, "legit", ws_port, 200, 5000)
    check(h.wait("idle", idle, 30) == 0, f"the idle clients failed: {(h.dir / 'idle.err').read_text()}")
    result = json.loads(h.output("idle").read_text().splitlines()[-1])
    print(f"[{h.name}] idle clients: {result}", flush=True)
    check(h.stop("sim", sim) == 0, "rsg_sim did not exit 0 on SIGTERM")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    check(result["opened"] == 16 and result["closed_by_server"] == 16, f"idle clients: {result}")
    counts = limit_counts(h)
    check(counts["clients"] >= 1 and counts["idle_timeout"] >= 15, f"limits: {counts}")


def attack_chatty_clients(h):
    """Issue 51: 16 WebSocket clients from 2 addresses (127.0.0.2, .3) that subscribe to nothing and
    send a 40-byte message every 0.5 s, each renewed as rsg_view closes or refuses it, for 30 s. What
    a client sends never makes it less idle, and an address holds at most --max-clients-per-address
    (4) clients, so two addresses hold at most 8 of --max-clients (16). Once they are past the grace
    a new client has to subscribe (Server::kSubscribeGrace, 10 s), 12 legitimate Foxglove clients
    from 12 other addresses arrive 0.5 s apart, each subscribing 2 s after it connected (a person
    picking topics): every one gets its 8,000 messages and none is closed -- a client within
    its grace or with a subscription never makes room, the chatty idle ones do. The control that
    shows the attack is real: the chatty clients held places (at least 8 open at once) and asked for
    more than the per-address cap allows (`clients_per_address` counted); and the legitimate
    clients past the first 8 could only be served by closing chatty ones (`clients` counted).
    Before: every legitimate client refused "too many clients", and one that subscribed 2 s after
    connecting was evicted."""
    port, gateway, stats, view, ws_port = start_view(h)
    url = f"ws://127.0.0.1:{ws_port}/"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "90000"])
    chatty = h.start("chatty", [node(), ATTACK, "chatty", url, "16", "2", "127.0.0.2", "32000"])
    time.sleep(11.0)  # past the grace: the chatty clients are idle now, whatever they send
    late = []
    for i in range(12):
        # 8,000 messages (the two RobotState channels at 1 kHz: 4 s): the twelve overlap, so that
        # the last ones find every place taken.
        late.append(h.start(f"late{i}", [node(), ATTACK, "late", url, f"127.0.0.{10 + i}", "2000", "8000", "20000"]))
        time.sleep(0.5)
    for i, client in enumerate(late):
        check(h.wait(f"late{i}", client, 30) == 0,
              f"legitimate client {i} (subscribing after 2 s) was not served: {(h.dir / f'late{i}.err').read_text()}")
    check(h.wait("chatty", chatty, 40) == 0, f"the chatty clients failed: {(h.dir / 'chatty.err').read_text()}")
    result = json.loads(h.output("chatty").read_text().splitlines()[-1])
    print(f"[{h.name}] chatty clients: {result}", flush=True)
    check(h.stop("sim", sim) == 0, "rsg_sim did not exit 0 on SIGTERM")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    counts = limit_counts(h)
    print(f"[{h.name}] limits: {counts}", flush=True)
    check(result["opened"] >= 8, f"the attack did not hold its places: {result}")
    check(counts["clients_per_address"] > 0 and counts["clients"] > 0, f"limits: {counts}")


def attack_tcp(h):
    """1,100 TCP connections that never send a byte, from 10 addresses, and 100 from one of them, each
    renewed as soon as rsg_view closes it, for 8 s: rsg_view never holds more than --max-connections (64) of them, a
    legitimate client gets its data meanwhile, and the limits are counted. Then a second rsg_view,
    whose --max-connections is past its fd limit (prlimit --nofile 64): accept fails with EMFILE and
    it backs off instead of spinning (under a third of a core), counted as `accept_failures`."""
    port, gateway, stats, view, ws_port = start_view(h)
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "60000"])
    fds_before, cpu_before, start = open_fds(view.pid), cpu_s(view.pid), time.monotonic()
    attacker = h.start("attacker", [node(), ATTACK, "tcp", "127.0.0.1", str(ws_port), "1100", "10", "8000"])
    # ... and 100 more from one of those addresses: past the per-address limit (8) whatever the order
    # in which the others arrive (spread evenly, ten addresses can share 64 slots without any of them
    # holding 8).
    crowd = h.start("crowd", [node(), ATTACK, "tcp", "127.0.0.1", str(ws_port), "100", "1", "8000"])
    time.sleep(2.0)
    fds_during = 0
    for _ in range(20):
        fds_during = max(fds_during, open_fds(view.pid))
        time.sleep(0.05)
    legit_client(h, "legit", ws_port, 200, 5000)
    check(h.wait("attacker", attacker, 30) == 0, f"the attacker failed: {(h.dir / 'attacker.err').read_text()}")
    check(h.wait("crowd", crowd, 30) == 0, f"the one-address attacker failed: {(h.dir / 'crowd.err').read_text()}")
    cpu = (cpu_s(view.pid) - cpu_before) / (time.monotonic() - start)
    result = json.loads(h.output("attacker").read_text().splitlines()[-1])
    print(f"[{h.name}] attacker: {result}; rsg_view fds {fds_before} before, {fds_during} at most during; "
          f"CPU {cpu:.0%} of a core", flush=True)
    check(fds_during <= fds_before + 64 + 2, f"rsg_view held {fds_during - fds_before} connections")

    # The fd limit itself: rsg_view with its own cap set past it.
    other_port = free_tcp_port()
    other = h.start("view_fds", ["prlimit", "--nofile=64:64", h.binary("rsg_view"), "--domain", str(h.domain),
                                 "--listen", f"127.0.0.1:{other_port}", "--max-connections", "1000",
                                 "--max-connections-per-address", "1000"])
    wait_for(lambda: "serving" in (h.dir / "view_fds.err").read_text(), "the second rsg_view to listen")
    flood = h.start("flood", [node(), ATTACK, "tcp", "127.0.0.1", str(other_port), "300", "20", "5000"])
    time.sleep(1.5)
    cpu_before, start = cpu_s(other.pid), time.monotonic()
    time.sleep(3.0)
    other_cpu = (cpu_s(other.pid) - cpu_before) / (time.monotonic() - start)
    check(h.wait("flood", flood, 30) == 0, f"the flood failed: {(h.dir / 'flood.err').read_text()}")
    print(f"[{h.name}] at the fd limit: rsg_view CPU {other_cpu:.0%} of a core", flush=True)
    check(h.stop("view_fds", other) == 0, "the second rsg_view did not exit 0 on SIGTERM")
    check(h.stop("sim", sim) == 0, "rsg_sim did not exit 0 on SIGTERM")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    counts = limit_counts(h)
    check(counts["connections"] > 0 and counts["per_address"] > 0, f"limits: {counts}")
    check(other_cpu < 0.34, f"rsg_view spins at the fd limit: {other_cpu:.0%} of a core")
    check(limit_counts(h, "view_fds")["accept_failures"] > 0, "accept never failed: was the fd limit reached?")


def page(h):
    """Debian's headless Chromium loads the page while rsg_sim runs: the page shows live samples, the
    last q it shows is one rsg_sim sent, Chart.js plots them, and the gateway panel says the link is up."""
    chromium = shutil.which("chromium")
    check(chromium is not None, "chromium is not installed: run `make deps`")
    screenshot = Path(SCREENSHOT) if SCREENSHOT else h.dir / "rsg_view.png"
    port, gateway, stats, view, ws_port = start_view(h)
    record = h.dir / "sim.record.jsonl"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "60000",
                          "--record", str(record)])
    devtools = free_tcp_port()
    h.start("chromium", [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                         f"--user-data-dir={h.dir / 'chromium'}", f"--remote-debugging-port={devtools}",
                         "about:blank"])
    status = h.run("page", [node(), str(HERE / "check_page.mjs"), str(devtools), f"http://127.0.0.1:{ws_port}/",
                            str(screenshot)], timeout_s=60)
    check(status == 0, f"check_page failed: {(h.dir / 'page.err').read_text()}")
    shown = json.loads(h.output("page").read_text().splitlines()[-1])
    print(f"[{h.name}] the page showed {shown}; screenshot {screenshot}", flush=True)
    check(h.stop("sim", sim) == 0, "rsg_sim did not exit 0 on SIGTERM")
    sent = {", ".join(f"{v:.4f}" for v in frame["fields"]["q"]) for frame in read_json_lines(record)
            if "q" in frame["fields"]}
    check(shown["last_q"] in sent, f"the page shows q = {shown['last_q']}, which rsg_sim never sent")
    check(shown["chart_js"] and shown["q_points"] >= 50, f"Chart.js did not plot: {shown}")
    check(h.stop("view", view) == 0, "rsg_view did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


if __name__ == "__main__":
    sys.exit(main(f"view.{CASE}", globals()[CASE]))
