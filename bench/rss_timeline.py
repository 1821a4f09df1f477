#!/usr/bin/env python3
"""Resident set of every running pfem-mpi rank over time, sampled from /proc every 20 ms.

Usage: start a run, then `python3 bench/rss_timeline.py OUT.txt` on the same machine; it writes
`time pid rss_MB` lines until the ranks exit (or after 20 minutes). VmHWM (the run's closing
table) says how high the resident set went; this says when, which a heap profiler cannot: a
heap peak and an RSS peak differ where freed pages stay resident.
"""
import os
import subprocess
import sys
import time


def ranks():
    found = subprocess.run(["pgrep", "-f", "pfem-mpi"], capture_output=True, text=True).stdout
    pids = []
    for pid in found.split():
        try:
            cmd = open(f"/proc/{pid}/cmdline").read()
        except OSError:
            continue
        if "mpirun" not in cmd and "rss_timeline" not in cmd and "pgrep" not in cmd:
            pids.append(pid)
    return pids


def main():
    out = open(sys.argv[1], "w")
    deadline = time.time() + 1200
    pids = []
    while not pids and time.time() < deadline:
        pids = ranks()
        time.sleep(0.2)
    while time.time() < deadline:
        alive = False
        for pid in pids:
            try:
                status = open(f"/proc/{pid}/status").read()
            except OSError:
                continue
            alive = True
            rss_kb = int(status.split("VmRSS:")[1].split()[0])
            out.write(f"{time.time():.2f} {pid} {rss_kb // 1024}\n")
        if not alive:
            break
        time.sleep(0.02)


if __name__ == "__main__":
    main()
