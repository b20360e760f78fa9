#!/usr/bin/env python3
"""Prints the time of emaki.synthesize on StyLit against `emaki synth` on the same files,
excluding file decoding: the CLI's own "synthesis" figure (EbSynth's channel rules and the
engine, after decoding, before writing) against the Python call on arrays already decoded
(rules, engine, and the result made a numpy array). Runs alternate, so each pair sees about the
same load on a shared machine; the figures to read are the medians of the pairs' ratios, of
wall time and of CPU time (the CLI prints the CPU seconds of its synthesis; here the process's
CPU time over the call, every engine thread counted): CPU time moves much less than wall time
when other jobs share the cores.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_overhead.py [RUNS [THREADS]]

THREADS (default 0: all cores) goes to both; 1 makes each run less sensitive to other jobs on a
shared machine.
"""

import os
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time

import emaki

ROOT = pathlib.Path(__file__).resolve().parents[1]
STYLIT = ROOT / "examples" / "stylit"
BINARY = os.environ.get("EMAKI_BINARY", str(ROOT / "build" / "release" / "apps" / "emaki" / "emaki"))
GUIDES = ["fullgi", "dirdif", "dirspc", "indirb"]


def cli_seconds(out, threads):
    args = [BINARY, "synth", "-style", STYLIT / "source_style.png", "-output", out,
            "--threads", threads]
    for g in GUIDES:
        args += ["-guide", STYLIT / ("source_%s.png" % g), STYLIT / ("target_%s.png" % g),
                 "-weight", "0.5"]
    proc = subprocess.run([str(a) for a in args], capture_output=True, text=True, check=True)
    m = re.search(r"synthesis ([0-9.]+) s, ([0-9.]+) CPU s", proc.stderr)
    return float(m.group(1)), float(m.group(2))


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    style = emaki.read_image(STYLIT / "source_style.png")
    guides = [(emaki.read_image(STYLIT / ("source_%s.png" % g)),
               emaki.read_image(STYLIT / ("target_%s.png" % g)), 0.5) for g in GUIDES]
    cli, py, cli_cpu, py_cpu = [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "out.png"
        cli_seconds(out, threads)  # warm the page cache and the binary
        for i in range(runs):
            wall, cpu = cli_seconds(out, threads)
            cli.append(wall)
            cli_cpu.append(cpu)
            start, cpu = time.perf_counter(), time.process_time()
            result = emaki.synthesize(style, guides, threads=threads)
            py.append(time.perf_counter() - start)
            py_cpu.append(time.process_time() - cpu)
            print("run %d: emaki synth %.3f s (%.3f CPU s), emaki.synthesize %.3f s (%.3f CPU s)"
                  % (i + 1, cli[-1], cli_cpu[-1], py[-1], py_cpu[-1]), flush=True)
        same = (result == emaki.read_image(out)).all()
    c, p = statistics.median(cli), statistics.median(py)
    print("StyLit 1200x912, 4 guides, threads %d, %d runs each, alternating:" % (threads, runs))
    print("  emaki synth       median %.3f s (min %.3f), %.3f CPU s"
          % (c, min(cli), statistics.median(cli_cpu)))
    print("  emaki.synthesize  median %.3f s (min %.3f), %.3f CPU s"
          % (p, min(py), statistics.median(py_cpu)))
    ratio = statistics.median(b / a for a, b in zip(cli, py))
    cpu_ratio = statistics.median(b / a for a, b in zip(cli_cpu, py_cpu))
    print("  overhead, wall time: %+.1f %% (median of the %d pairs' ratios), %+.1f %% (medians), "
          "%+.1f %% (minima)" % (100 * (ratio - 1), runs, 100 * (p / c - 1),
                                 100 * (min(py) / min(cli) - 1)))
    print("  overhead, CPU time:  %+.1f %% (median of the pairs' ratios)" % (100 * (cpu_ratio - 1)))
    print("  same pixels: %s" % same)


if __name__ == "__main__":
    main()
