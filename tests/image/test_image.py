"""The image, run by a real engine: every tool in its own container, on the host network, talking
over loopback and the host's /dev/shm (what docker/compose.yaml sets).

  pipeline      rsg_sim -> rsg_gateway -> rsg_echo --json and rsg_record: every frame exact at the
                echo, the MCAP file read by the reference reader (tests/tools/record/check_recording.mjs)
                to the values sent
  health        the image's HEALTHCHECK (GET /livez on the gateway's metrics port): healthy
                before, while and after rsg_sim streams, unhealthy while the gateway is frozen
                (SIGSTOP), healthy again after; healthy in a container of another tool
  view_and_restart
                rsg_view serves its page to Debian's headless Chromium on the host
                (tests/tools/view/check_page.mjs): live samples rsg_sim sent, plotted by Chart.js; then
                the gateway container killed (`ENGINE kill`) and run again, as `restart: on-failure`
                would, then its process killed from the host (a crash, the Fast DDS 2.9.1 abort's
                effect) and restarted by the engine itself: the running echo and recorder resume,
                and every sample the echo printed is one rsg_sim sent, in order
  ros2_type_hash
                the image's gateway run with --ros2 and the standard topics, read by a
                ROS 2 Jazzy rclpy node (make deps' ROS 2 environment on the host): rosidl's RIHS01 type
                hash, as Jazzy's rosidl computes it, on each of its five ROS 2 writers
  dds_attacks   the image's gateway at 500 Hz with a reader, then the Fast DDS attacks of
                tests/support/dds_attacks.py from the host (the 84-byte statistics datagram on every
                port of the domain, two readers of the image on a unicast and a multicast locator,
                3,000 random RTPS datagrams): it keeps running and publishing, every reader gets its
                samples, rsg_dds_guard_total counts what its guard did; then every published Fast
                DDS flaw of tests/support/fastdds_flaws.py, unicast and to the discovery multicast
                group (integration.fastdds_flaws has their controls): it keeps publishing, the
                reader keeps its samples, and a reader started after them gets samples
  compose       docker/compose.yaml's services, run as the file says (docker compose with Docker;
                with podman by compose_up, as Debian 12's podman-compose cannot run the file): the
                gateway healthy, the echo's samples, the page on RSG_VIEW_PORT, the recording in the
                volume read by the reference reader

    tests/image/run.sh          # builds the image first (make test-image)
    test_image.py --engine "podman --runtime runc" --image rsg [--case NAME]
"""

import argparse
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tests" / "support"))
from harness import (TestFailure, check, free_tcp_port, free_udp_port, read_json_lines, wait_for, wait_for_stats,  # noqa: E402
                     wait_reader_matched)
from metrics_support import http_get, parse_samples, value_of  # noqa: E402
from dds_attacks import (TWO_LOCATORS_PROFILE, TWO_LOCATORS_XML, guard_counts, one_datagram,  # noqa: E402
                         random_datagrams, send_to_domain)
from fastdds_flaws import attack_every  # noqa: E402

# Where the image installs rsg's XML profiles (docker/Dockerfile: prefix /opt/rsg).
IMAGE_PROFILES = "/opt/rsg/share/rsg/xml_profiles"
SELECTIONS = ["--every", "1:q,dq,time", "--every", "3:g0", "--every", "10:all"]
COUNT = 1000
# Inside the image: the entrypoint's stats file (the HEALTHCHECK reads it) and where tests mount.
STATS_DIR, DATA = "/run/rsg", "/data"
IMAGE_UID = 10001  # the image's user (docker/Dockerfile)


