#!/usr/bin/env python3
"""Prints how long two Python threads take to synthesize at once against one alone: the GIL is
released while the engine runs, so on a machine with two free cores two one-thread syntheses
take about as long as one (ratio near 1; with the GIL held it would be 2).

Also printed, for a machine busy with other jobs (where the ratio says little): the process's
CPU seconds per wall second while the two run (each call uses one engine thread, so with the
GIL held it would stay at or below 1.0), and how often the two calls' pyramid levels alternate
(the engine reports each level as it starts; with the GIL held for a whole call, one call's
levels would all come before the other's: 1 switch).

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_gil.py [REPEATS]
"""

import pathlib
import statistics
import sys
import threading
import time

import numpy as np

import emaki

ROOT = pathlib.Path(__file__).resolve().parents[1]
STYLIT = ROOT / "examples" / "stylit"
GUIDES = ["fullgi", "dirdif", "dirspc", "indirb"]


def half(a):
    h, w, c = a.shape
    return np.ascontiguousarray(a.reshape(h // 2, 2, w // 2, 2, c).mean(axis=(1, 3)).astype(np.float32) / 255)


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    style = half(emaki.read_image(STYLIT / "source_style.png"))
    guides = [(half(emaki.read_image(STYLIT / ("source_%s.png" % g))),
               half(emaki.read_image(STYLIT / ("target_%s.png" % g))), 0.5) for g in GUIDES]

    def one(events=None, tag=0):
        progress = None if events is None else (
            lambda level, levels: events.append((time.perf_counter(), tag, level)))
        emaki.synthesize(style, guides, threads=1, progress=progress)

    one()  # warm up
    alone, both, parallelism, mixed = [], [], [], []
    for _ in range(repeats):
        start = time.perf_counter()
        one()
        alone.append(time.perf_counter() - start)
        events = []
        threads = [threading.Thread(target=one, args=(events, k)) for k in range(2)]
        start, cpu = time.perf_counter(), time.process_time()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        both.append(time.perf_counter() - start)
        parallelism.append((time.process_time() - cpu) / both[-1])
        # Pyramid levels start inside the engine: with the GIL held for a whole call, one
        # call's levels would all come before the other's.
        order = [tag for _, tag, _ in sorted(events)]
        mixed.append(sum(a != b for a, b in zip(order, order[1:])))
        print("one alone %.3f s, two at once %.3f s (%.2f CPU s per s, level starts alternate "
              "%d times)" % (alone[-1], both[-1], parallelism[-1], mixed[-1]), flush=True)
    a, b = statistics.median(alone), statistics.median(both)
    print("StyLit 600x456, threads=1 per call, %d repeats:" % repeats)
    print("  one synthesis alone      median %.3f s" % a)
    print("  two threads at once      median %.3f s" % b)
    pairs = statistics.median(y / x for x, y in zip(alone, both))
    print("  ratio two / one: %.2f (median of the repeats' ratios; %.2f of the medians)"
          % (pairs, b / a))
    print("  (1.0: the two run in parallel; 2.0: serialised, as with the GIL held)")
    print("  CPU seconds per wall second with two at once: median %.2f (max %.2f; <= 1.0 if "
          "serialised)" % (statistics.median(parallelism), max(parallelism)))
    print("  the two calls' pyramid levels interleave: %d switches per run (median; 1 if the GIL "
          "serialised the calls)" % statistics.median(mixed))


if __name__ == "__main__":
    main()
