"""An attacker on the network against the flight recorder (issue 39), on loopback: one valid frame
from the allowed address every 30 ms, so that the link goes down and up on every frame (expected
rate 1 kHz), plus a flood of junk from another address (127.0.0.2), against a one-second ring, in
a --pcap-dir that already holds earlier dumps and a file of the operator's. Before the limits
every link change wrote a file and the ring kept the junk: gigabytes in seconds.

Asserts, with the defaults where the test does not need another value: at most one dump per
--pcap-min-interval (10 s by default) and every further link change counted as throttled; the
dumps hold only the allowed sender's datagrams (the junk counted as not kept); the folder within
--pcap-max-files and --pcap-max-mb, rsg's oldest files deleted first and counted, the operator's
file untouched; the folder's bytes before and after; promtool accepts the scrape; every valid
frame reached a legitimate reader (rsg_echo). Then the project's oversized vectors
(tests/data/vectors/oversized.jsonl, 2138 to 9000 bytes) from the allowed address: the gateway
counts each as length_mismatch, the category every decoder gives them (docs/protocol.md, step 1)."""

import json
import os
import socket
import sys
import time
from pathlib import Path

from attack_support import JunkFlood, checked_scrape, dump_senders, folder_bytes, gateway_with_reader
from harness import check, main, read_json, wait_for, wait_for_stats, free_udp_port
from metrics_support import free_tcp_port, value_of

VECTORS = Path(__file__).resolve().parents[1] / "data" / "vectors"
FLAP_RATE = 33   # a frame every 30 ms ...
FRAMES = 132     # ... for 4 s
OLD_FILES = 6    # earlier dumps in the folder, 300 KB each
MAX_FILES = 4
MAX_MB = 1