class Containers:
    """The containers of one run: each started attached (`ENGINE run --rm`), its stdout and stderr
    in LABEL.out / LABEL.err of the scratch directory, removed at the end whatever happened."""

    def __init__(self, engine, image, case):
        self.engine = shlex.split(engine)
        self.name = "podman" if "podman" in self.engine[0] else "docker"
        self.image = image
        self.dir = Path(tempfile.mkdtemp(prefix="rsg_image_"))
        self.data = self.dir / "data"  # mounted at /data: the containers' user (uid 10001) writes there
        self.data.mkdir()
        self.stats_dir = self.dir / "gateway"  # mounted over /run/rsg: the gateway's stats file
        self.stats_dir.mkdir()
        for path in (self.data, self.stats_dir):
            path.chmod(0o777)
        self.stats = self.stats_dir / "gateway-stats.json"
        # The entrypoint's --metrics 127.0.0.1:$RSG_METRICS_PORT, where the HEALTHCHECK asks /livez:
        # a port of this run (the host network is shared with every other test's gateways).
        self.metrics_port = free_tcp_port()
        # Domains 210-233: none of ctest's (tests/support/test_domain.py: 20-99), one per case, so that no
        # other test's gateway and no earlier case's writer is matched.
        self.domain = 210 + os.getpid() % 3 * 8 + sorted(CASES).index(case)
        self.prefix = f"rsg-image-test-{os.getpid()}-{case.replace('_', '-')}"
        self.processes = {}
        self.names = set()
        self.started = time.time()

    def container(self, label):
        return f"{self.prefix}-{label}"

    def engine_run(self, *args, timeout_s=60, check_status=True):
        result = subprocess.run([*self.engine, *args], capture_output=True, text=True, timeout=timeout_s)
        if check_status:
            check(result.returncode == 0, f"{self.name} {' '.join(args)}: {result.stderr.strip()}")
        return result

    def start(self, label, *argv, entrypoint=None, mounts=()):
        """Starts `argv` in a container of the image (the gateway's entrypoint unless `entrypoint`)."""
        name = self.container(label)
        command = [*self.engine, "run", "--rm", "--name", name, "--network", "host", "--ipc", "host",
                   "-e", f"RSG_METRICS_PORT={self.metrics_port}",
                   "-v", f"{self.data}:{DATA}", *[arg for mount in mounts for arg in ("-v", mount)]]
        if entrypoint:
            command += ["--entrypoint", entrypoint]
        command += [self.image, *map(str, argv)]
        print(f"[image] start {label}: {' '.join(command)}", flush=True)
        out = open(self.dir / f"{label}.out", "ab")
        err = open(self.dir / f"{label}.err", "ab")
        self.processes[label] = subprocess.Popen(command, stdout=out, stderr=err)
        self.names.add(name)
        return self.processes[label]

    def gateway(self, port, label="gateway"):
        return self.start(label, *self.gateway_args(port), mounts=[f"{self.stats_dir}:{STATS_DIR}"])

    def gateway_args(self, port):
        return ["--listen", f"127.0.0.1:{port}", "--domain", self.domain, "--expected-rate", "500"]

    def detached_gateway(self, label, port):
        """The gateway as compose runs it: detached, `--restart on-failure`."""
        name = self.container(label)
        self.names.add(name)
        self.engine_run("run", "-d", "--name", name, "--restart", "on-failure", "--network", "host", "--ipc", "host",
                        "-e", f"RSG_METRICS_PORT={self.metrics_port}", "-v", f"{self.stats_dir}:{STATS_DIR}", self.image, *map(str, self.gateway_args(port)))
        return name

    def inspect(self, name, template):
        return self.engine_run("inspect", "--format", template, name).stdout.strip()

    def wait(self, label, timeout_s=60):
        try:
            return self.processes[label].wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            raise TestFailure(f"the {label} container did not exit within {timeout_s} s")

    def stop(self, label, timeout_s=30):
        """`ENGINE stop`: SIGTERM to the tool, as an operator's; returns the tool's exit status."""
        self.engine_run("stop", "-t", str(timeout_s), self.container(label), timeout_s=timeout_s + 30)
        return self.wait(label)

    def output(self, label):
        return self.dir / f"{label}.out"

    def stderr(self, label):
        path = self.dir / f"{label}.err"
        return path.read_text(errors="replace") if path.exists() else ""

    def cleanup(self, keep):
        remove_containers(self.engine, self.names)
        # What killed processes left in the host's /dev/shm (--ipc host): files of the image's user
        # made during this run.
        for path in Path("/dev/shm").glob("fast*"):
            try:
                info = path.stat()
                if info.st_uid == IMAGE_UID and info.st_mtime >= self.started - 1:
                    path.unlink()
            except OSError:
                pass
        for process in self.processes.values():
            if process.poll() is None:
                process.kill()
                process.wait()
        subprocess.run(["fastdds", "shm", "clean"], capture_output=True)
        if not keep:
            shutil.rmtree(self.dir, ignore_errors=True)

    def dump_logs(self):
        print(f"(outputs are in {self.dir})")
        for label in self.processes:
            lines = self.stderr(label).splitlines()
            if lines:
                print(f"--- {label}.err (last 20 lines)")
                print("\n".join(line[:300] for line in lines[-20:]))


