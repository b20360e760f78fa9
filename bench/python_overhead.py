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

    ... bench/python_overhead.py --instructions

counts instead the instructions each executes (valgrind's callgrind, one thread, StyLit at
half size), which no other job can disturb: the engine's own functions (rules, Synthesizer)
in each, and the whole synthesis region in each (the CLI: from the decoded files to B'; Python:
the whole emaki.synthesize call, arrays in and out).
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


ENGINE = ["emaki::synth::apply_ebsynth_rules*", "emaki::synth::Synthesizer::Synthesizer*",
          "emaki::synth::RuledInputs::release_guides*", "emaki::synth::Synthesizer::run*"]
CLI_REGION = ["emaki::app::(anonymous namespace)::ruled_inputs*"] + ENGINE[1:]
PY_REGION = ["emaki::python::(anonymous namespace)::synthesize*"]
PY_CALL = """
import emaki
s = emaki.read_image('source_style.png')
g = [(emaki.read_image('source_%s.png' % n), emaki.read_image('target_%s.png' % n), 0.5)
     for n in ('fullgi', 'dirdif', 'dirspc', 'indirb')]
emaki.write_image('py.png', emaki.synthesize(s, g, threads=1))
"""


def callgrind(folder, functions, command):
    """Instructions executed inside `functions` (callgrind's --toggle-collect)."""
    toggles = ["--toggle-collect=%s" % f for f in functions]
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.abspath(emaki.__file__)))
    proc = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                           "--collect-atstart=no", *toggles, *command], cwd=folder, env=env,
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return int(re.search(r"Collected : (\d+)", proc.stderr).group(1))


def instructions():
    import numpy as np
    with tempfile.TemporaryDirectory() as tmp:
        for name in ["source_style"] + ["%s_%s" % (s, g) for g in GUIDES for s in ("source", "target")]:
            a = emaki.read_image(STYLIT / (name + ".png"))
            h, w, c = a.shape
            m = a.reshape(h // 2, 2, w // 2, 2, c).astype(np.float64).mean(axis=(1, 3))
            emaki.write_image(pathlib.Path(tmp) / (name + ".png"), np.floor(m + 0.5).astype(np.uint8))
        cli = [BINARY, "synth", "-style", "source_style.png", "-output", "cli.png", "--threads", "1"]
        for g in GUIDES:
            cli += ["-guide", "source_%s.png" % g, "target_%s.png" % g, "-weight", "0.5"]
        py = [sys.executable, "-c", PY_CALL]
        figures = [(label, callgrind(tmp, region, cmd))
                   for label, region, cmd in [
                       ("emaki synth, engine", ENGINE, cli), ("emaki.synthesize, engine", ENGINE, py),
                       ("emaki synth, synthesis region", CLI_REGION, cli),
                       ("emaki.synthesize, whole call", PY_REGION, py)]]
        same = (emaki.read_image(pathlib.Path(tmp) / "cli.png") ==
                emaki.read_image(pathlib.Path(tmp) / "py.png")).all()
    print("StyLit 600x456, 4 guides, one thread, instructions (callgrind):")
    for label, n in figures:
        print("  %-32s %15d" % (label, n))
    print("  engine: %+.3f %%; whole call against the CLI's synthesis: %+.3f %%; same pixels: %s"
          % (100 * (figures[1][1] / figures[0][1] - 1), 100 * (figures[3][1] / figures[2][1] - 1),
             same))


def main():
    if sys.argv[1:2] == ["--instructions"]:
        instructions()
        return
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
