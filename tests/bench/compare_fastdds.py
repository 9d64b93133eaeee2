#!/usr/bin/env python3
"""Puts two `make bench` e2e runs side by side: Fast DDS 2.9 on the host and 3.x in the chroot of
tools/fastdds3/chroot.sh, run one after the other on one machine (docs/benchmarks/fastdds3/).

    compare_fastdds.py RESULTS_2X.json RESULTS_3X.json > comparison.md

Each path is judged as the e2e report judges it, by ratios within its own run: the gateway
against the leanest relay on the same Fast DDS, data-sharing against UDP. Standard library only.
"""
import json
import sys

ROWS = [  # (scenario, what it is)
    ("baseline_udp_oneway", "UDP loopback one way"),
    ("baseline_fastdds", "plain Fast DDS writer -> reader, UDP"),
    ("gateway_udp", "**gateway e2e, UDP**"),
    ("gateway_udp_ros2_standard", "**gateway e2e, UDP, + JointState, TF, wrench at 100 Hz**"),
    ("floor_relay_fastdds_to_fastdds", "leanest relay on Fast DDS -> Fast DDS reader"),
    ("floor_relay_cyclone_to_fastdds", "leanest relay on Cyclone -> Fast DDS reader"),
    ("floor_gateway_to_cyclone", "**gateway e2e, UDP -> Cyclone reader**"),
    ("floor_relay_fastdds_to_cyclone", "leanest relay on Fast DDS -> Cyclone reader"),
    ("baseline_fastdds_shm", "plain Fast DDS writer -> reader, SHM"),
    ("gateway_shm", "**gateway e2e, SHM**"),
    ("baseline_fastdds_datasharing", "plain Fast DDS writer -> reader, data-sharing"),
    ("gateway_datasharing", "**gateway e2e, data-sharing**"),
    ("embedded_callback", "**embedded gateway: datagram -> callback**"),
]


def cpu(run):
    if "gateway" in run:
        return run["gateway"].get("cpu_percent")
    return run.get("publisher_cpu_percent")


def cell(value, digits=1):
    return "–" if value is None else f"{value:,.{digits}f}"


def percent(value):
    return "–" if value is None else f"{value:.1f} %"


def ratio(a, b):
    return None if not a or not b else a / b


def main():
    old, new = (json.load(open(path)) for path in sys.argv[1:3])
    for name, run in (("2.x", old), ("3.x", new)):
        settings = run["settings"]
        print(f"- **Fast DDS {run['machine']['fastdds']}** ({name}): {run['date']}, commit {settings['commit']}, "
              f"{settings['latency_run_s']} s per latency run, {settings['max_rate_step_s']} s per max-rate step")
    machine = old["machine"]
    print(f"- Machine: {machine['cpu_model']}, {machine['cpus']} CPUs ({machine['hypervisor']} guest), "
          f"Linux {machine['kernel']}; Cyclone DDS {machine['cyclonedds']} (2.x) / {new['machine']['cyclonedds']} (3.x)")
    print()
    print("One-way latency in µs, full 2137-byte frames at 1 kHz; CPU: the publishing process, % of one core.")
    print()
    print("| path | p50 2.x | p50 3.x | p99 2.x | p99 3.x | CPU 2.x | CPU 3.x | lost 2.x / 3.x |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for scenario, label in ROWS:
        a, b = old.get(scenario), new.get(scenario)
        if not a or not b:
            continue
        print(f"| {label} | {cell(a['p50_us'])} | {cell(b['p50_us'])} | {cell(a['p99_us'])} | {cell(b['p99_us'])} "
              f"| {percent(cpu(a))} | {percent(cpu(b))} | {a['lost']} / {b['lost']} |")
    print()
    print("Ratios within each run (what the e2e goals judge):")
    print()
    print("| ratio | 2.x | 3.x |")
    print("|---|---:|---:|")
    checks = [
        ("gateway p50 / leanest Fast DDS relay p50 (Fast DDS reader)", "gateway_udp", "floor_relay_fastdds_to_fastdds",
         "p50_us"),
        ("gateway p99 / leanest Fast DDS relay p99 (Fast DDS reader)", "gateway_udp", "floor_relay_fastdds_to_fastdds",
         "p99_us"),
        ("gateway p50 / Cyclone relay p50 (Fast DDS reader)", "gateway_udp", "floor_relay_cyclone_to_fastdds", "p50_us"),
        ("gateway p50 / plain Fast DDS writer p50", "gateway_udp", "baseline_fastdds", "p50_us"),
        ("gateway data-sharing p50 / gateway UDP p50", "gateway_datasharing", "gateway_udp", "p50_us"),
        ("gateway SHM p50 / gateway UDP p50", "gateway_shm", "gateway_udp", "p50_us"),
    ]
    for label, top, bottom, key in checks:
        values = [ratio(run.get(top, {}).get(key), run.get(bottom, {}).get(key)) for run in (old, new)]
        print(f"| {label} | {cell(values[0], 2)} | {cell(values[1], 2)} |")
    cpu_ratio = [ratio(cpu(run["gateway_udp"]), cpu(run["floor_relay_fastdds_to_fastdds"])) for run in (old, new)]
    print(f"| gateway CPU / leanest Fast DDS relay CPU | {cell(cpu_ratio[0], 2)} | {cell(cpu_ratio[1], 2)} |")
    print(f"| highest loss-free rate, UDP / data-sharing (Hz) | {old['max_rate_zero_loss_hz']:,.0f} / "
          f"{old['max_rate_datasharing_zero_loss_hz']:,.0f} | {new['max_rate_zero_loss_hz']:,.0f} / "
          f"{new['max_rate_datasharing_zero_loss_hz']:,.0f} |")
    used = [run["gateway_datasharing"].get("data_sharing_used") for run in (old, new)]
    print(f"| data-sharing used by the gateway's reader | {used[0]} | {used[1]} |")


if __name__ == "__main__":
    main()