def remove_containers(engine, names):
    """Stops (SIGTERM first: a tool stopped cleanly removes its segments from /dev/shm) and removes
    the containers, one engine call each: a call naming a container that is gone already (`run
    --rm`) fails whole, leaving the others running."""
    stops = [subprocess.Popen([*engine, "stop", "-t", "10", name], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL) for name in names]
    for stop in stops:
        stop.wait()
    for name in names:
        subprocess.run([*engine, "rm", "-f", name], capture_output=True)


def node(script, *args, timeout_s=90):
    """Runs one of the project's Node checks; fails (never skips) when Node or its packages are missing."""
    folder = (ROOT / script).parent
    check(shutil.which("node") is not None, "node is not installed: run `make deps`")
    check((folder / "node_modules").is_dir(), f"{folder.relative_to(ROOT)}/node_modules is missing: run `make deps`")
    result = subprocess.run(["node", str(ROOT / script), *map(str, args)], capture_output=True, text=True,
                            timeout=timeout_s)
    check(result.returncode == 0, f"{script}: {result.stderr.strip()} {result.stdout.strip()}")
    return json.loads(result.stdout.strip().splitlines()[-1])


def healthy(c, container):
    """The image's HEALTHCHECK on a running container: podman runs it on demand (its timer needs
    systemd), Docker runs it itself and reports the state."""
    if c.name == "podman":
        return c.engine_run("healthcheck", "run", container, check_status=False).returncode == 0
    state = c.engine_run("inspect", "--format", "{{.State.Health.Status}}", container, check_status=False)
    return state.stdout.strip() == "healthy"


def is_subsequence(items, sequence):
    it = iter(sequence)
    return all(any(item == candidate for candidate in it) for item in items)


def pipeline(c):
    port = free_udp_port()
    c.gateway(port)
    wait_for_stats(c.stats, lambda s: True, "the gateway container to start", timeout_s=60)
    c.start("echo", "--domain", c.domain, "--json", "--count", COUNT, "--timeout", "90", entrypoint="rsg_echo")
    c.start("record", "--domain", c.domain, "--out", f"{DATA}/pipeline.mcap", entrypoint="rsg_record")
    wait_for_stats(c.stats, lambda s: s["state_readers"] >= 2, "2 readers to match the gateway", timeout_s=60)
    wait_reader_matched(c, "echo", "rsg_echo")
    wait_reader_matched(c, "record", "rsg_record")
    c.start("sim", "--to", f"127.0.0.1:{port}", "--rate", "500", "--count", COUNT, *SELECTIONS,
            "--record", f"{DATA}/sim.jsonl", entrypoint="rsg_sim")
    check(c.wait("sim") == 0, f"rsg_sim exited non-zero: {c.stderr('sim')}")
    check(c.wait("echo", 90) == 0, f"rsg_echo did not receive every sample: {c.stderr('echo')[-500:]}")

    sent = read_json_lines(c.data / "sim.jsonl")
    received = read_json_lines(c.output("echo"))
    check(len(sent) == COUNT, f"rsg_sim recorded {len(sent)} frames, not {COUNT}")
    check(len(received) == COUNT, f"rsg_echo printed {len(received)} samples for {COUNT} frames")
    for index, (expected, actual) in enumerate(zip(sent, received)):
        check(actual == expected, f"sample {index} differs from the frame sent:\n  sent {expected}\n  got  {actual}")
    stats = wait_for_stats(c.stats, lambda s: s["frames_published"] >= COUNT, "the gateway to publish every frame")
    check((stats["frames_received"], stats["lost"], sum(stats["invalid"].values())) == (COUNT, 0, 0),
          f"gateway counters: {stats}")

    time.sleep(1.5)  # the last samples and a status sample reach the recorder
    check(c.stop("record") == 0, f"rsg_record did not exit 0 on SIGTERM: {c.stderr('record')}")
    check("dropped 0 (sequence gaps), 0 (lost in DDS)" in c.stderr("record"), c.stderr("record"))
    seen = node("tests/tools/record/check_recording.mjs", c.data / "pipeline.mcap", "--frames", c.data / "sim.jsonl")
    check(seen["states"] == COUNT and seen["statuses"] >= 1, f"the reference reader read {seen}")
    print(f"[image] pipeline: {COUNT} frames exact at rsg_echo and in the MCAP file ({seen})", flush=True)


