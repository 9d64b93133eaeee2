"""Bad flags, files and profiles: one message naming the problem, exit status 2, and nothing
started (the listening port is still free). A port another process holds is the machine's refusal,
not a usage error: exit status 1, for the gateway and a tool alike (src/app/tool_main.hpp).
Also: --allow-from rejects other senders."""

import json
import os
import socket
import sys
import time
from pathlib import Path

from harness import check, main, read_json, wait_for, wait_for_stats, free_udp_port, port_is_free


def expect_refusal(h, label, flags, words):
    port = free_udp_port()
    status = h.run(label, [h.binary("rsg_gateway"), "--domain", str(h.domain), "--listen", f"127.0.0.1:{port}",
                           *flags])
    message = (h.dir / f"{label}.err").read_text()
    check(status == 2, f"{label}: exit status {status}, expected 2 ({message.strip()})")
    for word in words:
        check(word in message, f"{label}: message does not name '{word}': {message.strip()}")
    check(port_is_free(port), f"{label}: the listening port stayed bound")


def body(h):
    config = h.dir / "gateway.yaml"
    config.write_text("domain: 3\ntopic: arm\nexpected-rat: 100\n")
    expect_refusal(h, "unknown_key", ["--config", str(config)], [str(config) + ":3", "expected-rat"])
    config.write_text("domain: 3\nexpected-rate: [1, 2]\n")
    expect_refusal(h, "wrong_type", ["--config", str(config)], [str(config) + ":2", "expected-rate"])
    expect_refusal(h, "missing_file", ["--config", str(h.dir / "absent.yaml")], ["absent.yaml"])
    expect_refusal(h, "bad_flag", ["--domian", "3"], ["--domian"])
    expect_refusal(h, "bad_group", ["--request-groups", "7"], ["--request-groups", "'7'"])
    expect_refusal(h, "bad_network", ["--allow-from", "10.0.0.0/33"], ["--allow-from", "10.0.0.0/33"])
    expect_refusal(h, "missing_profile", ["--writer-profile", "no_such_writer"], ["no_such_writer"])
    broken = h.dir / "broken.xml"
    broken.write_text("<dds>\n<profiles>\n<data_writer profile_name='x'></data_reader>\n</profiles>\n</dds>\n")
    expect_refusal(h, "broken_profiles", ["--profiles", str(broken)],
                   [f"{broken}:3: not well-formed XML (XML_ERROR_MISMATCHED_ELEMENT"])
    profile_errors_come_first_on_stderr(h)

    # Files the configuration names are checked before anything starts: the file and errno.
    missing_dir = h.dir / "no_such_dir"
    expect_refusal(h, "stats_dir_missing", ["--stats-file", str(missing_dir / "stats.json")],
                   [f"--stats-file: cannot write '{missing_dir / 'stats.json'}'", "No such file or directory (ENOENT)"])
    expect_refusal(h, "stats_file_is_dir", ["--stats-file", str(h.dir)], ["--stats-file", "Is a directory (EISDIR)"])
    expect_refusal(h, "pcap_dir_missing", ["--pcap-ring", "5", "--pcap-dir", str(missing_dir)],
                   ["--pcap-dir", str(missing_dir), "No such file or directory (ENOENT)"])
    stats_file_warning_names_errno_once(h)

    # Flags override the file: the file names a missing profile, the flag a good one.
    config.write_text("writer-profile: no_such_writer\n")
    expect_refusal(h, "file_value", ["--config", str(config)], ["no_such_writer"])
    gateway, stats = h.gateway("overridden", "--listen", f"127.0.0.1:{free_udp_port()}", "--config", str(config),
                               "--writer-profile", "rsg_state_writer")
    wait_for_stats(stats, lambda s: True, "the gateway to start with the flag's profile")
    check(h.stop("overridden", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    # The port is taken: the environment refuses (exit 1), the message names the address.
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as holder:
        holder.bind(("127.0.0.1", 0))
        taken = holder.getsockname()[1]
        status = h.run("port_taken", [h.binary("rsg_gateway"), "--domain", str(h.domain),
                                      "--listen", f"127.0.0.1:{taken}"])
        message = (h.dir / "port_taken.err").read_text()
        check(status == 1, f"port_taken: exit status {status}, expected 1 ({message.strip()})")
        check(f"127.0.0.1:{taken}" in message and message.startswith("rsg_gateway: "),
              f"port_taken: message does not name the address: {message.strip()}")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        taken = holder.getsockname()[1]
        status = h.run("view_port_taken", [h.binary("rsg_view"), "--domain", str(h.domain),
                                           "--listen", f"127.0.0.1:{taken}"])
        message = (h.dir / "view_port_taken.err").read_text()
        check(status == 1, f"view_port_taken: exit status {status}, expected 1 ({message.strip()})")
        check(str(taken) in message, f"view_port_taken: message does not name the port: {message.strip()}")

    # --allow-from: frames from 127.0.0.1 are not in 10.0.0.0/8.
    port = free_udp_port()
    gateway, stats = h.gateway("filtered", "--listen", f"127.0.0.1:{port}", "--allow-from", "10.0.0.0/8",
                               "--allow-from", "::1")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "200", "--count", "50"])
    check(status == 0, f"rsg_sim exited {status}")
    final = wait_for_stats(stats, lambda s: s["rejected_source"] >= 50, "50 rejected datagrams")
    check(final["frames_received"] == 0 and final["frames_published"] == 0, f"filtered gateway published: {final}")
    check(h.stop("filtered", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    check(read_json(stats)["rejected_source"] == 50, "rejected_source changed after the stream ended")

    # --allow-from 127.0.0.1/32: the same stream sent from 127.0.0.2 is dropped and counted, from
    # 127.0.0.1 it is published. Both addresses are loopback, so only the filter tells them apart.
    port = free_udp_port()
    gateway, stats = h.gateway("allow_one", "--listen", f"0.0.0.0:{port}", "--allow-from", "127.0.0.1/32")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    frame = bytes.fromhex(first_valid_vector_hex())
    for source, count in (("127.0.0.2", 30), ("127.0.0.1", 20)):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.bind((source, 0))
            for _ in range(count):
                sender.sendto(frame, ("127.0.0.1", port))
    final = wait_for_stats(stats, lambda s: s["rejected_source"] + s["frames_received"] >= 50, "50 datagrams")
    check(final["rejected_source"] == 30, f"datagrams from 127.0.0.2 not all rejected: {final}")
    check(final["frames_received"] == 20 and final["frames_published"] == 20,
          f"datagrams from 127.0.0.1 not all published: {final}")
    check(h.stop("allow_one", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    # A clean shutdown deletes every entity, so the gateway leaves nothing in /dev/shm (its
    # data-sharing pools included) that could block or confuse the next start.
    before = shared_memory()
    gateway, stats = h.gateway("shutdown", "--listen", f"127.0.0.1:{free_udp_port()}")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    check(shared_memory() != before, "the gateway created no shared memory: the check below proves nothing")
    check(h.stop("shutdown", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    # Segments that appeared meanwhile but are still mapped belong to some other live process (a
    # test run beside this one), not to the gateway, which has exited.
    leftovers = shared_memory() - before - mapped_shared_memory()
    check(not leftovers, f"left in /dev/shm after SIGTERM: {sorted(leftovers)}")


def profile_errors_come_first_on_stderr(h):
    """Well-formed XML Fast DDS rejects: its own reasons on stderr (not stdout, a tool's output), then
    the one line naming the file."""
    wrong = h.dir / "wrong.xml"
    wrong.write_text("<dds><profiles><data_writer profile_name='x'><qos><no_such_policy/></qos>"
                     "</data_writer></profiles></dds>\n")
    status = h.run("wrong_profiles", [h.binary("rsg_echo"), "--domain", str(h.domain), "--json",
                                      "--profiles", str(wrong)])
    err = (h.dir / "wrong_profiles.err").read_text()
    check(status == 2, f"wrong_profiles: exit status {status}, expected 2 ({err.strip()})")
    check(h.output("wrong_profiles").read_text() == "", "Fast DDS's log went to stdout, the tool's output")
    ours = err.find(f"rsg_echo: --profiles: {wrong}: Fast DDS rejected this XML profile file")
    theirs = err.find("no_such_policy")
    check(ours >= 0 and 0 <= theirs < ours, f"Fast DDS's reason is not on stderr before rsg_echo's line: {err}")


def stats_file_warning_names_errno_once(h):
    """The stats file's directory disappears while the gateway runs: one warning with errno, not one a second."""
    directory = h.dir / "stats_dir"
    directory.mkdir()
    stats = directory / "stats.json"
    gateway = h.start("vanishing", [h.binary("rsg_gateway"), "--domain", str(h.domain), "--listen",
                                    f"127.0.0.1:{free_udp_port()}", "--stats-file", str(stats)])
    wait_for_stats(stats, lambda s: True, "the gateway to write its stats file")
    for file in directory.iterdir():
        file.unlink()
    directory.rmdir()
    warning = f"cannot write {stats}.partial: No such file or directory (ENOENT)"
    err = h.dir / "vanishing.err"
    wait_for(lambda: warning in err.read_text(), "the stats file warning")
    time.sleep(2.5)  # two more writes fail the same way
    check(h.stop("vanishing", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    check(err.read_text().count("cannot write") == 1, f"the warning was repeated: {err.read_text()}")


def shared_memory():
    return set(os.listdir("/dev/shm"))


def mapped_shared_memory():
    """Names of /dev/shm files some live process has mapped or open (/proc/*/maps and /proc/*/fd)."""
    paths = set()
    for process in Path("/proc").glob("[0-9]*"):
        try:
            paths.update(line.split(maxsplit=5)[5] for line in (process / "maps").read_text().splitlines()
                         if len(line.split(maxsplit=5)) == 6)
            paths.update(os.readlink(fd) for fd in (process / "fd").iterdir())
        except OSError:  # the process exited, or is not ours to read
            continue
    return {path[len("/dev/shm/"):].removesuffix(" (deleted)") for path in paths if path.startswith("/dev/shm/")}


def first_valid_vector_hex():
    vectors = Path(__file__).resolve().parents[1] / "data" / "vectors" / "valid.jsonl"
    with vectors.open() as lines:
        return json.loads(next(lines))["frame_hex"]


if __name__ == "__main__":
    sys.exit(main("startup_errors", body))
