#!/usr/bin/env python3
"""One frame's way through a floor scenario, step by step, from a `perf script` trace.

    breakdown.py TRACE --sender PID --children PID,PID --scenario NAME --result RESULT_JSON

TRACE is `perf script -F comm,pid,tid,cpu,time,event,trace` of sched_switch, sched_wakeup and
raw_syscalls. The sender is rsg_bench_e2e's main thread (sendto, syscall 44, once per frame); the
relay is the child that wakes first after it; the reader is the first other thread woken after
the relay's first send. Prints the median (and p90) of each step over all frames, in us.
"""

import argparse
import json
import re
import statistics
from collections import defaultdict

LINE = re.compile(r"^\s*(?P<comm>.+?)\s+(?P<pid>\d+)/(?P<tid>\d+)\s+\[(?P<cpu>\d+)\]\s+(?P<time>[\d.]+):\s+"
                  r"(?P<event>[\w:]+):\s*(?P<trace>.*)$")
SENDTO, RECVFROM, SENDMSG, RECVMSG, RECVMMSG, SENDMMSG, FUTEX = 44, 45, 46, 47, 299, 307, 202
POLLS = {7, 271, 232, 281, 23, 270}  # poll, ppoll, epoll_wait, epoll_pwait, select, pselect6
SENDS = {SENDTO, SENDMSG, SENDMMSG}
RECVS = {RECVFROM, RECVMSG, RECVMMSG}


def parse(path):
    events = []
    with open(path, encoding="utf-8", errors="replace") as lines:
        for line in lines:
            m = LINE.match(line)
            if not m:
                continue
            e = {"pid": int(m["pid"]), "tid": int(m["tid"]), "cpu": int(m["cpu"]), "t": float(m["time"]) * 1e6,
                 "event": m["event"], "trace": m["trace"]}
            if e["event"].startswith("raw_syscalls"):
                nr = re.search(r"NR (\d+)", e["trace"])
                e["nr"] = int(nr.group(1)) if nr else -1
            elif e["event"] == "sched:sched_wakeup":
                woken = re.search(r"pid=(\d+)", e["trace"])
                e["woken"] = int(woken.group(1)) if woken else -1
            elif e["event"] == "sched:sched_switch":
                nxt = re.search(r"next_pid=(\d+)", e["trace"])
                e["next"] = int(nxt.group(1)) if nxt else -1
            events.append(e)
    return events


def first(events, start, predicate, limit_us=5000):
    for i in range(start, len(events)):
        if events[i]["t"] - events[start]["t"] > limit_us:
            return None
        if predicate(events[i]):
            return i
    return None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("trace")
    parser.add_argument("--sender", type=int, required=True)
    parser.add_argument("--children", default="")
    parser.add_argument("--scenario", default="")
    parser.add_argument("--result", default="")
    args = parser.parse_args()
    children = {int(c) for c in args.children.split(",") if c}
    events = parse(args.trace)
    tids_of = defaultdict(set)
    for e in events:
        tids_of[e["pid"]].add(e["tid"])

    steps = defaultdict(list)
    counts = defaultdict(list)
    relay_pid = reader_tid = None
    for i, e in enumerate(events):
        if not (e["tid"] == args.sender and e["event"] == "raw_syscalls:sys_enter" and e["nr"] == SENDTO):
            continue
        t0 = e["t"]
        # The relay's receiving thread: the first child thread woken after the datagram left.
        w = first(events, i, lambda x: x["event"] == "sched:sched_wakeup" and
                  any(x["woken"] in tids_of[c] for c in children))
        if w is None:
            continue
        relay_tid = events[w]["woken"]
        relay = next(c for c in children if relay_tid in tids_of[c])
        run = first(events, w, lambda x: x["event"] == "sched:sched_switch" and x["next"] == relay_tid)
        got = first(events, w, lambda x: x["tid"] == relay_tid and x["event"] == "raw_syscalls:sys_exit"
                    and x["nr"] in RECVS)
        if run is None or got is None:
            continue
        send = first(events, got, lambda x: x["pid"] == relay and x["event"] == "raw_syscalls:sys_enter"
                     and x["nr"] in SENDS)
        if send is None:
            continue
        sent = first(events, send, lambda x: x["tid"] == events[send]["tid"] and
                     x["event"] == "raw_syscalls:sys_exit")
        futexes = sum(1 for x in events[got:send] if x["tid"] == relay_tid and x["event"] == "raw_syscalls:sys_enter"
                      and x["nr"] == FUTEX)
        # The reader's receiving thread: the first thread outside the relay and the sender woken
        # after the relay's send.
        rw = first(events, send, lambda x: x["event"] == "sched:sched_wakeup" and x["woken"] != args.sender
                   and x["woken"] not in tids_of[relay] and x["woken"] > 0
                   and any(x["woken"] in tids_of[p] for p in [args.sender, *children]))
        if rw is None or sent is None:
            continue
        reader = events[rw]["woken"]
        rrun = first(events, rw, lambda x: x["event"] == "sched:sched_switch" and x["next"] == reader)
        rgot = first(events, rw, lambda x: x["tid"] == reader and x["event"] == "raw_syscalls:sys_exit"
                     and x["nr"] in RECVS)
        if rrun is None or rgot is None:
            continue
        rdone = first(events, rgot, lambda x: x["tid"] == reader and x["event"] == "raw_syscalls:sys_enter")
        if rdone is None:
            continue
        relay_pid, reader_tid = relay, reader
        s = steps
        s["1 sendto -> relay thread woken (kernel loopback)"].append(events[w]["t"] - t0)
        s["2 woken -> running (scheduler)"].append(events[run]["t"] - events[w]["t"])
        s["3 running -> datagram in hand (poll/recv return)"].append(events[got]["t"] - events[run]["t"])
        s["4 datagram -> DDS send syscall (decode, write, DDS stack)"].append(events[send]["t"] - events[got]["t"])
        s["5 DDS send syscall"].append(events[sent]["t"] - events[send]["t"])
        s["6 send -> reader thread woken (kernel loopback)"].append(events[rw]["t"] - events[send]["t"])
        s["7 woken -> running (scheduler)"].append(events[rrun]["t"] - events[rw]["t"])
        s["8 running -> datagram in hand"].append(events[rgot]["t"] - events[rrun]["t"])
        s["9 datagram -> next syscall (DDS receive path, listener, take)"].append(events[rdone]["t"] - events[rgot]["t"])
        s["total sendto -> reader done"].append(events[rdone]["t"] - t0)
        counts["futex calls by the relay thread between recv and send"].append(futexes)
        counts["reader woken on a thread other than the relay's CPU"].append(int(events[rw]["cpu"] != events[send]["cpu"]))

    n = len(steps["total sendto -> reader done"])
    result = json.load(open(args.result)) if args.result else {}
    print(f"## {args.scenario}: {n} frames traced (relay pid {relay_pid}, reader tid {reader_tid})")
    if result:
        print(f"bench over the same run: p50 {result.get('p50_us', 0):.1f} us, p99 {result.get('p99_us', 0):.1f} us")
    print()
    print("| step | p50 µs | p90 µs |")
    print("|---|---:|---:|")
    for name, values in sorted(steps.items()):
        values = sorted(values)
        print(f"| {name} | {statistics.median(values):.1f} | {values[int(0.9 * (len(values) - 1))]:.1f} |")
    for name, values in counts.items():
        print(f"| {name} (mean) | {statistics.mean(values):.2f} | |")


if __name__ == "__main__":
    main()