def health(c):
    """The HEALTHCHECK follows /livez, the process's liveness: healthy whether the robot streams or
    not (before, during, after), unhealthy while the gateway is frozen (SIGSTOP: its loop hands over
    no snapshot, and the check's read times out), healthy again once it goes on. With podman each
    check is run on demand (`podman healthcheck run`); Docker runs it every 10 s and says unhealthy
    after 3 failures, so there the waits are longer but the states the same."""
    port = free_udp_port()
    c.gateway(port)
    wait_for_stats(c.stats, lambda s: True, "the gateway container to start", timeout_s=60)
    gateway = c.container("gateway")
    wait_for(lambda: healthy(c, gateway), "the HEALTHCHECK to pass before the robot sent a frame", timeout_s=60,
             interval_s=1)
    c.start("sim", "--to", f"127.0.0.1:{port}", "--rate", "500", "--duration", "120", entrypoint="rsg_sim")
    wait_for_stats(c.stats, lambda s: s["frames_published"] > 0, "the gateway to publish", timeout_s=60)
    check(healthy(c, gateway) or c.name != "podman", "unhealthy while rsg_sim streams")
    check(c.stop("sim") == 0, f"rsg_sim did not exit 0 on SIGTERM: {c.stderr('sim')}")
    check(healthy(c, gateway) or c.name != "podman", "unhealthy once the robot stopped: a liveness check must not care")
    c.engine_run("kill", "--signal", "STOP", gateway)
    try:
        wait_for(lambda: not healthy(c, gateway), "the HEALTHCHECK to fail while the gateway is frozen", timeout_s=60,
                 interval_s=1)
    finally:
        c.engine_run("kill", "--signal", "CONT", gateway)
    wait_for(lambda: healthy(c, gateway), "the HEALTHCHECK to pass once the gateway goes on", timeout_s=60,
             interval_s=1)
    # A container of another tool runs no gateway: healthy.
    c.start("echo", "--domain", c.domain, entrypoint="rsg_echo")
    wait_for(lambda: healthy(c, c.container("echo")), "the HEALTHCHECK to pass in a container without a gateway",
             timeout_s=60, interval_s=1)
    print("[image] health: healthy before, while and after the robot streams, unhealthy while the gateway is "
          "frozen, healthy again after; healthy without a gateway", flush=True)


