"""The GIL is released while the engine runs, and Ctrl-C stops it cleanly.

(Timing figures — two threads at once against one — are in bench/python_gil.py; tests never
time things. This test checks instead that another Python thread makes progress.)"""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np

import emaki

HERE = os.path.dirname(os.path.abspath(__file__))


def noise(shape, seed):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def test_another_python_thread_runs_while_synthesize_runs():
    style, src, tgt = noise((160, 200, 3), 1), noise((160, 200, 3), 2), noise((160, 200, 3), 3)
    counter = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1

    worker = threading.Thread(target=count)
    worker.start()
    try:
        time.sleep(0.2)
        a = counter[0]
        time.sleep(0.2)
        alone = counter[0] - a  # in 0.2 s while this thread sleeps
        before = counter[0]
        start = time.perf_counter()
        emaki.synthesize(style, [(src, tgt)], threads=1, search_vote_iters=4)
        seconds = time.perf_counter() - start
        during = counter[0] - before
    finally:
        stop.set()
        worker.join()
    # With the GIL held for the call, the counter would stand still; released, it runs at a
    # good part of its own pace (the engine uses one thread of this machine's cores).
    assert seconds > 0.2, seconds
    assert during > 0.1 * alone * seconds / 0.2, (during, alone, seconds)


INTERRUPTED = r"""
import sys, time
import numpy as np
import emaki
rng = np.random.default_rng(1)
style = rng.random((256, 256, 3), dtype=np.float32)
src, tgt = rng.random((256, 256, 3), dtype=np.float32), rng.random((256, 256, 3), dtype=np.float32)
print("ready", flush=True)
try:
    # EbSynth's uniform schedule with many iterations: minutes of work.
    emaki.synthesize(style, [(src, tgt)], search_vote_iters=500, patch_match_iters=4)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
"""


def test_ctrl_c_interrupts_a_long_synthesis():
    env = dict(os.environ)
    proc = subprocess.Popen([sys.executable, "-c", INTERRUPTED], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(1.0)
        sent = time.perf_counter()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
        latency = time.perf_counter() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert out.strip() == "interrupted", (out, err)
    assert proc.returncode == 0, err
    assert latency < 5.0, latency  # within a sweep or two, not after the minutes of work
