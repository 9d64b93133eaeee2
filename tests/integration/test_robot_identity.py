"""Two robots in one partition are never mixed silently (docs/service.md, "Several robots"): two
gateways in partition robot1, each fed by its own rsg_sim, both say so -- an error line naming the
topic and partition, `rsg_state_other_writers` on /metrics, /readyz 503 "another writer ... robots mixed" -- and rsg_echo, reading that partition,
warns "2 programs write 'robot_state' in partition 'robot1'". Once the second gateway stops, the
first says the other writer is gone and is ready again.

The control: a gateway in partition robot2 beside robot1's is no other writer (0 on every side, /readyz
200), and a reader of robot1 started then gets no warning: the warning is the partition's sharing,
not the second gateway's existence."""

import sys

from harness import check, main, wait_for, wait_for_stats, wait_reader_matched
from metrics_support import http_get, parse_samples, start_gateway, value_of


def sim(h, label, port):
    """A robot streaming until stopped."""
    return h.start(label, [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "200", "--duration", "120"])


def other_writers(metrics):
    """rsg_state_other_writers of the gateway on TCP port `metrics`."""
    _, text = http_get(metrics, "/metrics")
    return value_of(parse_samples(text), "rsg_state_other_writers")


def stderr_of(h, label):
    return (h.dir / f"{label}.err").read_text(errors="replace")


def body(h):
    first, first_stats, first_port, first_metrics = start_gateway(h, "robot1", "--partition", "robot1",
                                                                  "--name", "robot1", rate="200")
    first_sim = sim(h, "sim1", first_port)
    wait_for_stats(first_stats, lambda s: s["link_up"], "robot1's link to come up")
    wait_for(lambda: http_get(first_metrics, "/readyz")[0] == 200, "robot1's /readyz 200 while alone")
    check(other_writers(first_metrics) == 0, "robot1 alone counts another writer")

    # A copy of robot1's configuration for the second robot, the partition kept.
    second, second_stats, second_port, second_metrics = start_gateway(h, "robot2", "--partition", "robot1",
                                                                      "--name", "robot2", rate="200")
    second_sim = sim(h, "sim2", second_port)
    for label, metrics in (("robot1", first_metrics), ("robot2", second_metrics)):
        wait_for(lambda: other_writers(metrics) == 1, f"{label} to count the other gateway's writer")
        wait_for(lambda: "1 other writer of 'robot_state' in partition 'robot1'" in stderr_of(h, label),
                 f"{label}'s error line about the other writer")
    status, text = http_get(first_metrics, "/readyz")
    check(status == 503 and "another writer of the state topic in this partition (1): robots mixed" in text,
          f"robot1's /readyz with another robot in its partition: {status} {text!r}")
    print(f"[{h.name}] same partition: both gateways count 1 other writer; robot1's /readyz: {text.strip()!r}")

    # 2000 samples: 5 s of both robots, time for discovery to show the reader both programs.
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--partition", "robot1",
                            "--json", "--count", "2000", "--timeout", "30"])
    wait_for(lambda: "2 programs write 'robot_state' in partition 'robot1'" in stderr_of(h, "echo"),
             "rsg_echo's warning about two robots in its partition")
    check(h.wait("echo", echo, 45) == 0, f"rsg_echo failed: {stderr_of(h, 'echo')[-500:]}")

    # The second robot goes: the first says so and is ready again.
    second_sim.kill()
    check(h.stop("robot2", second) == 0, "robot2's gateway did not exit 0")
    wait_for(lambda: other_writers(first_metrics) == 0, "robot1 to see the other writer gone")
    wait_for(lambda: "no other writer of 'robot_state' in partition 'robot1' any more" in stderr_of(h, "robot1"),
             "robot1's line that the other writer is gone")
    wait_for(lambda: http_get(first_metrics, "/readyz")[0] == 200, "robot1's /readyz 200 again")

    # The control: robot2 in a partition of its own.
    third, third_stats, third_port, third_metrics = start_gateway(h, "robot2b", "--partition", "robot2",
                                                                  "--name", "robot2", rate="200")
    third_sim = sim(h, "sim3", third_port)
    wait_for_stats(third_stats, lambda s: s["link_up"], "robot2's link in partition robot2")
    echo2 = h.start("echo2", [h.binary("rsg_echo"), "--domain", str(h.domain), "--partition", "robot1",
                              "--json", "--count", "400", "--timeout", "30"])
    wait_reader_matched(h, "echo2", "rsg_echo")
    check(h.wait("echo2", echo2, 45) == 0, f"rsg_echo of robot1 failed: {stderr_of(h, 'echo2')[-500:]}")
    for label, metrics in (("robot1", first_metrics), ("robot2b", third_metrics)):
        check(other_writers(metrics) == 0, f"{label} counts another writer across partitions")
    check(http_get(first_metrics, "/readyz")[0] == 200 and http_get(third_metrics, "/readyz")[0] == 200,
          "a gateway is not ready beside another robot's in another partition")
    check("programs write" not in stderr_of(h, "echo2"), f"rsg_echo warned with one robot in its partition: "
          f"{stderr_of(h, 'echo2')}")
    print(f"[{h.name}] control: partitions robot1 and robot2, no other writer, both ready, rsg_echo quiet")

    for process in (first_sim, third_sim):
        process.kill()
    check(h.stop("robot1", first) == 0 and h.stop("robot2b", third) == 0, "a gateway did not exit 0")


if __name__ == "__main__":
    sys.exit(main("robot_identity", body))