def dds_attacks(c):
    port = free_udp_port()
    gateway = c.gateway(port)
    wait_for_stats(c.stats, lambda s: True, "the gateway container to start", timeout_s=60)
    c.start("sim", "--to", f"127.0.0.1:{port}", "--rate", "500", "--duration", "120", entrypoint="rsg_sim")
    plain = c.start("plain", "--domain", c.domain, "--json", "--timeout", "120", entrypoint="rsg_echo")
    wait_for_stats(c.stats, lambda s: s["state_readers"] >= 1 and s["frames_published"] > 500,
                   "a reader to match and frames to be published", timeout_s=60)

    def alive_and_publishing(what):
        check(gateway.poll() is None, f"the gateway container ended after {what}: {c.stderr('gateway')[-800:]}")
        before = json.loads(c.stats.read_text())["frames_published"]
        wait_for_stats(c.stats, lambda s: s["frames_published"] >= before + 500,
                       f"the gateway to publish after {what}", timeout_s=30)

    def guard():
        reply = http_get(c.metrics_port, "/metrics")
        check(reply is not None and reply[0] == 200, f"/metrics did not answer: {reply}")
        return guard_counts(parse_samples(reply[1]), value_of)

    send_to_domain(int(c.domain), [one_datagram()] * 3)
    time.sleep(0.5)
    alive_and_publishing("the 84-byte statistics datagram")
    wait_for(lambda: guard()["statistics_misplaced"] >= 1,
             "rsg_dds_guard_total to count the misplaced statistics submessage", timeout_s=30)

    (c.data / "two_locators.xml").write_text(TWO_LOCATORS_XML)
    for i in range(3):  # side by side: the second one to match is the one Fast DDS sends to unopened
        c.start(f"two_locators{i}", "--domain", c.domain, "--json", "--count", "1000", "--timeout", "60",
                "--profiles", IMAGE_PROFILES, "--profiles", f"{DATA}/two_locators.xml",
                "--participant-profile", TWO_LOCATORS_PROFILE, entrypoint="rsg_echo")
        time.sleep(0.7)
    for i in range(3):
        check(c.wait(f"two_locators{i}", 90) == 0,
              f"reader {i} on two locators did not get 1000 samples: {c.stderr(f'two_locators{i}')[-500:]}")
    alive_and_publishing("two readers on a unicast and a multicast locator")
    wait_for(lambda: guard()["send_channel_opened"] >= 1, "rsg_dds_guard_total to count the opened send channel",
             timeout_s=30)

    send_to_domain(int(c.domain), random_datagrams(3000))
    time.sleep(0.5)
    alive_and_publishing("3,000 random RTPS datagrams")
    check(plain.poll() is None, f"the plain reader ended: {c.stderr('plain')[-500:]}")
    print(f"[image] dds_attacks: the gateway kept publishing; guard {guard()}", flush=True)

    # The published Fast DDS flaws (issue 46), each unicast and multicast.
    def still_running(what):
        check(gateway.poll() is None, f"the gateway container ended after {what}: {c.stderr('gateway')[-800:]}")
        check(plain.poll() is None, f"the plain reader ended after {what}: {c.stderr('plain')[-500:]}")
    samples = c.output("plain").read_text(errors="replace").count("\n")
    sent = attack_every(int(c.domain), still_running)
    alive_and_publishing("the published Fast DDS flaws")
    wait_for(lambda: c.output("plain").read_text(errors="replace").count("\n") >= samples + 500,
             "the plain reader to get 500 more samples after the published Fast DDS flaws", timeout_s=30)
    c.start("late", "--domain", c.domain, "--json", "--count", "200", "--timeout", "30", entrypoint="rsg_echo")
    check(c.wait("late", 60) == 0, f"a reader started after the published Fast DDS flaws did not get 200 samples: "
          f"{c.stderr('late')[-500:]}")
    print(f"[image] dds_attacks: the published Fast DDS flaws ({sent} datagrams): the gateway kept publishing, "
          "the reader its samples, a reader started after them got 200", flush=True)


