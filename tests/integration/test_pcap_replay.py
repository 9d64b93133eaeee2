"""rsg_sim --pcap records what it sends; rsg_sim --replay sends that capture into a second gateway:
rsg_echo --json prints exactly what it printed for the live run, and the gateway counts the same
invalid frames. tshark (Debian's, not rsg's code) confirms the capture holds every datagram."""

import subprocess
import sys

from harness import check, main, read_json, read_json_lines, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 300
RATE = "500"
CORRUPT_EVERY = "25"  # 12 invalid frames among the 300, replayed as they were
VALID = COUNT - COUNT // 25


def run_gateway_and_echo(h, label, send_argv_for_port):
    """A gateway on a fresh port and topic, an echo on it; runs the sender; returns (echo lines, stats)."""
    port = free_udp_port()
    topic = f"pcap_replay_{label}"
    gateway, stats = h.gateway(f"gateway_{label}", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE,
                               "--topic", topic)
    wait_for_stats(stats, lambda s: True, f"the {label} gateway to start")
    echo = h.start(f"echo_{label}", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", topic, "--json",
                                     "--count", str(VALID), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, f"the {label} rsg_echo to match")
    wait_reader_matched(h, f"echo_{label}", "rsg_echo")
    status = h.run(f"sender_{label}", send_argv_for_port(port))
    check(status == 0, f"the {label} sender exited {status}")
    check(h.wait(f"echo_{label}", echo, 45) == 0, f"the {label} rsg_echo did not receive every sample")
    check(h.stop(f"gateway_{label}", gateway) == 0, f"the {label} gateway did not exit 0")
    return h.output(f"echo_{label}").read_text().splitlines(), read_json(stats)


def body(h):
    capture = h.dir / "live.pcap"
    sim = h.binary("rsg_sim")
    live_lines, live_stats = run_gateway_and_echo(h, "live", lambda port: [
        sim, "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT), "--every", "1:q,dq,time",
        "--every", "4:g0", "--every", "10:all", "--corrupt-every", CORRUPT_EVERY, "--pcap", str(capture)])
    check(len(live_lines) == VALID, f"the live echo printed {len(live_lines)} samples, not {VALID}")

    tshark = subprocess.run(["tshark", "-n", "-r", str(capture), "-T", "fields", "-e", "udp.length"],
                            capture_output=True, text=True, timeout=60)
    check(tshark.returncode == 0, f"tshark cannot read the capture: {tshark.stderr}")
    check(len(tshark.stdout.splitlines()) == COUNT, f"the capture holds {len(tshark.stdout.splitlines())} "
          f"datagrams, not {COUNT}")

    replay_lines, replay_stats = run_gateway_and_echo(h, "replay", lambda port: [
        sim, "--to", f"127.0.0.1:{port}", "--replay", str(capture), "--speed", "2"])
    check(replay_lines == live_lines, "rsg_echo printed other samples for the replay than for the live run")
    for key in ("frames_received", "frames_published", "invalid", "lost", "duplicated", "reordered"):
        check(replay_stats[key] == live_stats[key],
              f"{key}: replay {replay_stats[key]}, live {live_stats[key]}")
    check(sum(live_stats["invalid"].values()) == COUNT // 25, f"invalid frames: {live_stats['invalid']}")


if __name__ == "__main__":
    sys.exit(main("pcap_replay", body))
