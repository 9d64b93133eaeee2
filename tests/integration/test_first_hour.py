"""What a new user sees when the most common set-up mistakes happen (issue 30): each message says
what is wrong, with the numbers, and what to check.

1. rsg_echo, rsg_record and rsg_view in the wrong partition: after a few seconds without a writer they say what
   they look for (domain, partition, topic, type) and which writer of that topic they see instead
   ("a writer of 'robot_state' ... exists in partition 'robot2'"); with nothing on the domain, they say so.
2. A gateway that has received no datagram since start-up says so once, after 10 s, naming its address;
   a reader matched with it says after 5 s that no sample arrives and where to look, and a view
   reader whose groups no frame carries says that too.
3. A robot that does not answer the selection request (--robot names a port nobody listens on):
   after three tries the gateway warns once, with the numbers, and slows down.
"""

import sys

from harness import acquire_domain, check, free_tcp_port, free_udp_port, main, read_json, wait_for, wait_for_stats


def stderr_of(h, label):
    path = h.dir / f"{label}.err"
    return path.read_text(errors="replace") if path.exists() else ""


def wait_for_line(h, label, text, timeout_s=20):
    return wait_for(lambda: text in stderr_of(h, label), f"{label} to say '{text}'", timeout_s)


def body(h):
    # 2. starts first: its 10 s run while the rest happens.
    silent_port = free_udp_port()
    silent, silent_stats = h.gateway("silent", "--listen", f"127.0.0.1:{silent_port}", "--partition", "silent")
    wait_for_stats(silent_stats, lambda s: True, "the silent gateway to start")
    matched = h.start("matched", [h.binary("rsg_echo"), "--domain", str(h.domain), "--partition", "silent",
                                  "--json"])

    # 1. A gateway in partition robot2, readers in robot1.
    port = free_udp_port()
    gateway, stats = h.gateway("robot2", "--listen", f"127.0.0.1:{port}", "--partition", "robot2")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    domain = str(h.domain)
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", domain, "--partition", "robot1", "--json"])
    record = h.start("record", [h.binary("rsg_record"), "--domain", domain, "--partition", "robot1",
                                "--out", str(h.dir / "robot.mcap")])
    view = h.start("view", [h.binary("rsg_view"), "--domain", domain, "--partition", "robot1",
                            "--listen", f"127.0.0.1:{free_tcp_port()}"])
    for label, tool in (("echo", "rsg_echo"), ("record", "rsg_record"), ("view", "rsg_view")):
        wait_for_line(h, label, f"{tool}: warning: a writer of 'robot_state' (type 'rsg::RobotState') exists in "
                                "partition 'robot2': another partition (--partition robot2)")
        text = stderr_of(h, label)
        check(f"{tool}: warning: no writer matched: this reader looks for topic 'robot_state', type "
              f"'rsg::RobotState', in partition 'robot1' on domain {domain}" in text, f"{label}: {text}")
        check(text.count("no writer matched") == 1, f"{label} said it more than once: {text}")
    for label, process in (("echo", echo), ("view", view)):
        check(h.stop(label, process) == 0, f"{label} did not exit 0 on SIGTERM")
    # A recording that matched no writer is a failure, and says so (docs/record-replay.md).
    check(h.stop("record", record) == 1, "rsg_record that matched no writer did not exit 1 on SIGTERM")
    check("no writer of 'robot_state' matched" in stderr_of(h, "record"), stderr_of(h, "record"))
    check(h.stop("robot2", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    # 1. Nobody at all on the domain; rsg_echo gives up sooner than it would explain, and explains first.
    empty_domain = str(acquire_domain())  # a second domain of this test's, which nothing joins
    status = h.run("lonely", [h.binary("rsg_echo"), "--domain", empty_domain, "--timeout", "1"])
    check(status == 1, f"rsg_echo --timeout exited {status}")
    check(f"rsg_echo: warning: no writer of any topic is visible on domain {empty_domain}: is the gateway "
          "running, on this --domain" in stderr_of(h, "lonely"), stderr_of(h, "lonely"))

    # 2. A view whose groups the robot does not send.
    port = free_udp_port()
    viewed, stats = h.gateway("viewed", "--listen", f"127.0.0.1:{port}", "--partition", "viewed")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    view_echo = h.start("view_echo", [h.binary("rsg_echo"), "--domain", domain, "--partition", "viewed",
                                      "--view", "view_joints", "--json"])
    wait_for_line(h, "view_echo", "rsg_echo: matched 1 writer of ")
    sim = h.start("poses_sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "100",
                                "--count", "900", "--groups", "0"])
    wait_for_line(h, "view_echo", "but no sample has arrived")
    check("or no frame carries every group of this view" in stderr_of(h, "view_echo"), stderr_of(h, "view_echo"))
    check(h.output("view_echo").read_text() == "", "the view got samples without group 2")
    sim.kill()
    for label, process in (("view_echo", view_echo), ("viewed", viewed)):
        check(h.stop(label, process) == 0, f"{label} did not exit 0 on SIGTERM")

    # 3. The robot streams from one port and is asked on another, where nobody listens.
    port = free_udp_port()
    nobody = free_udp_port()
    gateway, stats = h.gateway("asking", "--listen", f"127.0.0.1:{port}", "--request-groups", "2",
                               "--robot", f"127.0.0.1:{nobody}", "--expected-rate", "100")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    report_path = h.dir / "sim.report.json"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "100", "--count", "600",
                          "--report", str(report_path)])
    wait_for_line(h, "asking", f"3 selection requests to 127.0.0.1:{nobody} went unanswered: the frames from "
                               "127.0.0.1:")
    text = stderr_of(h, "asking")
    check("still carry group_select=0x3f, not 0x04" in text and "Asking every 10 s from now on" in text, text)
    check(text.count(f"asked 127.0.0.1:{nobody} for selection") == 3, f"not three requests before the warning: {text}")
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    check(read_json(report_path)["selection_requests"] == 0, "the sim got a request it should not have")
    check(h.stop("asking", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    # 2. The silent gateway, by now.
    wait_for_line(h, "silent", f"no datagram on 127.0.0.1:{silent_port} for 10 s: is the robot sending here")
    check(h.stop("silent", silent) == 0, "the gateway did not exit 0 on SIGTERM")
    check(stderr_of(h, "silent").count("no datagram on") == 1, "the warning came more than once")
    text = stderr_of(h, "matched")
    check("rsg_echo: warning: matched 1 writer of 'robot_state' 5 s ago, but no sample has arrived: does the "
          "gateway get valid frames?" in text and "group of this view" not in text, text)
    check(h.stop("matched", matched) == 0, "rsg_echo did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("first_hour", body))
