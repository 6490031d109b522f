#!/usr/bin/env python3
"""Regenerates the guide's figure tables (docs/GUIDE.md) from one measuring run, so figures cannot drift apart.

    scripts/figures.sh            # benchmarks, timings and memory, then docs/GUIDE.md rewritten
    scripts/figures.py --tables-only   # rewrite from the last run's results (target/figures.json)

Every table lives in docs/GUIDE.md between `<!-- figures:NAME -->` and `<!-- /figures -->`. This
script owns those blocks: it writes each table with the machine, the date, the load average
during the run and the command that measured each row. Ratios (tidepool against the papers'
loop, two threads against one, the ocean with foam against without) come from the same run,
so they hold even when the machine is busy and the absolute figures are inflated.

What each row measures is said in its label; criterion figures are medians of the benchmark's
samples (`target/criterion/<id>/new/estimates.json`).
"""

import datetime
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TARGET = ROOT / "target"
RESULTS = TARGET / "figures.json"
BIN = TARGET / "release" / "tidepool"
BENCHES = ["pool", "ocean", "lake", "encoder"]
# Short runs: the tables need medians good to a few percent, not criterion's defaults.
CRITERION_ARGS = ["--warm-up-time", "1", "--measurement-time", "3", "--noplot"]


def run(cmd, **kw):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    return subprocess.run(cmd, cwd=ROOT, check=True, **kw)


def load():
    return os.getloadavg()[0]


def machine():
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def criterion_medians():
    """Every benchmark's median in nanoseconds, by its full id."""
    medians = {}
    for bench in (TARGET / "criterion").rglob("new/benchmark.json"):
        full_id = json.loads(bench.read_text())["full_id"]
        estimates = json.loads((bench.parent / "estimates.json").read_text())
        medians[full_id] = estimates["median"]["point_estimate"]
    return medians


def wall_median(args, runs=5):
    times = []
    with tempfile.TemporaryDirectory() as d:
        for _ in range(runs):
            start = time.perf_counter()
            subprocess.run([str(BIN), *args, "--out", str(Path(d) / "out.png")], cwd=ROOT, check=True)
            times.append(time.perf_counter() - start)
    return statistics.median(times)


def bytes_per_frame(measure_args):
    """The player's bytes per frame in a 160x48 pty with `measure_args` (None: the test's own)."""
    env = dict(os.environ)
    if measure_args is not None:
        env["MEASURE_ARGS"] = measure_args
    out = subprocess.run(
        ["cargo", "test", "--release", "--test", "integration", "bytes_per_frame", "--", "--ignored", "--nocapture"],
        cwd=ROOT, capture_output=True, text=True, env=env,
    )
    text = out.stdout + out.stderr
    m = re.search(r"(\d+) bytes in (\d+) frames \(([\d.]+) frames/s sent\), (\d+) bytes/frame = ([\d.]+)% of the naive (\d+), (\d+) kB/s", text)
    if not m:
        raise SystemExit(f"figures: the bytes_per_frame test printed no figure:\n{text[-2000:]}")
    return {"bytes": int(m[4]), "fps": float(m[3]), "percent": float(m[5]), "naive": int(m[6]), "kBps": int(m[7])}


def measure():
    started = datetime.datetime.now(datetime.timezone.utc)
    loads = [load()]
    run(["cargo", "build", "--release"])
    run(["cargo", "bench", *sum((["--bench", b] for b in BENCHES), []), "--", *CRITERION_ARGS])
    loads.append(load())
    memory = {scene: peak_rss_of([str(BIN), "render", scene, "--size", "1920x1080"]) for scene in ["ocean", "lake", "pool"]}
    wall = wall_median(["render", "pool", "--size", "1024x1024", "--steps", "2000"])
    loads.append(load())
    frame_bytes = {"still": bytes_per_frame(None), "alive": bytes_per_frame("--bandwidth unlimited")}
    loads.append(load())
    return {
        "machine": machine(),
        "date": started.strftime("%Y-%m-%d %H:%M UTC"),
        "load": [round(l, 2) for l in loads],
        "criterion": criterion_medians(),
        "peak_mb": memory,
        "pool_render_wall_s": wall,
        "bytes_per_frame": frame_bytes,
    }