def body(h):
    port, metrics = free_udp_port(), free_tcp_port()
    folder = h.dir / "dumps"
    folder.mkdir()
    old = []
    for i in range(OLD_FILES):  # oldest first, a minute apart, a day ago
        path = folder / f"rsg_flight_20261126T10{i:02d}00.000Z_{i + 1}_link_down.pcap"
        path.write_bytes(b"\0" * 300_000)
        stamp = time.time() - 86400 + 60 * i
        os.utime(path, (stamp, stamp))
        old.append(path)
    notes = folder / "operator_notes.txt"
    notes.write_bytes(b"not rsg's\n" * 30_000)
    before = folder_bytes(folder)

    gateway, stats, echo = gateway_with_reader(
        h, metrics, FRAMES, "--listen", f"127.0.0.1:{port}", "--allow-from", "127.0.0.1", "--expected-rate", "1000",
        "--pcap-ring", "1", "--pcap-dir", str(folder), "--pcap-max-files", str(MAX_FILES), "--pcap-max-mb",
        str(MAX_MB), "--metrics", f"127.0.0.1:{metrics}")

    flood = JunkFlood(port)
    flood.start()
    started = time.monotonic()
    report = h.dir / "sim.report.json"
    try:
        status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(FLAP_RATE),
                               "--count", str(FRAMES), "--report", str(report)])
    finally:
        flood.stop()
    attacked_s = time.monotonic() - started
    check(status == 0, f"rsg_sim exited {status}")
    check(flood.sent > 1000, f"only {flood.sent} junk datagrams sent")

    # Valid frames kept flowing to the legitimate reader, every one of them.
    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every frame sent during the attack")
    final = wait_for_stats(stats, lambda s: s["frames_published"] == FRAMES and not s["link_up"],
                           "every frame published and the link down")
    # Every link down asks for a dump: each one written, throttled, refused or failed, all on
    # /metrics; the log says the first at once, then counts (app::RepeatedLog), not a line a flap.
    def dumps_of(samples):
        return {result: value_of(samples, "rsg_flight_recorder_dumps_total", result=result)
                for result in ("written", "throttled", "refused", "failed", "no_room")}
    samples = wait_for(lambda: (lambda s: s if sum(dumps_of(s).values()) >= 10 and dumps_of(s)["written"] >= 1
                                else None)(checked_scrape(h, metrics, "flood")),
                       "the dump requests to be counted and the first dump written")
    changes = sum(dumps_of(samples).values())
    check(changes >= 10, f"the link went down only {changes} times: the attack did not happen")
    down_lines = (h.dir / "gateway.err").read_text(errors="replace").count("link down (")
    check(down_lines <= 2, f"{down_lines} 'link down' lines for {changes} link downs")
    elapsed_s = time.monotonic() - started
    dumps = dumps_of(samples)
    written, throttled = dumps["written"], dumps["throttled"]
    not_kept = value_of(samples, "rsg_flight_recorder_datagrams_not_kept_total")
    deleted = value_of(samples, "rsg_flight_recorder_files_deleted_total")
    bound = 1 + int(elapsed_s // 10)
    check(written <= bound, f"{written} dumps in {elapsed_s:.1f} s: more than one per --pcap-min-interval (10 s)")
    check(throttled >= changes - bound, f"{changes} link changes but only {throttled} throttled dumps")
    check(not_kept == value_of(samples, "rsg_frames_rejected_source_total") and not_kept > 0,
          f"{not_kept} datagrams not kept, {value_of(samples, 'rsg_frames_rejected_source_total')} rejected")

    ours = sorted(p for p in folder.iterdir() if p.name.startswith("rsg_flight_"))
    new = [p for p in ours if p not in old]
    check(new, "no dump was written")
    for path in new:
        senders = dump_senders(path)
        check(senders and set(senders) == {"127.0.0.1"}, f"{path.name} holds datagrams from {set(senders)}")
    check(len(ours) <= MAX_FILES, f"{len(ours)} dump files, more than --pcap-max-files {MAX_FILES}")
    ours_bytes = sum(p.stat().st_size for p in ours)
    check(ours_bytes <= MAX_MB << 20, f"{ours_bytes} bytes of dumps, more than --pcap-max-mb {MAX_MB}")
    gone = [p for p in old if not p.exists()]
    check(gone == old[:len(gone)] and len(gone) == deleted and deleted >= OLD_FILES - MAX_FILES + 1,
          f"deleted {[p.name for p in gone]} (counted {deleted}): not the oldest first")
    check(notes.exists() and notes.stat().st_size == 300_000, "the operator's file was touched")
    after = folder_bytes(folder)
    print(f"attack: {changes} link downs and {flood.sent} junk datagrams in {attacked_s:.1f} s; "
          f"{written:.0f} dumps written, {throttled:.0f} throttled, {not_kept:.0f} datagrams not kept, "
          f"{deleted:.0f} old files deleted; --pcap-dir {before} bytes before, {after} after")

    # Oversized datagrams from the allowed sender: length_mismatch, as every decoder says.
    vectors = [json.loads(line) for line in (VECTORS / "oversized.jsonl").read_text().splitlines() if line.strip()]
    check(all(v["error"] == "length_mismatch" for v in vectors), "oversized.jsonl expects another category")
    invalid_before = final["invalid"]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for vector in vectors:
            sender.sendto(bytes.fromhex(vector["frame_hex"]), ("127.0.0.1", port))
    counted = wait_for_stats(stats, lambda s: sum(s["invalid"].values()) >= sum(invalid_before.values()) + len(vectors),
                             "the oversized datagrams to be counted")
    grown = {k: counted["invalid"][k] - invalid_before.get(k, 0) for k in counted["invalid"]}
    check({k: v for k, v in grown.items() if v} == {"length_mismatch": len(vectors)},
          f"the oversized vectors were counted as {grown}")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    check(read_json(stats)["frames_published"] == FRAMES, "the final stats lost frames")


if __name__ == "__main__":
    sys.exit(main("attack_flight_recorder", body))