def view_and_restart(c):
    """One gateway, a streaming rsg_sim, and long-running readers: the page first, then the kill."""
    port = free_udp_port()
    c.gateway(port)
    wait_for_stats(c.stats, lambda s: True, "the gateway container to start", timeout_s=60)
    ws_port = free_tcp_port()
    c.start("view", "--domain", c.domain, "--listen", f"127.0.0.1:{ws_port}", entrypoint="rsg_view")
    # The echo, a monitor that outlives gateway kills, uses no data-sharing (docs/operating.md: a
    # writer killed while notifying a data-sharing reader can leave that reader's mutex locked); the
    # recorder keeps its reliable default, as compose.yaml runs it.
    c.start("echo2", "--domain", c.domain, "--json", "--qos", "reader_realtime_udp", entrypoint="rsg_echo")
    c.start("record2", "--domain", c.domain, "--out", f"{DATA}/restart.mcap", "--chunk-size", "65536",
            entrypoint="rsg_record")
    wait_for_stats(c.stats, lambda s: s["state_readers"] >= 3, "3 readers to match the gateway", timeout_s=60)
    for label, tool in (("view", "rsg_view"), ("echo2", "rsg_echo"), ("record2", "rsg_record")):
        wait_reader_matched(c, label, tool)
    wait_for(lambda: "serving" in c.stderr("view"), "rsg_view to listen")
    c.start("sim2", "--to", f"127.0.0.1:{port}", "--rate", "500", "--record", f"{DATA}/sim2.jsonl",
            entrypoint="rsg_sim")

    # The page, from the container, in Debian's headless Chromium on the host.
    chromium = shutil.which("chromium")
    check(chromium is not None, "chromium is not installed: run `make deps`")
    devtools = free_tcp_port()
    browser = subprocess.Popen([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                                f"--user-data-dir={c.dir / 'chromium'}", f"--remote-debugging-port={devtools}",
                                "about:blank"], stdout=subprocess.DEVNULL, stderr=open(c.dir / "chromium.err", "wb"))
    try:
        shown = node("tests/tools/view/check_page.mjs", devtools, f"http://127.0.0.1:{ws_port}/", c.dir / "rsg_view.png")
    finally:
        browser.kill()
        browser.wait()
    sent = {", ".join(f"{v:.4f}" for v in frame["fields"]["q"]) for frame in read_json_lines(c.data / "sim2.jsonl")
            if "q" in frame["fields"]}
    check(shown["last_q"] in sent, f"the page shows q = {shown['last_q']}, which rsg_sim never sent")
    check(shown["chart_js"] and shown["q_points"] >= 50, f"Chart.js did not plot: {shown}")
    print(f"[image] view: the page showed {shown}", flush=True)
    check(c.stop("view") == 0, "rsg_view did not exit 0 on SIGTERM")

    # The kill, then the gateway again with the same command, as `restart: on-failure` would: the
    # engine does not restart a container it was told to kill, so the test runs it again.
    def samples():
        return len(read_json_lines(c.output("echo2")))

    def recorded():  # the recorder's progress: the file grows by a chunk (64 KiB before zstd) at a time
        path = c.data / "restart.mcap"
        return path.stat().st_size if path.exists() else 0

    def both_resume(what, echo_then, file_then):
        wait_for(lambda: samples() >= echo_then + 500, f"rsg_echo to resume {what} ({echo_then} samples then)",
                 timeout_s=60)
        wait_for(lambda: recorded() >= file_then + 100_000, f"rsg_record to resume {what} ({file_then} bytes then)",
                 timeout_s=60)

    wait_for(lambda: samples() >= 200, "rsg_echo's first samples")
    c.engine_run("kill", c.container("gateway"))
    status = c.wait("gateway")
    check(status != 0, f"the killed gateway container exited {status}")
    time.sleep(1.0)
    before, file_before = samples(), recorded()
    c.stats.unlink(missing_ok=True)
    gateway = c.detached_gateway("gateway2", port)
    wait_for_stats(c.stats, lambda s: s["frames_published"] > 0, "the gateway to publish again", timeout_s=60)
    both_resume("after the kill", before, file_before)

    # A crash the engine did not order (the abort's effect: the process ends on a signal): SIGKILL
    # from the host to the container's process. The engine itself starts it again (on-failure).
    pid = c.inspect(gateway, "{{.State.Pid}}")
    os.kill(int(pid), 9)
    wait_for(lambda: c.inspect(gateway, "{{.RestartCount}}") not in ("", "0"), "the engine to restart the gateway",
             timeout_s=60)
    crashed = samples()
    both_resume("after the crash", crashed, recorded())
    check(c.processes["echo2"].poll() is None and c.processes["record2"].poll() is None,
          "a reader exited when the gateway was killed")
    check(c.stop("sim2") == 0, f"rsg_sim did not exit 0 on SIGTERM: {c.stderr('sim2')}")
    time.sleep(1.0)
    check(c.stop("echo2") == 0, "rsg_echo did not exit 0 on SIGTERM")
    check(c.stop("record2") == 0, f"rsg_record did not exit 0 on SIGTERM: {c.stderr('record2')}")

    received = read_json_lines(c.output("echo2"))
    sent = read_json_lines(c.data / "sim2.jsonl")
    check(len(received) >= crashed + 500, f"rsg_echo printed {len(received)} samples, {crashed} before the crash")
    check(is_subsequence(received, sent), "rsg_echo printed a sample rsg_sim did not send, or out of order")
    seen = node("tests/tools/record/check_recording.mjs", c.data / "restart.mcap")
    check(seen["states"] >= 1000, f"the recording holds {seen['states']} states")
    print(f"[image] restart: {before} samples before the kill, {crashed} before the crash, {len(received)} in "
          f"all, every one sent by rsg_sim, in order; the recording is readable ({seen['states']} states)", flush=True)
    c.engine_run("stop", "-t", "20", gateway, timeout_s=60)
    check(c.inspect(gateway, "{{.State.ExitCode}}") == "0", "the gateway did not exit 0 on SIGTERM")