def peak_rss_of(cmd):
    """Peak resident memory of one command, MB, read from its own rusage through `time -f`."""
    with tempfile.TemporaryDirectory() as d:
        out = subprocess.run(
            ["/usr/bin/time", "-f", "%M", *cmd, "--out", str(Path(d) / "out.png")],
            cwd=ROOT, check=True, capture_output=True, text=True,
        )
    return int(out.stderr.strip().splitlines()[-1]) / 1024.0


def ms(ns):
    return f"{ns / 1e6:.2f} ms" if ns < 1e8 else f"{ns / 1e6:.0f} ms"


def us(ns):
    return f"{ns / 1e3:.0f} µs"


def rate(ns, cells):
    return cells / ns  # G per second = cells per ns


def speed_table(r):
    c = r["criterion"]
    side = 1024 * 1024
    papers = rate(c["sim/ripple_step/papers_scalar/1024"], side)
    step1 = rate(c["sim/ripple_step/step_1thread/1024"], side)
    block1 = rate(c["sim/ripple_step/advance16_1thread/1024"], 16 * side)
    block2 = rate(c["sim/ripple_step/advance16_2threads/1024"], 16 * side)
    block2_2k = rate(c["sim/ripple_step/advance16_2threads/2048"], 16 * 4 * side)
    block1_2k = rate(c["sim/ripple_step/advance16_1thread/2048"], 16 * 4 * side)
    o, l, p = "render/ocean/", "render/lake/", "render/pool/"
    player = c["player/render_encode_160x48"]
    mem = r["peak_mb"]
    rows = [
        ("ripple step 1024x1024, the papers' scalar loop", f"{papers:.2f} G cell updates/s", "`cargo bench --bench pool -- sim/`"),
        ("ripple step, tidepool, one step at a time, 1 thread (what the player gets)", f"{step1:.2f} G/s ({step1 / papers:.1f}x the papers' loop)", "same"),
        ("ripple step, tidepool, 16 steps blocked, 1 thread (what `render` gets)", f"{block1:.2f} G/s ({block1 / papers:.1f}x the papers' loop)", "same"),
        ("ripple step, 16 blocked, 2 threads", f"{block2:.2f} G/s ({block2 / block1:.2f}x one thread; 2048x2048: {block2_2k / block1_2k:.2f}x)", "same"),
        ("`render pool --size 1024x1024 --steps 2000`, wall, median of 5", f"{r['pool_render_wall_s']:.2f} s", "`time tidepool render pool --size 1024x1024 --steps 2000 --out p.png`"),
        ("pool frame 1920x1080 (step, refraction, caustics, shading)", ms(c[p + "step_and_render/1920x1080"]), "`cargo bench --bench pool -- render/pool`"),
        ("pool frame 160x96", ms(c[p + "step_and_render/160x96"]), "same"),
        ("ocean frame 160x94 with choppiness and foam (the player's)", ms(c[o + "160x94_ssaa1_chop_foam"]), "`cargo bench --bench ocean -- render/ocean/`"),
        ("ocean frame 1920x1080 ssaa 2: linear / choppy with foam", f"{ms(c[o + '1920x1080_ssaa2'])} / {ms(c[o + '1920x1080_ssaa2_chop_foam'])}", "same"),
        ("ocean maps 1024x1024, one step of a series (height, displacement, normals, foam)", ms(c["maps/1024"]), "`cargo bench --bench ocean -- maps/`"),
        ("lake frame 160x96 / 1920x1080 ssaa 2", f"{ms(c[l + '160x96_ssaa1'])} / {ms(c[l + '1920x1080_ssaa2'])}", "`cargo bench --bench lake`"),
        ("half-block text 160x48 cells: full frame / diff frame", f"{us(c['output/halfblock/full_frame_160x48'])} / {us(c['output/halfblock/diff_frame_160x48'])}", "`cargo bench --bench encoder`"),
        ("player frame 160x48 cells: two pool steps, render, encode", f"{us(player)} (~{1e9 / player:,.0f} fps)", "same"),
        ("PNG encode 1920x1080", ms(c["output/png/encode_1920x1080"]), "`cargo bench --bench pool -- output/png`"),
        ("player bytes per frame, 160x48, a stone a second: still water between stones / the alive defaults", f"{r['bytes_per_frame']['still']['percent']:.1f} % / {r['bytes_per_frame']['alive']['percent']:.1f} % of a naive redraw", "`cargo test --release --test integration bytes_per_frame -- --ignored --nocapture` (`MEASURE_ARGS='--bandwidth unlimited'` for the defaults)"),
        ("peak memory, `render ocean` / `render lake` / `render pool` at 1920x1080", f"{mem['ocean']:.0f} MB / {mem['lake']:.0f} MB / {mem['pool']:.0f} MB", "`/usr/bin/time -f %M tidepool render ocean --size 1920x1080`"),
    ]
    return table(["what", "figure", "reproduce with"], rows)


