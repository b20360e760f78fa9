#!/usr/bin/python3
"""Measures emaki on the bundled examples and prints docs/performance.md's tables (Markdown),
each under the command that makes it, so a figure there is re-measured, never edited.

Builds nothing: it runs the release build's programs (`emaki`, `bench/synth_bench`,
`bench/render_bench`, `bench/shot_bench`, `bench/temporal_bench`) and the Python module at modest
sizes; the default run takes a few minutes on 2 cores. Wall seconds depend on the machine and on
whatever else runs on it: compare figures as ratios, measured in one run of this script.

    /usr/bin/python3 bench/performance.py [--build build/release] [--runs 3] [--full]
        [--only synth,scaling,memory,render,shot,run,temporal,python]
        [--ebsynth PATH/TO/ebsynth] [--judge PATH/TO/judge] > performance.md

--full measures the bundled shot at its own size and length (48 frames, 960x540, previews: the
README's command) and the temporal table over 48 frames at 960x540, instead of 6 frames and
16 frames at 480x270. --ebsynth adds EbSynth's CPU build (built outside the project:
jamriska/ebsynth) on the same StyLit command line; --judge (../shared/tools/judge, built with its
build.sh) adds the judge's figures of both outputs and of the temporal variants.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STYLIT = os.path.join(ROOT, "examples", "stylit")
GUIDES = ("fullgi", "dirdif", "dirspc", "indirb")
HUGE_OFF = "glibc.malloc.hugetlb=0"
HUGE_ON = "glibc.malloc.hugetlb=1"


def stylit_args():
    a = ["-style", os.path.join(STYLIT, "source_style.png")]
    for g in GUIDES:
        a += ["-guide", os.path.join(STYLIT, f"source_{g}.png"),
              os.path.join(STYLIT, f"target_{g}.png"), "-weight", "0.5"]
    return a


def run_timed(cmd, env=None, cwd=None):
    """Runs cmd; returns its wall seconds, CPU seconds (user + system), minor page faults, peak
    RSS in MB (the child's own, from wait4) and stdout. Exits with its error when it fails."""
    e = dict(os.environ)
    e.update(env or {})
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        t0 = time.monotonic()
        p = subprocess.Popen(cmd, stdout=out, stderr=err, env=e, cwd=cwd, text=True)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.monotonic() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        if p.returncode != 0:
            sys.exit(f"performance.py: {shown(cmd)} failed ({p.returncode}): "
                     f"{err.read().strip()[-400:]}")
        return dict(wall=wall, cpu=ru.ru_utime + ru.ru_stime, faults=ru.ru_minflt,
                    rss=ru.ru_maxrss / 1024, out=out.read())


def median(runs, key):
    return statistics.median(r[key] for r in runs)


def spread(runs, key, fmt="{:.2f}"):
    v = [r[key] for r in runs]
    if len(v) == 1:
        return fmt.format(v[0])
    return (fmt + " ({}-{})").format(statistics.median(v), fmt.format(min(v)), fmt.format(max(v)))


def runs_text(n, how="median"):
    return "one run" if n == 1 else f"{how} of {n} runs"


def times_text(n):
    return "once each, alternated," if n == 1 else f"alternated {n} times"


def thp_mode():
    try:
        text = open("/sys/kernel/mm/transparent_hugepage/enabled").read()
        m = re.search(r"\[(\w+)\]", text)
        return m.group(1) if m else text.strip()
    except OSError:
        return "unknown"


def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


SCRATCH = []  # the temporary folder, shown as OUT


def shown(cmd):
    """A command as the reader would type it from the repository root (E=examples/stylit)."""
    s = " ".join(cmd).replace(STYLIT + "/", "$E/").replace(ROOT + "/", "")
    for t in SCRATCH:
        s = s.replace(t, "OUT")
    return s.replace(" -guide", " \\\n    -guide").replace(" -output", " \\\n    -output")


# ---------------------------------------------------------------------------------------------
# Sections: each returns Markdown lines.


def section_synth(a, emaki, tmp):
    out = os.path.join(tmp, "stylit.png")
    cmd = [emaki, "synth"] + stylit_args() + ["-output", out, "--quiet"]
    runs = [run_timed(cmd) for _ in range(a.runs)]
    lines = ["## Synthesis: EbSynth's StyLit example", "",
             "StyLit, 1200x912, a 3-channel style and 4 RGB guides at weight 0.5, default settings "
             f"(the second command of `run_example.sh`); emaki {runs_text(a.runs)}:", "",
             "```sh", "E=examples/stylit", shown(cmd), "```", "",
             "| | wall s | CPU s | peak RSS MB | judge `style` | `joint` | `coverage` |",
             "|---|---|---|---|---|---|---|"]
    judged = judge_stylit(a, out) if a.judge else None
    lines.append("| emaki | {} | {:.2f} | {} | {} |".format(
        spread(runs, "wall"), median(runs, "cpu"), f"{median(runs, 'rss'):.0f}",
        " | ".join(judged) if judged else "- | - | -"))
    if a.ebsynth:
        eout = os.path.join(tmp, "stylit_ebsynth.png")
        ecmd = [a.ebsynth] + stylit_args() + ["-output", eout]
        e = run_timed(ecmd)
        ej = judge_stylit(a, eout) if a.judge else None
        lines.append("| EbSynth (CPU build, one run) | {:.2f} | {:.2f} | {} | {} |".format(
            e["wall"], e["cpu"], f"{e['rss']:.0f}",
            " | ".join(ej) if ej else "- | - | -"))
        lines += ["", "EbSynth / emaki: **{:.1f}x** wall, {:.1f}x CPU.".format(
            e["wall"] / median(runs, "wall"), e["cpu"] / median(runs, "cpu"))]
    else:
        lines += ["", "(EbSynth's column: `--ebsynth PATH`.)"]
    return lines


def judge_stylit(a, output):
    cmd = [a.judge, "-style", os.path.join(STYLIT, "source_style.png")]
    for g in GUIDES:
        cmd += ["-guide", os.path.join(STYLIT, f"source_{g}.png"),
                os.path.join(STYLIT, f"target_{g}.png"), "-weight", "0.5"]
    p = subprocess.run(cmd + ["-output-to-judge", output], capture_output=True, text=True)
    m = {k: re.search(rf'"{k}":\s*([0-9.eE+-]+)', p.stdout) for k in ("style", "joint", "coverage")}
    if p.returncode != 0 or not all(m.values()):
        sys.exit(f"performance.py: the judge failed on {output}: {p.stderr.strip()[-300:]}")
    return ["{:.6f}".format(float(m["style"].group(1))),
            "{:.6f}".format(float(m["joint"].group(1))),
            "{:.3f}".format(float(m["coverage"].group(1)))]


def section_scaling(a, build):
    cmd = [os.path.join(build, "bench", "synth_bench"), "--repeat", str(a.runs)]
    out = run_timed(cmd, env={"GLIBC_TUNABLES": HUGE_ON})["out"]
    rows = re.findall(r"^\s*(\d+x\d+)\s+(\d+)\s+([0-9.]+)\s+([0-9.]+)\s*$", out, re.M)
    lines = ["## Synthesis time against image size", "",
             "The StyLit example at a quarter, half and full size (each halving low-passed), in "
             f"memory, {runs_text(a.runs, 'best')}:", "", "```sh", shown(cmd), "```", "",
             "| size | pixels | seconds | ns per pixel |", "|---|---|---|---|"]
    lines += [f"| {s} | {int(p):,} | {float(t):.3f} | {float(n):.0f} |" for s, p, t, n in rows]
    m = re.search(r"spread: \+-([0-9.]+) %", out)
    if m:
        lines += ["", f"Time per pixel within +-{m.group(1)} % across the three sizes."]
    return lines


def section_memory(a, emaki, tmp):
    """The huge-page restart of the shot commands: six frames of the bundled shot, the tunable
    turned off or not, runs alternated."""
    on, off = [], []
    for i in range(a.runs):
        for runs, env in ((on, None), (off, {"GLIBC_TUNABLES": HUGE_OFF})):
            path = shot_copy(tmp, f"thp{i}{'off' if env else 'on'}")
            runs.append(run_timed([emaki, "run", path, "--frames", "0-5", "--no-previews"], env))
    return ["## Huge pages", "",
            f"The kernel's transparent-huge-page mode here: `{thp_mode()}` (the commands that make "
            "shots' frames restart with huge pages only in `madvise` mode; `emaki synth` does "
            "not). `emaki run examples/fox/shot.toml --frames 0-5 --no-previews` into an empty "
            f"folder, {times_text(a.runs)} with `GLIBC_TUNABLES={HUGE_OFF}`:", "",
            "| | wall s | CPU s | minor page faults |", "|---|---|---|---|",
            "| default | {} | {:.2f} | {:,.0f} |".format(spread(on, "wall"), median(on, "cpu"),
                                                         median(on, "faults")),
            "| `GLIBC_TUNABLES={}` | {} | {:.2f} | {:,.0f} |".format(
                HUGE_OFF, spread(off, "wall"), median(off, "cpu"), median(off, "faults"))]


def section_render(a, build):
    cmd = [os.path.join(build, "bench", "render_bench"),
           os.path.join(ROOT, "examples", "data", "Fox.glb"), "8", "960x540"]
    outs = [run_timed(cmd, env={"GLIBC_TUNABLES": HUGE_ON})["out"] for _ in range(a.runs)]
    vals = [re.search(r"([0-9.]+) s/frame \(wall\), ([0-9.]+) CPU s/frame", o) for o in outs]
    wall = statistics.median(float(v.group(1)) for v in vals)
    cpu = statistics.median(float(v.group(2)) for v in vals)
    return ["## Guide passes", "",
            "emaki's renderer, the walking Fox, all 13 passes at 960x540 (2x2 samples), 8 frames, "
            f"{runs_text(a.runs)}:", "", "```sh", shown(cmd), "```", "",
            "| | seconds per frame | CPU seconds per frame |", "|---|---|---|",
            f"| `render_bench` | {wall:.3f} | {cpu:.3f} |"]


def section_shot(a, build):
    # 17 frames: two of the temporal frames re-measure the ink layers' reference (every 8 frames,
    # docs/design/ink-ratio.md), as often as along a whole shot.
    sizes = [("960x540", 17)] + ([("1920x1080", 9)] if a.full else [])
    modes = [("layers at once (`emaki run`)", []),
             ("one layer at a time", ["--one-layer-at-a-time"])]
    lines = ["## A shot in memory", "",
             "The bundled shot (three layers, temporal on) without files: rendering, synthesis, "
             "advection and compositing, with the frame's layers synthesized at once (as `emaki "
             "run` does) and one after another (`--one-layer-at-a-time`), the two alternated; "
             f"{runs_text(a.runs)}:", "", "```sh"]
    rows = []
    for size, frames in sizes:
        cmds = [[os.path.join(build, "bench", "shot_bench")] + flags + [size, str(frames)]
                for _, flags in modes]
        lines += [shown(c) for c in cmds]
        runs = [[], []]
        for _ in range(a.runs):
            for k, cmd in enumerate(cmds):
                runs[k].append(run_timed(cmd, env={"GLIBC_TUNABLES": HUGE_ON}))
        for (label, _), rs in zip(modes, runs):
            outs = [r["out"] for r in rs]
            f0 = statistics.median(float(re.search(r"\(no temporal\) ([0-9.]+) s", o).group(1))
                                   for o in outs)
            ft = statistics.median(float(re.search(r"\(temporal\) ([0-9.]+) s", o).group(1))
                                   for o in outs)
            steps = {}
            for o in outs:
                for name, sec in re.findall(r" (\w+) ([0-9.]+) s",
                                            o.split("per temporal frame:")[1]):
                    steps.setdefault(name, []).append(float(sec))
            split = ", ".join(f"{n} {statistics.median(v):.2f}" for n, v in steps.items())
            rows.append(f"| {size} | {label} | {f0:.2f} | {ft:.2f} | {median(rs, 'rss'):.0f} "
                        f"| {split} |")
            if not TEMPORAL_FRAME.get(size):
                TEMPORAL_FRAME[size] = ft
    lines += ["```", "",
              "| size | layers | frame 0 s | temporal frame s | peak RSS MB "
              "| per temporal frame, by step (s) |",
              "|---|---|---|---|---|---|"] + rows
    lines += ["", "Frame 0 runs the whole pyramid; temporal frames start from the previous "
              "frame's field. The `layers` step includes the frame's rendering and advection; one "
              "layer at a time, the first layer's step includes the frame's rendering and every "
              "layer's advection. Layers at once fill the cores a layer alone leaves idle (between "
              "its PatchMatch rounds) and hold more memory at once."]
    return lines


def shot_copy(tmp, name):
    """examples/fox/shot.toml with absolute input paths and its outputs under tmp."""
    text = open(os.path.join(ROOT, "examples", "fox", "shot.toml")).read()
    text = text.replace('"../', '"' + os.path.join(ROOT, "examples") + "/")
    folder = os.path.join(tmp, name)
    text = re.sub(r'^folder = "out"', f'folder = "{folder}"', text, flags=re.M)
    path = os.path.join(tmp, name + ".toml")
    open(path, "w").write(text)
    return path


def section_run(a, emaki, tmp):
    lines = ["## The bundled shot, with its files", ""]
    if a.full:
        what = "`emaki run examples/fox/shot.toml`: 48 frames at 960x540 with previews"
        extra = []
    else:
        what = "`emaki run examples/fox/shot.toml`, frames 0-5, no previews"
        extra = ["--frames", "0-5", "--no-previews"]
    runs = []
    for i in range(a.runs):
        path = shot_copy(tmp, f"run{i}")
        cmd = [emaki, "run", path] + extra
        runs.append(run_timed(cmd))
    shown_cmd = "emaki run examples/fox/shot.toml " + " ".join(extra)
    lines += [f"{what}, into an empty output folder each time, {runs_text(a.runs)} "
              "(a copy of the shot writes under a temporary folder):", "",
              "```sh", shown_cmd.strip(), "```", "",
              "| | wall s | CPU s | minor page faults | peak RSS MB |", "|---|---|---|---|---|",
              "| emaki run | {} | {:.1f} | {:,.0f} | {} |".format(
                  spread(runs, "wall", "{:.1f}"), median(runs, "cpu"), median(runs, "faults"),
                  f"{median(runs, 'rss'):.0f}")]
    return lines


def section_temporal(a, build):
    size, frames = ("960x540", 48) if a.full else ("480x270", 16)
    cmd = [os.path.join(build, "bench", "temporal_bench"), "--size", size, "--frames",
           str(frames), "--variants", "frame,position,rest_position"]
    if a.judge:
        cmd += ["--judge", a.judge, "--judge-every", "8"]
    out = run_timed(cmd, env={"GLIBC_TUNABLES": HUGE_ON})["out"]
    lines = ["## Temporal: flicker and ghosts", "",
             f"The bundled shot's base layer at {size}, frames 0-{frames - 1}: frame by frame "
             "(`temporal = false`), and with advection by world `position` or by `rest_position` "
             "(the default), each with the shot's other temporal settings. Flicker is "
             "`emaki qa flicker`'s measure (objects: the Fox), ghost share `emaki qa ghost`'s, "
             "drift the mean value against frame by frame over the last quarter of the frames, "
             "in levels of 255:", "", "```sh", shown(cmd), "```", "",
             "| variant | flicker | Fox | ground | vs frame by frame | judge `style` | coverage "
             "| ghost share | drift |", "|---|---|---|---|---|---|---|---|---|"]
    if not a.judge:  # no judge columns
        lines[-2:] = ["| variant | flicker | Fox | ground | vs frame by frame | ghost share "
                      "| drift |", "|---|---|---|---|---|---|---|"]
    row = re.compile(r"^(\S+)\s+[\d.]+\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+x)\s+"
                     r"(-|[\d.]+(?: \([+-][\d.]+ %\))?)\s+(\S+)\s+(\S+)\s+\S+\s+\S+\s+(\S+)$")
    for line in out.splitlines():
        m = row.match(line.strip())
        if m:
            g = list(m.groups())
            if not a.judge:
                del g[5:7]
            lines.append("| " + " | ".join(g) + " |")
    return lines


def section_python(a, build, emaki, tmp):
    env = {"PYTHONPATH": os.path.join(build, "python")}
    script = os.path.join(ROOT, "examples", "python", "stylit.py")
    out = os.path.join(tmp, "stylit_py.png")
    cmd = ["/usr/bin/python3", script, out]
    plain, tuned = [], []
    for _ in range(a.runs):
        plain.append(run_timed(cmd, env=env, cwd=ROOT))
        tuned.append(run_timed(cmd, env=dict(env, GLIBC_TUNABLES=HUGE_ON), cwd=ROOT))
    cli = os.path.join(tmp, "stylit.png")
    same = os.path.exists(cli) and open(cli, "rb").read() == open(out, "rb").read()
    return ["## Python", "",
            "`examples/python/stylit.py` (the StyLit example through `emaki.synthesize`, the "
            f"module's import and file reading included), {times_text(a.runs)} with and "
            "without the huge-page tunable that `emaki` sets for itself:", "",
            "```sh", "PYTHONPATH=build/release/python /usr/bin/python3 examples/python/stylit.py "
            "OUT.png", "GLIBC_TUNABLES=glibc.malloc.hugetlb=1 PYTHONPATH=... (the same)", "```", "",
            "| | wall s | CPU s | minor page faults |", "|---|---|---|---|",
            "| plain | {} | {:.2f} | {:,.0f} |".format(spread(plain, "wall"), median(plain, "cpu"),
                                                       median(plain, "faults")),
            "| `GLIBC_TUNABLES={}` | {} | {:.2f} | {:,.0f} |".format(
                HUGE_ON, spread(tuned, "wall"), median(tuned, "cpu"), median(tuned, "faults")),
            "", "Its PNG is {} `emaki synth`'s.".format(
                "the same file as" if same else "NOT the same file as" if os.path.exists(cli)
                else "to be compared with")]


SECTIONS = ("synth", "scaling", "memory", "render", "shot", "colour", "run", "temporal",
            "lookdev", "plan", "farm", "python")
TEMPORAL_FRAME = {}  # size -> the shot section's temporal frame seconds


def section_colour(a, build):
    size = "960x540"
    if size not in TEMPORAL_FRAME:
        out = run_timed([os.path.join(build, "bench", "shot_bench"), size, "4"],
                        env={"GLIBC_TUNABLES": HUGE_ON})["out"]
        TEMPORAL_FRAME[size] = float(re.search(r"\(temporal\) ([0-9.]+) s", out).group(1))
    cmd = [os.path.join(build, "bench", "colour_bench"), size, f"{TEMPORAL_FRAME[size]:.2f}", "10"]
    out = run_timed(cmd, env={"GLIBC_TUNABLES": HUGE_ON})["out"]
    rows = []
    for label, name in (("passes: albedo ACEScg -> scene_linear", "passes"),
                        ("compositing.space = scene_linear: composite_frame's extra", "compositing"),
                        ("composite PNG: scene_linear -> sRGB / Filmic", "Filmic PNG")):
        m = re.search(re.escape(label) + r"\s+([0-9.]+) ms /\s+([0-9.]+) ms", out)
        rows.append(f"| {name} | {float(m.group(1)):.1f} | {float(m.group(2)):.1f} |")
    m = re.search(r"per frame: ([0-9.]+) ms, ([0-9.]+) %", out)
    return ["## Colour management", "",
            "The most colour management a shot can ask for (ACEScg studio passes, `scene_linear` "
            "compositing, the Filmic view on the composite PNG), on the bundled shot's frame 0 at "
            "960x540, best of 10; the defaults cost nothing:", "", "```sh", shown(cmd), "```", "",
            "| step | wall ms | CPU ms |", "|---|---|---|"] + rows + [
            "", f"{float(m.group(1)):.1f} ms a frame: {m.group(2)} % of a temporal frame "
            f"(`shot_bench {size}`: {TEMPORAL_FRAME[size]:.2f} s)."]


def section_lookdev(a, build):
    emaki = os.path.join(build, "apps", "emaki", "emaki")
    cmd = ["sh", os.path.join(ROOT, "bench", "lookdev_bench.sh"), emaki, "5"]
    out = run_timed(cmd)["out"]
    saves = re.findall(r"save to frame written ([0-9.]+) s \(run ([0-9.]+) s, CPU ([0-9.]+) s\)",
                       out)
    rows = [f"| {i + 1} | {float(w):.2f} | {float(r):.2f} | {float(c):.2f} |"
            for i, (w, r, c) in enumerate(saves)]
    return ["## Look development", "",
            "`emaki lookdev` on the bundled shot at `--scale 0.5` (480x270), frame 0: five saves "
            "of the painting, each timed from the save to the new frame written (the page asks "
            "for it every 0.1 s):", "", "```sh", shown(cmd), "```", "",
            "| save | save to frame s | making it s | CPU s |", "|---|---|---|---|"] + rows


def section_plan(a, build):
    cmd = [os.path.join(build, "bench", "plan_bench"), "100000", "1000000"]
    out = run_timed(cmd)["out"]
    rows = []
    for m in re.finditer(r"(\d+) frames: (\d+) tasks, (\d+) dependencies: plan ([0-9.]+) s "
                         r"\(CPU ([0-9.]+) s\), json ([0-9.]+) s \(CPU ([0-9.]+) s, ([0-9.]+) MB\)",
                         out):
        fr, tasks, _, pw, _, jw, _, mb = m.groups()
        rows.append(f"| {int(fr):,} | {int(tasks):,} | {float(pw):.3f} | {float(jw):.3f} | {mb} |")
    return ["## Planning a long shot", "",
            "`emaki plan` of a production shot (two temporal layers, chunks of 8) stretched to "
            "10^5 and 10^6 frames, every task to do:", "", "```sh", shown(cmd), "```", "",
            "| frames | tasks | task graph s | JSON s | JSON MB |", "|---|---|---|---|---|"] + rows


def farm_rows(a, script, emaki, work, shots):
    """bench/farm_bench.sh without Slurm on `shots` (None: the production's), a.runs times
    alternated: the table's row, and the rows of the per-stage table."""
    env = dict(os.environ, FARM_BENCH_SLURM="0", FARM_BENCH_REPEAT=str(a.runs))
    if shots:
        env["FARM_BENCH_SHOTS"] = " ".join(shots)
    out = run_timed(["bash", script, emaki, work], env=env)["out"]
    num = r"\s+([0-9.]+)"
    total = re.search(r"all \(whole processes\)" + num * 4, out)
    n = re.search(r"; (\d+) tasks", out)
    same = re.search(r"tasks vs emaki run: (identical|DIFFERENT.*)", out)
    stages = re.findall(r"^(prepare|passes|layer|composite|previews) \((\d+) tasks\)" + num * 4 +
                        r"\s+(\S+)$", out, re.M)
    if not (total and n and same and len(stages) == 5):
        sys.exit(f"performance.py: farm: unexpected output of {script}:\n{out}")
    what = ", ".join(shots) if shots else "examples/production (3 shots, 480x270, 60 frames)"
    run_cpu, tasks_cpu = float(total.group(2)), float(total.group(4))
    ratio = f"{tasks_cpu / run_cpu:.2f}x"
    reps = re.search(r"per repetition: ([0-9. ]+); median ([0-9.]+)", out)
    if reps:
        ratio = f"{reps.group(2)}x ({', '.join(reps.group(1).split())})"
    row = (f"| {what} | {n.group(1)} | {run_cpu:.1f} | {tasks_cpu:.1f} | {ratio} "
           f"| {same.group(1)} |")
    stage_rows = [f"| {what} | {k} | {c} | {float(rc):.1f} | {float(tc):.1f} | {r} |"
                  for k, c, _, rc, _, tc, r in stages]
    return [row], stage_rows


def section_farm(a, emaki, tmp):
    script = os.path.join(ROOT, "bench", "farm_bench.sh")
    rows, stage_rows = farm_rows(a, script, emaki, os.path.join(tmp, "farm"), None)
    full = ["examples/fox/shot.toml", "examples/town/shot.toml"]
    if a.full:
        more, more_stages = farm_rows(a, script, emaki, os.path.join(tmp, "farm_full"), full)
        rows += more
        stage_rows += more_stages
    env = f"FARM_BENCH_SLURM=0 FARM_BENCH_REPEAT={a.runs}"
    commands = [f"{env} bench/farm_bench.sh"]
    if a.full:
        commands.append(f'{env} FARM_BENCH_SHOTS="{" ".join(full)}" bench/farm_bench.sh')
    return (["## A production on the farm", "",
             "The tasks `emaki plan` makes (chunks of 8 frames, 1 thread each), run one by one "
             "here without a scheduler, against `emaki run --threads 1` of the same shots one "
             "after another: the CPU-seconds a farm's nodes spend against one process's; " +
             ("one run" if a.runs == 1 else f"mean of {a.runs} runs, the two alternated, and "
              "the median of the runs' ratios") +
             ("" if a.full else " (`--full` adds the bundled examples at full size)") + ":", "",
             "```sh"] + commands + ["```", "",
             "| shots | tasks | emaki run CPU s | tasks CPU s | tasks vs run (each run) | outputs |",
             "|---|---|---|---|---|---|"] + rows +
            ["", "By stage: `emaki run --timings` splits the run's CPU time among the task kinds "
             "(its process start and exit in none of them); each task is a whole process:", "",
             "| shots | stage | tasks | emaki run CPU s | tasks CPU s | tasks vs run |",
             "|---|---|---|---|---|---|"] + stage_rows +
            ["", "Through Slurm on the private test cluster: the script's own output."])


# Each section's function, called with (args, build folder, emaki, scratch folder).
SECTION_RUNS = {
    "synth": lambda a, b, e, t: section_synth(a, e, t),
    "scaling": lambda a, b, e, t: section_scaling(a, b),
    "memory": lambda a, b, e, t: section_memory(a, e, t),
    "render": lambda a, b, e, t: section_render(a, b),
    "shot": lambda a, b, e, t: section_shot(a, b),
    "colour": lambda a, b, e, t: section_colour(a, b),
    "run": lambda a, b, e, t: section_run(a, e, t),
    "temporal": lambda a, b, e, t: section_temporal(a, b),
    "lookdev": lambda a, b, e, t: section_lookdev(a, b),
    "plan": lambda a, b, e, t: section_plan(a, b),
    "farm": lambda a, b, e, t: section_farm(a, e, t),
    "python": lambda a, b, e, t: section_python(a, b, e, t),
}


def printed_arguments(argv):
    """The command line as the page shows it, with every path replaced by PATH."""
    argv = list(argv)
    for i, x in enumerate(argv[:-1]):
        if x in ("--ebsynth", "--judge", "--build"):
            argv[i + 1] = "PATH"
    argv = [re.sub(r"^(--(?:ebsynth|judge|build)=).*", r"\1PATH", x) for x in argv]
    return " ".join(argv)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--build", default=os.path.join(ROOT, "build", "release"))
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--full", action="store_true")
    p.add_argument("--only", default=",".join(SECTIONS))
    p.add_argument("--ebsynth")
    p.add_argument("--judge")
    a = p.parse_args()
    only = a.only.split(",")
    bad = [s for s in only if s not in SECTIONS]
    if bad:
        sys.exit(f"performance.py: --only: unknown section {bad[0]!r} "
                 f"(sections: {', '.join(SECTIONS)})")
    build = os.path.abspath(a.build)
    emaki = os.path.join(build, "apps", "emaki", "emaki")
    if not os.access(emaki, os.X_OK):
        sys.exit(f"performance.py: --build: no {emaki}: build the release preset first")
    t0, load0 = time.monotonic(), os.getloadavg()[0]
    lines = []
    with tempfile.TemporaryDirectory(prefix="emaki_performance_") as tmp:
        SCRATCH.append(tmp)
        for name in SECTIONS:
            if name not in only:
                continue
            print(f"performance.py: {name} ...", file=sys.stderr)
            lines += SECTION_RUNS[name](a, build, emaki, tmp)
            lines.append("")
    args = printed_arguments(sys.argv[1:])
    header = [
        "# Performance", "",
        "Every figure on this page is printed by `bench/performance.py`, which runs the release "
        "build's programs on the bundled examples; the page is its output. To measure your "
        "machine, build the release preset and run", "",
        "```sh", "/usr/bin/python3 bench/performance.py [--full] [--ebsynth PATH] [--judge PATH]"
        " > docs/performance.md", "```", "",
        "Figures vary between machines and with whatever else runs on them: compare them as "
        "ratios between rows measured in one run, not with figures from another machine; on a "
        "shared machine CPU seconds and page faults say more than wall seconds. This "
        "run: `bench/performance.py{}` on {} ({} cores), load average {:.1f} at the start and "
        "{:.1f} at the end (other jobs shared the machine when above the core count), "
        "{:.0f} s.".format(" " + args if args else "", cpu_model(), os.cpu_count(), load0,
                           os.getloadavg()[0], time.monotonic() - t0), ""]
    footer = [
        "## Other benchmarks", "",
        "- `bench/eval_set.py` and `bench/eval_spread.py`: emaki against EbSynth's CPU build on 13 "
        "exemplar/target pairs, judged ([design/evaluation.md](design/evaluation.md)); "
        "`bench/compare_ebsynth.sh`: EbSynth's own StyLit and FaceStyle command lines, wall "
        "time and peak memory.",
        "- `bench/temporal_bench`: one layer of a shot run several ways (frame by frame, advection "
        "guides, confidence, uniformity, warm start, temporal weight), flicker, ghosts, drift and "
        "the judge ([guide.md](guide.md#reading-qa)).",
        "- `bench/python_overhead.py` (the module's cost over the command line's synthesis, in "
        "instructions with `--instructions`) and `bench/python_gil.py` (two Python threads "
        "synthesizing at once).",
        "- `bench/farm_bench.sh` with Slurm (the production submitted to the private test "
        "cluster: its wall time and the scheduler's delay per task) and "
        "`bench/slurm_overhead.sh` (the scheduler's cost per task, [slurm.md](slurm.md)).",
        "- Instruction counts, which other jobs do not disturb: `valgrind --tool=callgrind` of "
        "`emaki synth ... --threads 1` ([design/engine-speed.md](design/engine-speed.md))."]
    print("\n".join(header + lines + footer).rstrip())


if __name__ == "__main__":
    main()