# What the compose runner below understands of a service; any other key fails the test, so that
# compose.yaml cannot grow a setting this test would silently leave out.
COMPOSE_KEYS = {"image", "build", "network_mode", "ipc", "entrypoint", "command", "volumes", "restart", "depends_on",
                "environment", "logging"}


def compose_services(path, env):
    """docker/compose.yaml's services with ${VAR:-default} filled in from `env`, in start order."""
    import yaml  # Debian's python3-yaml (make deps)
    text = re.sub(r"\$\{(\w+):-([^}]*)\}", lambda m: env.get(m.group(1)) or m.group(2), path.read_text())
    spec = yaml.safe_load(text)
    services, ordered = spec["services"], []
    while len(ordered) < len(services):
        ready = [name for name, service in services.items() if name not in ordered
                 and all(dep in ordered for dep in service.get("depends_on", []))]
        check(ready, f"compose.yaml: depends_on has a cycle among {set(services) - set(ordered)}")
        ordered += ready
    for name in ordered:
        unknown = set(services[name]) - COMPOSE_KEYS
        check(not unknown, f"compose.yaml: service {name} uses {unknown}, which tests/image does not run")
    return [(name, services[name]) for name in ordered], set(spec.get("volumes") or {})


def compose_up(c, project, env):
    """Runs compose.yaml's services as `compose up -d` does, with the engine itself: Debian 12's
    podman-compose (1.0.3) passes no `ipc:` and adds a bridge network to `network_mode: host`
    services, which podman refuses. Returns {service: container name}."""
    services, volumes = compose_services(ROOT / "docker" / "compose.yaml", env)
    for volume in volumes:
        c.engine_run("volume", "create", f"{project}_{volume}")
    names = {}
    for name, service in services:
        container = f"{project}_{name}_1"
        names[name] = container
        c.names.add(container)
        args = ["run", "-d", "--name", container]
        for key, flag in (("network_mode", "--network"), ("ipc", "--ipc"), ("restart", "--restart")):
            if key in service:
                args += [flag, service[key]]
        for variable in service.get("environment", []):
            args += ["-e", variable]
        # Docker's json-file log with a size limit is podman's k8s-file with max-size (podman keeps
        # no count of rotated files).
        logging = service.get("logging", {})
        check(logging.get("driver") == "json-file", f"compose.yaml: log driver {logging.get('driver')}")
        args += ["--log-driver", "k8s-file"]
        if "max-size" in logging.get("options", {}):
            args += ["--log-opt", f"max-size={logging['options']['max-size']}"]
        for volume in service.get("volumes", []):
            source, target = volume.split(":", 1)
            args += ["-v", f"{project}_{source}:{target}" if source in volumes else volume]
        if "entrypoint" in service:
            entrypoint = service["entrypoint"]
            args += ["--entrypoint", entrypoint[0] if len(entrypoint) == 1 else json.dumps(entrypoint)]
        c.engine_run(*args, env.get("RSG_IMAGE", service["image"]), *service.get("command", []))
    return names


