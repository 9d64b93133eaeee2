"""Signals as an attacker with a local shell, and an operator, send them (issue 39), with the example
configuration's flight recorder (deploy/systemd/robot1.yaml's bounds):

- 1,200 SIGUSR1 in about two seconds while the robot streams at 500 Hz: one dump is written (the
  default --pcap-min-interval is 10 s), the rest are counted as throttled and logged at most once,
  --pcap-dir grows by that one file, promtool accepts the scrape, and every frame reaches a
  legitimate reader (rsg_echo). Before the limit each signal wrote a file: 5 GB in 10 s.
- SIGHUP re-reads --config: a new allow-from applies from the next datagram (the robot's frames are
  then rejected, counted as such), a changed topic is named as needing a restart, a file that does
  not check leaves the running configuration in place (counted as a failed reload), and restoring
  allow-from lets frames through again. Before, SIGHUP killed the gateway with no final stats.
- SIGTERM still ends it with exit 0 and the final stats."""

import os
import re
import signal
import sys
import time

from attack_support import checked_scrape, folder_bytes, gateway_with_reader
from harness import check, main, read_json, wait_for, wait_for_stats, free_udp_port
from metrics_support import free_tcp_port, value_of

RATE = 500
FRAMES = 3000  # 6 s
SIGNALS = 1200


def write_config(path, port, metrics, dumps, allow_from, topic="robot_state", extra=""):
    path.write_text(f"listen: 127.0.0.1:{port}\nallow-from: [{allow_from}]\nexpected-rate: {RATE}\n"
                    f"topic: {topic}\nmetrics: 127.0.0.1:{metrics}\n"
                    f"pcap-ring: 1\npcap-dir: {dumps}\npcap-min-interval: 10\npcap-max-files: 100\n"
                    f"pcap-max-mb: 500\n{extra}")


def log_count(h, text):
    return (h.dir / "gateway.err").read_text(errors="replace").count(text)


def reloads(h, metrics):
    samples = checked_scrape(h, metrics, "reload")
    return (value_of(samples, "rsg_config_reloads_total", result="applied"),
            value_of(samples, "rsg_config_reloads_total", result="failed"))


def body(h):
    port, metrics = free_udp_port(), free_tcp_port()
    dumps = h.dir / "dumps"
    dumps.mkdir()
    config = h.dir / "gateway.yaml"
    write_config(config, port, metrics, dumps, "127.0.0.1")
    gateway, stats, echo = gateway_with_reader(h, metrics, FRAMES, "--config", str(config))

    # 1. A SIGUSR1 flood while the robot streams.
    before = folder_bytes(dumps)
    streaming = time.monotonic()
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE),
                          "--count", str(FRAMES)])
    wait_for_stats(stats, lambda s: s["link_up"], "the stream to start")
    started = time.monotonic()
    for _ in range(SIGNALS):
        os.kill(gateway.pid, signal.SIGUSR1)
        time.sleep(0.0015)
    flood_s = time.monotonic() - started
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()} during the SIGUSR1 flood")
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every frame sent during the SIGUSR1 flood")
    wait_for_stats(stats, lambda s: s["frames_published"] == FRAMES, "every frame published")
    samples = wait_for(lambda: (lambda s: s if value_of(s, "rsg_flight_recorder_dumps_total", result="written")
                                >= 1 else None)(checked_scrape(h, metrics, "sigusr1")),
                       "the first dump to be written")
    written = value_of(samples, "rsg_flight_recorder_dumps_total", result="written")
    throttled = value_of(samples, "rsg_flight_recorder_dumps_total", result="throttled")
    elapsed_s = time.monotonic() - streaming
    check(written <= 1 + int(elapsed_s // 10), f"{written} dumps for {SIGNALS} signals in {elapsed_s:.1f} s")
    check(throttled >= 1, "no request was counted as throttled")
    files = list(dumps.iterdir())
    after = folder_bytes(dumps)
    check(len(files) == written, f"{len(files)} files in --pcap-dir for {written} dumps")
    check(log_count(h, "less than --pcap-min-interval") == 1, "the throttled dumps were not logged exactly once")
    print(f"SIGUSR1: {SIGNALS} signals in {flood_s:.1f} s: {written:.0f} dump written, {throttled:.0f} requests "
          f"throttled (signals coalesce); --pcap-dir {before} bytes before, {after} after")

    # 2. SIGHUP: allow-from reloads, topic needs a restart.
    published = read_json(stats)["frames_published"]
    rejected = read_json(stats)["rejected_source"]
    write_config(config, port, metrics, dumps, "127.0.0.2", topic="elsewhere", extra="log-level: debug\n")
    os.kill(gateway.pid, signal.SIGHUP)
    wait_for(lambda: gateway.poll() is not None or log_count(h, "SIGHUP: configuration reloaded: allow-from [127.0.0.2]"),
             "the reload to be logged")
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()} on SIGHUP")
    text = (h.dir / "gateway.err").read_text(errors="replace")
    check(re.search(r"SIGHUP: not applied until a restart: --topic", text), "--topic not named")
    wait_for(lambda: reloads(h, metrics) == (1, 0), "the reload to be counted")
    check(h.run("sim_refused", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "100",
                                "--count", "20"]) == 0, "rsg_sim failed")
    after_reload = wait_for_stats(stats, lambda s: s["rejected_source"] >= rejected + 20,
                                  "the robot's frames to be rejected under the new allow-from")
    check(after_reload["frames_published"] == published, "frames from outside the new allow-from were published")

    # A file that does not check: counted, logged, the running configuration stays.
    write_config(config, port, metrics, dumps, "300.1.1.1")
    os.kill(gateway.pid, signal.SIGHUP)
    wait_for(lambda: log_count(h, "SIGHUP: configuration not reloaded"), "the failed reload to be logged")
    wait_for(lambda: reloads(h, metrics) == (1, 1), "the failed reload to be counted")
    check(gateway.poll() is None, "the gateway exited on a bad reload")

    # Back to the robot's address: frames flow again.
    write_config(config, port, metrics, dumps, "127.0.0.1")
    os.kill(gateway.pid, signal.SIGHUP)
    wait_for(lambda: reloads(h, metrics) == (2, 1), "the second reload to be counted")
    check(h.run("sim_again", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "100",
                              "--count", "20"]) == 0, "rsg_sim failed")
    wait_for_stats(stats, lambda s: s["frames_published"] == published + 20, "frames to flow again")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    final = read_json(stats)
    check(final["frames_published"] == published + 20, f"the final stats say {final['frames_published']} published")


if __name__ == "__main__":
    sys.exit(main("attack_signals", body))
