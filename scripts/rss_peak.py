#!/usr/bin/env python3
"""Run a command and report its peak memory, split as Linux splits it:
anonymous memory (the heap: what the process itself allocates) and file
pages (a mapped volume's pages, which the kernel reads and drops), for the
large-volume measurements in docs/performance.md.

    python3 scripts/rss_peak.py [--every SECONDS] -- COMMAND [ARGS...]

Samples /proc/PID/status (RssAnon, RssFile) every 0.05 s by default and
prints, after the command ends, the peaks and the kernel's own VmHWM (the
peak of their sum, exact), the wall time and the exit status as one JSON
line on stderr. The command's own output passes through.
"""
import json
import subprocess
import sys
import time


def status(pid):
    out = {}
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                key, _, rest = line.partition(":")
                if key in ("RssAnon", "RssFile", "VmHWM"):
                    out[key] = int(rest.split()[0]) * 1024
    except OSError:
        pass
    return out


def main():
    args = sys.argv[1:]
    every = 0.05
    if args[:1] == ["--every"]:
        every, args = float(args[1]), args[2:]
    if args[:1] == ["--"]:
        args = args[1:]
    if not args:
        sys.exit(__doc__)
    start = time.perf_counter()
    proc = subprocess.Popen(args)
    peak = {"RssAnon": 0, "RssFile": 0, "VmHWM": 0}
    while proc.poll() is None:
        for k, v in status(proc.pid).items():
            peak[k] = max(peak[k], v)
        time.sleep(every)
    wall = time.perf_counter() - start
    gib = 1 << 30
    print(json.dumps({
        "wall_s": round(wall, 2),
        "exit": proc.returncode,
        "peak_anon_gib": round(peak["RssAnon"] / gib, 3),
        "peak_file_gib": round(peak["RssFile"] / gib, 3),
        "vm_hwm_gib": round(peak["VmHWM"] / gib, 3),
        "sampled_every_s": every,
    }), file=sys.stderr)
    sys.exit(proc.returncode)


if __name__ == "__main__":
    main()
