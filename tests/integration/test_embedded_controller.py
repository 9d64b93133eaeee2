"""examples/embedded_controller: the gateway inside a controller process. rsg_sim -> the example's
rsg::gateway::EmbeddedGateway -> its callback gets every frame, and rsg_echo in another process still
receives every sample over DDS, with the values the sim sent."""

import re
import signal
import sys

from harness import check, main, read_json_lines, wait_for, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 500
RATE = "500"


def body(h):
    port = free_udp_port()
    config = h.dir / "gateway.yaml"
    stats = h.dir / "stats.json"
    config.write_text(f"listen: 127.0.0.1:{port}\ndomain: {h.domain}\nexpected-rate: {RATE}\nstats-file: {stats}\n")
    controller = h.start("controller", [h.binary("rsg_example_embedded_controller"), str(config)])
    wait_for(lambda: "frames on UDP" in h.output("controller").read_text(), "the controller to start")

    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                            "--json", "--count", str(COUNT), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo's reader to match the embedded writer")
    wait_reader_matched(h, "echo", "rsg_echo")

    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--record", str(record)])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every sample from the embedded gateway")

    controller.send_signal(signal.SIGTERM)
    check(h.wait("controller", controller) == 0, "the controller did not exit 0")
    frames = re.findall(r"embedded controller: (\d+) frames", h.output("controller").read_text())
    check(frames and int(frames[-1]) == COUNT, f"the controller's callback saw {frames} frames, not {COUNT}")

    sent = read_json_lines(record)
    received = read_json_lines(h.output("echo"))
    check(len(received) == len(sent) == COUNT, f"echo printed {len(received)} samples for {len(sent)} frames")
    for index, (expected, actual) in enumerate(zip(sent, received)):
        check(actual == expected, f"sample {index} differs from the frame sent:\n  sent {expected}\n  got  {actual}")


if __name__ == "__main__":
    sys.exit(main("embedded_controller", body))
