"""Shots and syntheses called from several Python threads at once: each call keeps its own
thread count and its own pixel budget, and the results are those of the calls made one by one."""

import threading

import numpy as np
import pytest

import emaki
from test_shot import digests, tiny


def noise(shape, seed):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def synth_once(threads):
    style, src, tgt = noise((48, 56, 3), 1), noise((48, 56, 3), 2), noise((40, 64, 3), 3)
    return emaki.synthesize(style, [(src, tgt)], threads=threads, search_vote_iters=2)


def test_shot_runs_and_syntheses_in_several_threads_at_once(tmp_path):
    # Each run used to reset the process-wide task arena under the other threads' work: SIGSEGV.
    expected_synth = synth_once(1)
    alone = emaki.Shot.from_dict(tiny(tmp_path / "alone"))
    alone.run(previews=False, threads=1)
    expected = digests(tmp_path / "alone")
    shots = [emaki.Shot.from_dict(tiny(tmp_path / ("s%d" % i))) for i in range(3)]
    errors = []
    running = [len(shots)]

    def run_shot(i):
        try:
            for k in range(3):
                shots[i].run(previews=False, force=True, threads=(i + k) % 3)
                if digests(tmp_path / ("s%d" % i)) != expected:
                    errors.append("shot %d differs" % i)
        except Exception as e:  # reported below, with the others
            errors.append(repr(e))
        finally:
            running[0] -= 1

    def run_synth(threads):
        try:
            while True:
                if not np.array_equal(synth_once(threads), expected_synth):
                    errors.append("synthesis with %d threads differs" % threads)
                if running[0] == 0:
                    break
        except Exception as e:
            errors.append(repr(e))

    workers = [threading.Thread(target=run_shot, args=(i,)) for i in range(len(shots))]
    workers += [threading.Thread(target=run_synth, args=(t,)) for t in (0, 2)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    assert errors == []


def test_a_shots_pixel_budget_stays_with_that_shot(tmp_path):
    small = tiny(tmp_path / "small")
    small["limits"] = {"max_pixels": 1}
    with pytest.raises(emaki.InputError) as e:
        emaki.Shot.from_dict(small)
    assert e.value.subject == "source.size"
    # Nothing the failed shot asked for outlives it.
    out = synth_once(0)
    assert out.shape == (40, 64, 3)
    # A budget that fits one shot's frames governs that shot only.
    fits = tiny(tmp_path / "fits")
    fits["limits"] = {"max_pixels": 64 * 36}
    assert emaki.Shot.from_dict(fits).size == (64, 36)
    big = tiny(tmp_path / "big")
    big["source"]["size"] = [128, 72]
    assert emaki.Shot.from_dict(big).size == (128, 72)
    assert synth_once(0).shape == (40, 64, 3)
