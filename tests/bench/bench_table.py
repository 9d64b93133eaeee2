#!/usr/bin/env python3
"""Prints Google Benchmark JSON results as a markdown table, each benchmark also as a ratio to the
ISA-L CRC of the same frame.

    bench_table.py RESULTS.json [...]

Names follow BM_<operation>_<frame>; the baseline of BM_X_<frame> is BM_Crc32Isal_<frame>. Times are
the median CPU time over the repetitions (CPU rather than wall time: on a shared machine the
benchmark thread is sometimes descheduled, which wall time would count). Standard library only.
"""

import json
import sys

UNITS_PER_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def aggregates(results):
    """{benchmark name: {aggregate name: entry}}, in the order the benchmarks ran; a run without
    repetitions counts as its own median."""
    table = {}
    for entry in results["benchmarks"]:
        name = entry.get("run_name", entry["name"])
        kind = entry.get("aggregate_name", "median") if entry.get("run_type") == "aggregate" else "median"
        table.setdefault(name, {}).setdefault(kind, entry)
    return table


def cpu_ns(entry):
    return entry["cpu_time"] * UNITS_PER_NS[entry.get("time_unit", "ns")]


def print_table(path):
    with open(path, encoding="utf-8") as file:
        results = json.load(file)
    context = results["context"]
    print(f"`{path}`: {context.get('date', '?')}, {context.get('host_name', '?')}, "
          f"{context.get('num_cpus', '?')} CPUs at {context.get('mhz_per_cpu', '?')} MHz, "
          f"load average {', '.join(f'{x:.2f}' for x in context.get('load_avg', [])) or '?'}")
    print()
    print("| benchmark | median CPU time | spread (cv) | throughput | × CRC ISA-L |")
    print("|---|---:|---:|---:|---:|")
    table = aggregates(results)
    for name, kinds in table.items():
        median = kinds["median"]
        frame = name.rsplit("_", 1)[-1]
        baseline = table.get(f"BM_Crc32Isal_{frame}", {}).get("median")
        ratio = f"{cpu_ns(median) / cpu_ns(baseline):.2f}" if baseline else ""
        cv = kinds.get("cv")
        spread = f"{cv['cpu_time'] * 100:.1f} %" if cv else ""
        rate = median.get("bytes_per_second")
        throughput = f"{rate / 1e9:.2f} GB/s" if rate else ""
        print(f"| {name} | {cpu_ns(median):.1f} ns | {spread} | {throughput} | {ratio} |")
    print()


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        print_table(path)


if __name__ == "__main__":
    main()
