#!/usr/bin/python3
"""Whether a pair of the evaluation set is over a bar because of one lucky or unlucky run:
EbSynth run N times on the same inputs and emaki with seeds 1..N, every output judged at full
size; prints each tool's mean, min and max of style, joint and coverage, and the ratio of means.
Uses bench/eval_set.py's pairs and data (run eval_set.py once first with the same --out).

    /usr/bin/python3 bench/eval_spread.py --ebsynth /tmp/ebsynth_src/bin/ebsynth_cpu \\
        [--emaki build/release/apps/emaki/emaki] [--judge /tmp/judge/judge] [--out /tmp/emaki_eval] \\
        [--shared ../shared] --only matcap_toon_cake,gen_stipple [--runs 5]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import eval_set as S  # noqa: E402


def judged(a, p, out):
    res = subprocess.run([a.judge] + S.args_of(p) + ["-output-to-judge", out], check=True,
                         capture_output=True, text=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ebsynth", required=True)
    ap.add_argument("--emaki", default=os.path.join(S.ROOT, "build/release/apps/emaki/emaki"))
    ap.add_argument("--judge", default="/tmp/judge/judge")
    ap.add_argument("--shared", default=os.path.join(S.ROOT, "..", "shared"))
    ap.add_argument("--out", default="/tmp/emaki_eval")
    ap.add_argument("--only", required=True, help="comma-separated pair names")
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    a.emaki = os.path.abspath(a.emaki)
    a.data = os.path.join(a.out, "data")
    pairs = {p["name"]: p for p in S.make_set(a)}
    spread = os.path.join(a.out, "spread")
    os.makedirs(spread, exist_ok=True)
    for name in a.only.split(","):
        p = pairs[name]
        eb, em = [], []
        for k in range(a.runs):
            out = os.path.join(spread, f"{name}_ebsynth{k + 1}.png")
            subprocess.run([a.ebsynth] + S.args_of(p) + ["-output", out], check=True,
                           stdout=subprocess.DEVNULL)
            eb.append(judged(a, p, out))
            out = os.path.join(spread, f"{name}_emaki_seed{k + 1}.png")
            subprocess.run([a.emaki, "synth"] + S.args_of(p) +
                           ["--seed", str(k + 1), "-output", out, "--quiet"], check=True,
                           stdout=subprocess.DEVNULL)
            em.append(judged(a, p, out))
        for key in ("style", "joint", "coverage"):
            e, m = [f[key] for f in eb], [f[key] for f in em]
            print(f"{name} {key}: EbSynth {statistics.mean(e):.6f} ({min(e):.6f}-{max(e):.6f}) "
                  f"emaki {statistics.mean(m):.6f} ({min(m):.6f}-{max(m):.6f}) "
                  f"ratio of means {statistics.mean(m) / statistics.mean(e):.3f}", flush=True)


if __name__ == "__main__":
    main()
