"""SIGHUP as an attacker with a local shell, or an operator's mistake, would use it (issue 51): a
reload never opens the door.

- A file without its allow-from line (deleted, or caught half-written at a line's end), and one
  whose allow-from is 0.0.0.0/0: refused, logged at warning, counted result="refused"; 100 frames
  from an outsider (127.0.0.2) are then all rejected, none published. Before: accepted, counted
  applied, 100/100 published.
- A file caught half-written in the middle of a line (no newline at its end): not used, counted
  failed; the outsider's frames still rejected.
- A SIGHUP storm (1,000 in about a second) of a refused file: a handful of log lines, not one each.
- The control that shows the attack is real: the same file without allow-from but with
  `reload-widens-access: true` is applied (logged at warning), and then the outsider's 100 frames
  are published.
"""

import os
import signal
import sys
import time

from attack_support import checked_scrape, send_frames
from harness import check, free_udp_port, main, read_json, wait_for, wait_for_stats
from metrics_support import free_tcp_port, http_get, value_of

FRAMES = 100
STORM = 1000


def config_text(port, metrics, allow_from=None, extra=""):
    lines = [f"allow-from: [{allow_from}]"] if allow_from is not None else []
    lines += [f"listen: 127.0.0.1:{port}", "expected-rate: 100", f"metrics: 127.0.0.1:{metrics}"]
    return "\n".join(lines) + "\n" + extra


def log_text(h):
    return (h.dir / "gateway.err").read_text(errors="replace")


def reloads(h, metrics):
    samples = checked_scrape(h, metrics, "reload")
    return {result: value_of(samples, "rsg_config_reloads_total", result=result)
            for result in ("applied", "failed", "refused")}


def body(h):
    port, metrics = free_udp_port(), free_tcp_port()
    config = h.dir / "gateway.yaml"
    config.write_text(config_text(port, metrics, "127.0.0.1/32"))
    gateway, stats = h.gateway("gateway", "--config", str(config))
    wait_for(lambda: gateway.poll() is not None or http_get(metrics, "/metrics"), "the gateway's /metrics")
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()}")

    expected = {"applied": 0, "failed": 0, "refused": 0}
    rejected = 0

    def reload_with(text, result, what):
        nonlocal rejected
        config.write_text(text)
        os.kill(gateway.pid, signal.SIGHUP)
        expected[result] += 1
        wait_for(lambda: reloads(h, metrics) == expected, f"{what}: the reload counted {result}")
        check(gateway.poll() is None, f"{what}: the gateway exited {gateway.poll()}")
        # The outsider's frames: none published unless the reload was the control's.
        published = read_json(stats)["frames_published"]
        send_frames(port, FRAMES, 200, source="127.0.0.2", first=1000 * int(sum(expected.values())))
        if result == "applied":
            return wait_for_stats(stats, lambda s: s["frames_published"] == published + FRAMES,
                                  f"{what}: the outsider's frames to be published")
        rejected += FRAMES
        after = wait_for_stats(stats, lambda s: s["rejected_source"] == rejected,
                               f"{what}: the outsider's {FRAMES} frames to be rejected")
        check(after["frames_published"] == published, f"{what}: frames from outside allow-from were published")
        return after

    # 1. The allow-from line gone (or the file cut just before it).
    reload_with(config_text(port, metrics), "refused", "no allow-from")
    text = log_text(h)
    check("warning: SIGHUP: configuration not reloaded, the running one stays: allow-from would go from "
          "[127.0.0.1/32] to everyone" in text.replace("[warning]", "warning:"), f"the refusal is not logged at warning:\n{text[-2000:]}")
    # 2. Everyone, spelled out.
    reload_with(config_text(port, metrics, "127.0.0.1/32, 0.0.0.0/0"), "refused", "allow-from 0.0.0.0/0")
    # 3. Half-written, cut in the middle of a line: "expected-rate: 1" would read as 1 Hz.
    whole = config_text(port, metrics, "127.0.0.1/32")
    reload_with(whole[:whole.index("expected-rate: ") + 16], "failed", "half-written")
    check("does not end with a newline: is it still being written?" in log_text(h), "the half file's reason not logged")

    # 4. A SIGHUP storm of the refused file: counted, a few lines.
    config.write_text(config_text(port, metrics))
    lines_before = log_text(h).count("SIGHUP")
    for _ in range(STORM):
        os.kill(gateway.pid, signal.SIGHUP)
        time.sleep(0.001)
    wait_for(lambda: reloads(h, metrics)["refused"] > expected["refused"], "the storm's reloads to be counted")
    time.sleep(1.5)  # every coalesced reload taken
    after_storm = reloads(h, metrics)
    check(after_storm["applied"] == expected["applied"] and after_storm["failed"] == expected["failed"],
          f"the storm: {after_storm}")
    storm_lines = log_text(h).count("SIGHUP") - lines_before
    check(storm_lines <= 2, f"{storm_lines} log lines for {STORM} SIGHUPs ({after_storm['refused'] - expected['refused']:.0f} "
                            "reloads refused)")
    expected["refused"] = after_storm["refused"]
    print(f"storm: {STORM} SIGHUPs, {after_storm['refused']:.0f} reloads refused in all, {storm_lines} log lines")

    # 5. The control: the same file, widening on purpose, is applied and the door is open.
    reload_with(config_text(port, metrics, extra="reload-widens-access: true\n"), "applied", "the control")
    check("warning: SIGHUP: configuration reloaded: allow-from [] (was [127.0.0.1/32])"
          in log_text(h).replace("[warning]", "warning:"), "the widening reload is not logged at warning")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("attack_reload", body))
