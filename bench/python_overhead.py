#!/usr/bin/env python3
"""Prints the time of emaki.synthesize on StyLit against `emaki synth` on the same files,
excluding file decoding: the CLI's own "synthesis" figure (EbSynth's channel rules and the
engine, after decoding, before writing) against the Python call on arrays already decoded
(rules, engine, and the result made a numpy array). Runs alternate, so each pair sees about the
same load on a shared machine; the figure to read is the median of the pairs' ratios.

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
    return float(re.search(r"synthesis ([0-9.]+) s", proc.stderr).group(1))


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    style = emaki.read_image(STYLIT / "source_style.png")
    guides = [(emaki.read_image(STYLIT / ("source_%s.png" % g)),
               emaki.read_image(STYLIT / ("target_%s.png" % g)), 0.5) for g in GUIDES]
    cli, py = [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "out.png"
        cli_seconds(out, threads)  # warm the page cache and the binary
        for i in range(runs):
            cli.append(cli_seconds(out, threads))
            start = time.perf_counter()
            result = emaki.synthesize(style, guides, threads=threads)
            py.append(time.perf_counter() - start)
            print("run %d: emaki synth %.3f s, emaki.synthesize %.3f s" % (i + 1, cli[-1], py[-1]),
                  flush=True)
        same = (result == emaki.read_image(out)).all()
    c, p = statistics.median(cli), statistics.median(py)
    print("StyLit 1200x912, 4 guides, threads %d, %d runs each, alternating:" % (threads, runs))
    print("  emaki synth       median %.3f s (min %.3f)" % (c, min(cli)))
    print("  emaki.synthesize  median %.3f s (min %.3f)" % (p, min(py)))
    ratio = statistics.median(b / a for a, b in zip(cli, py))
    print("  overhead: %+.1f %% (median of the %d pairs' ratios), %+.1f %% (medians), %+.1f %% "
          "(minima); same pixels: %s" % (100 * (ratio - 1), runs, 100 * (p / c - 1),
                                         100 * (min(py) / min(cli) - 1), same))


if __name__ == "__main__":
    main()
