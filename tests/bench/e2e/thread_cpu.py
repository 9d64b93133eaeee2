#!/usr/bin/env python3
"""Per-thread CPU and wake-ups of rsg_gateway during one rsg_bench_e2e gateway run
(docs/benchmarks/latency_breakdown.md, "Gateway CPU at 1 kHz, thread by thread").

usage: thread_cpu.py TESTS_BIN_DIR SCENARIO DURATION [more rsg_bench_e2e args...]
  e.g. thread_cpu.py build/tests/bin gateway_udp 20 --writer-profile bench_writer_nack_supression_10ms

Reads utime+stime and context switches of every gateway thread from /proc over the middle of the
measured part, then names the threads from their stacks (gdb attaches after the measured part;
Fast DDS 2.9 does not name its threads)."""
import os, subprocess, sys, time, re, json
bin_dir, scenario, duration = sys.argv[1], sys.argv[2], float(sys.argv[3])
extra = sys.argv[4:]
HZ = os.sysconf("SC_CLK_TCK")
out = f"/tmp/rsg_thread_cpu_{os.getpid()}.json"
bench = subprocess.Popen([os.path.join(bin_dir, "rsg_bench_e2e"), "--scenario", scenario, "--duration", str(duration),
                          "--warmup", "2", "--out", out] + extra, stderr=subprocess.DEVNULL)
def children(pid):
    try:
        return [int(c) for c in open(f"/proc/{pid}/task/{pid}/children").read().split()]
    except OSError:
        return []
gw = None
deadline = time.time() + 30
while gw is None and time.time() < deadline:
    for c in children(bench.pid):
        try:
            if open(f"/proc/{c}/comm").read().strip() == "rsg_gateway":
                gw = c
        except OSError:
            pass
    time.sleep(0.05)
def snap(pid):
    r = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            st = open(f"/proc/{pid}/task/{tid}/stat").read()
            comm = st[st.index("(") + 1:st.rindex(")")]
            f = st[st.rindex(")") + 2:].split()
            status = open(f"/proc/{pid}/task/{tid}/status").read()
            vol = int(re.search(r"voluntary_ctxt_switches:\s+(\d+)", status).group(1))
            nonvol = int(re.search(r"nonvoluntary_ctxt_switches:\s+(\d+)", status).group(1))
            r[int(tid)] = (comm, int(f[11]), int(f[12]), vol, nonvol)
        except (OSError, ValueError):
            pass
    return r, time.time()
if gw is None:
    sys.exit("no rsg_gateway child appeared")
# Inside the measured part: after start-up and the 2 s warm-up, ending well before the last frame.
time.sleep(2 + 4 + 2)
a, ta = snap(gw)
time.sleep(max(1.0, duration - 10))
b, tb = snap(gw)
bt = subprocess.run(["gdb", "-p", str(gw), "-batch", "-nx", "-ex", "thread apply all bt 30"],
                    capture_output=True, text=True, timeout=60).stdout
bench.wait()
res = json.load(open(out)) if os.path.exists(out) else {}
if os.path.exists(out):
    os.remove(out)
# name threads by the first recognisable frame of their stack
names = {}
for block in re.split(r"\n(?=Thread \d+ )", bt):
    m = re.match(r"Thread \d+ \(Thread 0x[0-9a-f]+ \(LWP (\d+)\)", block)
    if not m:
        continue
    tid = int(m.group(1))
    frames = re.findall(r"#\d+ +(?:0x[0-9a-f]+ in )?([^\s(]+)", block)
    key = None
    for pat, label in [(r"DataSharingListener", "data-sharing listener"),
                       (r"ResourceEvent", "Fast DDS event thread (timers)"),
                       (r"UDPChannelResource::perform_listen_operation", "Fast DDS UDP receive"),
                       (r"SharedMemChannelResource", "Fast DDS SHM receive"),
                       (r"FlowController", "Fast DDS flow controller"),
                       (r"Gateway::run|Ingress::receive", "rsg ingress/main loop"),
                       (r"SecurityManager|TimedEvent", "Fast DDS timed event"),
                       (r"spdlog", "spdlog"),
                       (r"^main$", "main"),
                       (r"sigwait|signal", "signal")]:
        if any(re.search(pat, f) for f in frames):
            key = label
            break
    names[tid] = (key or "?") + " | " + " < ".join(f for f in frames[:8])
total = 0
rows = []
for tid, (comm, ut, stt, vol, nv) in sorted(b.items()):
    if tid not in a:
        continue
    d = (ut + stt - a[tid][1] - a[tid][2]) / HZ / (tb - ta) * 100
    total += d
    rows.append((tid, comm, d, (ut - a[tid][1]) / HZ / (tb - ta) * 100, (stt - a[tid][2]) / HZ / (tb - ta) * 100,
                 (vol - a[tid][3]) / (tb - ta), (nv - a[tid][4]) / (tb - ta), names.get(tid, "?")))
print(f"{scenario} {' '.join(extra)}: interval {tb-ta:.1f}s, load {open('/proc/loadavg').read().split()[0]}, total {total:.2f} %, bench p50 {res.get('p50_us')}, bench cpu {res.get('gateway',{}).get('cpu_percent')}")
for tid, comm, d, u, s, vol, nv, name in rows:
    print(f"  {tid:7d} {comm:16s} {d:6.2f} % (user {u:5.2f} sys {s:5.2f})  wakeups/s {vol:7.1f} preempt/s {nv:6.1f}  {name[:200]}")