def ocean_table(r):
    c = r["criterion"]
    o = "render/ocean/"
    linear, chop = c[o + "1920x1080_ssaa2"], c[o + "1920x1080_ssaa2_chop_foam"]
    rows = [
        ("1920x1080 ssaa 2, linear sea (choppiness 0)", ms(linear), "`cargo bench --bench ocean -- render/ocean/`"),
        ("1920x1080 ssaa 2, choppiness 1 and foam", f"{ms(chop)} ({chop / linear:.2f}x the linear sea)", "same"),
        ("player frame 160x94, choppiness and foam", ms(c[o + "160x94_ssaa1_chop_foam"]), "same"),
        ("1024x1024 maps, one step of a series (foam continues)", ms(c["maps/1024"]), "`cargo bench --bench ocean -- maps/`"),
        ("1024x1024 maps without foam", ms(c["maps/1024_surface"]), "same"),
        ("peak memory, `render ocean --size 1920x1080`", f"{r['peak_mb']['ocean']:.0f} MB", "`/usr/bin/time -f %M tidepool render ocean --size 1920x1080`"),
    ]
    return table(["what (criterion median)", "figure", "command"], rows)


def bytes_block(r):
    lines = ["```sh", "cargo test --release --test integration bytes_per_frame -- --ignored --nocapture"]
    for name, label in [("still", "no breeze, rain 0.02, damping 4"), ("alive", "the defaults: MEASURE_ARGS='--bandwidth unlimited'")]:
        b = r["bytes_per_frame"][name]
        lines.append(
            f"# {label}: {b['bytes']:,} bytes/frame at {b['fps']:.0f} frames/s = {b['percent']:.1f}% of the naive"
            f" {b['naive']:,} ({b['kBps'] / 1000:.2f} MB/s)"
        )
    lines.append("```")
    return "\n".join(lines)


def table(head, rows):
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def provenance(r):
    loads = ", ".join(f"{l:.2f}" for l in r["load"])
    return (
        f"*Measured {r['date']} on {r['machine']} by `scripts/figures.sh` (one run for every table "
        f"marked like this one); load average during the run: {loads}.*"
    )


BLOCKS = {"speed": speed_table, "ocean": ocean_table, "bytes": bytes_block}


def rewrite_guide(r):
    path = ROOT / "docs" / "GUIDE.md"
    text = path.read_text()
    for name, make in BLOCKS.items():
        pattern = re.compile(rf"(<!-- figures:{name} -->\n).*?(<!-- /figures -->)", re.S)
        if not pattern.search(text):
            raise SystemExit(f"figures: docs/GUIDE.md has no <!-- figures:{name} --> block")
        body = make(r) + "\n\n" + provenance(r) + "\n"
        text = pattern.sub(lambda m: m[1] + body + m[2], text)
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text(text)
    tmp.replace(path)
    print(f"figures: docs/GUIDE.md rewritten ({', '.join(BLOCKS)})", file=sys.stderr)


def main():
    if "--tables-only" in sys.argv[1:]:
        if not RESULTS.exists():
            raise SystemExit("figures: no earlier run in target/figures.json; run scripts/figures.sh first")
        results = json.loads(RESULTS.read_text())
    else:
        results = measure()
        RESULTS.write_text(json.dumps(results, indent=1))
    rewrite_guide(results)


if __name__ == "__main__":
    main()