def compose(c):
    """docker/compose.yaml, on a domain and ports of this run, the image already built: with
    `docker compose` when the engine is Docker, else with compose_up."""
    project = c.prefix
    env = {**os.environ, "RSG_IMAGE": c.image, "RSG_DOMAIN": str(c.domain), "RSG_ROBOT_PORT": str(free_udp_port()),
           "RSG_VIEW_PORT": str(free_tcp_port()), "RSG_METRICS_PORT": str(c.metrics_port)}
    docker_compose = ["docker", "compose", "-p", project, "-f", str(ROOT / "docker" / "compose.yaml")]

    def logs(service):
        result = c.engine_run("logs", names[service], check_status=False)
        return result.stdout + result.stderr

    try:
        if c.name == "docker":
            subprocess.run([*docker_compose, "up", "-d", "--no-build"], env=env, check=True, timeout=180)
            names = {service: f"{project}-{service}-1" for service in ("gateway", "sim", "echo", "record", "view")}
        else:
            names = compose_up(c, project, env)
        check(set(names) >= {"gateway", "sim", "echo", "record", "view"}, f"compose.yaml's services: {set(names)}")
        wait_for(lambda: healthy(c, names["gateway"]), "the gateway container to be healthy", timeout_s=60)
        wait_for(lambda: logs("echo").count('"fields"') >= 100, "rsg_echo's samples", timeout_s=60)
        url = f"http://127.0.0.1:{env['RSG_VIEW_PORT']}/"
        page = wait_for(lambda: fetch(url), f"rsg_view's page at {url}", timeout_s=60)
        check("<html" in page.lower(), f"{url} is not the page: {page[:200]}")
        time.sleep(2.0)
        c.engine_run("stop", "-t", "20", names["record"], timeout_s=60)
        check(c.engine_run("inspect", "--format", "{{.State.ExitCode}}", names["record"]).stdout.strip() == "0",
              f"rsg_record did not exit 0 on SIGTERM: {logs('record')[-500:]}")
        volume = c.engine_run("volume", "inspect", "--format", "{{.Mountpoint}}", f"{project}_recordings").stdout.strip()
        files = sorted(Path(volume).glob("robot*.mcap"))
        check(files, f"no recording in the volume ({volume})")
        seen = node("tests/tools/record/check_recording.mjs", files[0])
        check(seen["states"] >= 100, f"the recording in the volume holds {seen['states']} states")
        print(f"[image] compose: gateway healthy, echo printing, page at {url}, {files[0].name} in the volume "
              f"({seen['states']} states)", flush=True)
    finally:
        if c.name == "docker":
            subprocess.run([*docker_compose, "down", "-v"], env=env, capture_output=True, timeout=180)
        else:
            remove_containers(c.engine, [name for name in c.names if name.startswith(f"{project}_")])
            subprocess.run([*c.engine, "volume", "rm", "-f", f"{project}_recordings"], capture_output=True)


def fetch(url):
    try:
        with urllib.request.urlopen(url, timeout=5) as response:
            return response.read().decode(errors="replace")
    except OSError:
        return None


def ros2_type_hash(c):
    """The image was built without ROS 2: its gateway, run with --ros2 and the standard topics, is
    seen by a real rclpy node (make deps' ROS 2 environment on the host) with rosidl's RIHS01 type
    hash on every writer, where it once showed INVALID: a ROS 2 Jazzy node, as its rosidl computes it."""
    sys.path.insert(0, str(ROOT / "tests" / "ros2"))
    from rclpy_common import RosEnv, check_rosidl_type_hashes  # noqa: E402 (the ROS 2 environment only here)
    c.start("gateway", "--listen", f"127.0.0.1:{free_udp_port()}", "--domain", c.domain, "--ros2",
            "--joint-states", "100", "--tf", "every:5", "--external-wrench", "50",
            mounts=[f"{c.stats_dir}:{STATS_DIR}"])
    wait_for_stats(c.stats, lambda s: True, "the gateway container to start", timeout_s=60)
    checked = check_rosidl_type_hashes(RosEnv(c.domain, "jazzy"))
    print(f"[image] ros2_type_hash: rosidl's hash on all {checked} ROS 2 writers of the image's gateway, "
          f"seen by a jazzy node", flush=True)


CASES = {"pipeline": pipeline, "health": health, "view_and_restart": view_and_restart, "compose": compose,
         "ros2_type_hash": ros2_type_hash, "dds_attacks": dds_attacks}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--engine", required=True, help='the engine command, e.g. "podman --runtime runc"')
    parser.add_argument("--image", default="rsg")
    parser.add_argument("--case", action="append", choices=sorted(CASES), help="default: every case")
    args = parser.parse_args()
    passed = failed = 0
    for name in args.case or list(CASES):
        c = Containers(args.engine, args.image, name)
        ok = False
        start = time.monotonic()
        try:
            CASES[name](c)
            ok = True
        except (TestFailure, subprocess.TimeoutExpired) as failure:
            print(f"[image.{name}] FAILED: {failure}")
            c.dump_logs()
        finally:
            c.cleanup(keep=not ok)
        print(f"[image.{name}] {'passed' if ok else 'FAILED'} in {time.monotonic() - start:.0f} s", flush=True)
        passed, failed = passed + ok, failed + (not ok)
        listed = subprocess.run([*c.engine, "ps", "-a", "--format", "{{.Names}}"], capture_output=True, text=True)
        left = [container for container in listed.stdout.split() if container.startswith(c.prefix)]
        if left:
            print(f"[image.{name}] FAILED: containers left behind: {left}")
            remove_containers(c.engine, left)
            passed, failed = passed - ok, failed + ok
    print(f"image: {passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
