#!/usr/bin/env python3
"""Where a thread waited: its off-CPU intervals, longest first, each with the stack it left the CPU
with and the stack of the thread that woke it (docs/benchmarks/readers/README.md).

Record while the scenario runs (as root; TID = the thread to judge, for rsg_gateway its main
thread, i.e. its pid):

  perf record -a -e sched:sched_switch --filter "prev_pid == TID || next_pid == TID" \\
              -e sched:sched_wakeup --filter "pid == TID" --call-graph dwarf,8192 -o trace.data
  perf script -i trace.data -F comm,tid,time,event,trace,ip,sym > trace.txt
  offcpu.py trace.txt TID [--top 25]

Waits for the next datagram (UdpSocket::wait_readable) are the robot's silences, listed apart.
"""
import argparse
import re
import sys

HEADER = re.compile(r"\s*(.*?)\s+(\d+)\s+([\d.]+):\s+sched:(\w+):\s+(.*)")
SWITCH = re.compile(r"prev_pid=(\d+) .*prev_state=(\S+) ==> .*next_pid=(\d+)")


def read_events(path):
    events = []
    for line in open(path, errors="replace"):
        if not line.strip():
            continue
        if not line.startswith("\t"):
            match = HEADER.match(line)
            events.append(None if match is None else {
                "comm": match[1], "time": float(match[3]), "event": match[4], "args": match[5], "stack": []})
        elif events and events[-1] is not None:
            frame = line.split(None, 1)
            events[-1]["stack"].append(frame[1].split(" (")[0].strip() if len(frame) > 1 else "?")
    return [event for event in events if event is not None]


def intervals(events, tid):
    """(seconds off CPU, state, stack at leaving, start time, waking event or None)."""
    left, waker, found = None, None, []
    for event in events:
        if event["event"] == "sched_switch":
            prev_pid, state, next_pid = SWITCH.search(event["args"]).groups()
            if int(prev_pid) == tid:
                left, waker = event, None
            elif int(next_pid) == tid and left is not None:
                found.append((event["time"] - left["time"], state_of(left), left["stack"], left["time"], waker))
                left = None
        elif event["event"] == "sched_wakeup" and left is not None:
            waker = event
    return sorted(found, key=lambda interval: -interval[0])


def state_of(event):
    return SWITCH.search(event["args"])[2]


def frames(stack, skip, count):
    return " < ".join(stack[skip:skip + count])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trace", help="perf script output")
    parser.add_argument("tid", type=int)
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()
    found = intervals(read_events(args.trace), args.tid)
    if not found:
        sys.exit(f"offcpu.py: no interval of thread {args.tid} in {args.trace}")
    waits = [interval for interval in found if "wait_readable" not in frames(interval[2], 0, 40)]
    print(f"{len(found)} intervals off CPU; the longest waits other than for the next datagram:")
    for seconds, state, stack, start, waker in waits[:args.top]:
        print(f"{seconds * 1e3:8.2f} ms {state:2} at {start:.3f}: {frames(stack, 4, 12)}")
        if waker is not None:
            print(f"            woken by {waker['comm']}: {frames(waker['stack'], 3, 14)}")
    silences = [interval for interval in found if interval not in waits]
    if silences:
        print(f"longest wait for the next datagram: {silences[0][0] * 1e3:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
