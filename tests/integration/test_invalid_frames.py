"""Invalid frames interleaved: none is published, and the gateway's counters (stats file and the
status topic) equal what the sim says it sent, category by category."""

import sys

from harness import (check, main, read_json, read_json_lines, wait_for, wait_for_stats, wait_reader_matched, free_udp_port)

# Frames 3, 7, 11, ... 699 are corrupted: 175 invalid, cycling through the seven categories. The
# last frame is valid: a gap at the very end is invisible to packet numbers.
COUNT = 701
CORRUPT_EVERY = 4
VALID = COUNT - COUNT // CORRUPT_EVERY
RATE = "500"
COUNTERS = ("frames_received", "frames_published", "invalid", "rejected_source")


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    h.start("probe", [h.binary("rsg_status_probe"), "--domain", str(h.domain), "--timeout", "50"])
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                            "--json", "--count", str(VALID), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo's reader to match the gateway's writer")
    wait_reader_matched(h, "echo", "rsg_echo")

    record, report_path = h.dir / "sim.record.jsonl", h.dir / "sim.report.json"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--groups", "2,5", "--corrupt-every", str(CORRUPT_EVERY),
                           "--record", str(record), "--report", str(report_path)])
    check(status == 0, f"rsg_sim exited {status}")
    report = read_json(report_path)
    check(report["valid"] == VALID, f"the sim sent {report['valid']} valid frames, the test expects {VALID}")

    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every valid frame")
    check(read_json_lines(h.output("echo")) == read_json_lines(record), "samples differ from the valid frames sent")

    expected = {"frames_received": report["sent"], "frames_published": report["valid"],
                "invalid": report["invalid"], "rejected_source": 0}
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every datagram")
    check({key: final[key] for key in COUNTERS} == expected,
          f"stats file {dict((k, final[k]) for k in COUNTERS)} != sim report {expected}")

    # The status topic says the same (it is published once a second).
    def status_with_everything():
        lines = read_json_lines(h.output("probe"))
        return [line for line in lines if line["frames_received"] >= report["sent"]]
    status_line = wait_for(status_with_everything, "a GatewayStatus sample counting every datagram")[0]
    check({key: status_line[key] for key in COUNTERS} == expected,
          f"status topic {dict((k, status_line[k]) for k in COUNTERS)} != sim report {expected}")

    # A corrupted frame replaces a valid one and so leaves a gap in the packet numbers, but it arrived:
    # it is counted under its category, not also as lost (the sim dropped nothing).
    check(report["dropped"] == 0 and final["lost"] == 0,
          f"lost {final['lost']} although the sim dropped {report['dropped']} (invalid frames counted as lost?)")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("invalid_frames", body))
