#!/usr/bin/env python3
"""Replay of issue 37's bad and extreme 3D inputs: each must end as it should -- the exit code, a
message naming its cause, no output left behind for a refusal -- within 10 s and 1 GB.

    python3 bench/probe_inputs.py [--plaf build/apps/plaf] [--keep DIR]

Each case is a config written here (no data root needed; the stale-staging case makes its own
folder). A refusal (exit 1) must come before the work it refuses: under 10 s of wall time and 1 GB
of peak memory (the child's maximum resident set, from wait4). A run that is meant to go through
(exit 0) is held to the same limits. The item of issue 37 each case replays is in its name.
Prints one line per case and a summary; exits 1 if any case fails.

The unit and CLI tests (tests/apps/reliability_cli_test.cpp and the others named in the issue's
closing note) check the same messages; this script adds the time and memory each takes.
"""
import argparse
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

TIME_LIMIT_S = 10.0
MEMORY_LIMIT_KB = 1024 * 1024

SPHERE = "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.5}\n"
SPHERE_HYBRID = ("order: 2\ngeometry: {type: sphere}\n"
                 "metric: {type: wall_power_law, h0: 1.0e-5, growth: 1.25, h_max: 5, h_wall_max: 0.15}\n"
                 "layers: {max: 60, isotropic_stop: all}\n")


def zooms(n):
    return "output:\n  zooms:\n" + "".join("    - {box: [0, 1, 0, 1]}\n" for _ in range(n))


# (name, config text, expected exit code, message substring (stderr) or None)
CASES = [
    ("1 thin box 1 x 1 x 0.001, surface",
     "order: 2\ngeometry: {type: box, lo: [0, 0, 0], hi: [1, 1, 0.001]}\nmetric: {type: uniform, h: 0.1}\n", 0, None),
    ("1 thin box 1 x 0.002 x 1, surface",
     "order: 2\ngeometry: {type: box, lo: [0, 0, 0], hi: [1, 0.002, 1]}\nmetric: {type: uniform, h: 0.1}\n", 0, None),
    ("1 wing of span 0.001",
     "order: 2\ngeometry: {type: wing, naca: \"0012\", chord: 1, span: 0.001}\nmetric: {type: uniform, h: 0.1}\n", 0, None),
    ("2 farfield h 0.6 under limits.cells 200000",
     SPHERE_HYBRID + "fill: {type: tetgen, farfield: {shape: sphere, radius: 20, h: 0.6}}\nlimits: {cells: 200000}\n",
     1, "limits.cells"),
    ("2 farfield h 0.2 (no limit given)",
     SPHERE_HYBRID + "fill: {type: tetgen, farfield: {shape: sphere, radius: 20, h: 0.2}}\n", 1, "limits.cells"),
    ("3 max_volume with a farfield h too coarse for it",
     SPHERE_HYBRID + "fill: {type: tetgen, max_volume: 1, farfield: {shape: sphere, radius: 20, h: 5}}\n",
     1, "fill.farfield.h: 5 is too coarse for fill.max_volume 1"),
    ("5 a million-zoom config (65 here)", SPHERE + zooms(65), 1, "output.zooms: 65 zooms; at most 64"),
    ("5 a 50 MB name (300 bytes here)", SPHERE + "name: " + "n" * 300 + "\n", 1, "name: must be a plain file name"),
    ("6 metric.h_max 0.01 on the sphere hybrid",
     SPHERE_HYBRID.replace("h_max: 5", "h_max: 0.01") + "fill: {type: tetgen}\n", 1, "limits.cells: up to 60 layers"),
    ("6 layers.max 10000", SPHERE_HYBRID.replace("max: 60", "max: 10000") + "fill: {type: tetgen}\n", 1,
     "limits.cells: up to 10000 layers"),
    ("7 h0 = 1e-200",
     "order: 2\ngeometry: {type: sphere}\n"
     "metric: {type: wall_power_law, h0: 1.0e-200, growth: 1.2, h_wall_max: 0.3, h_max: 2}\nlayers: {max: 5}\n",
     1, "metric.h0: 1e-200 is below what double precision places"),
    ("7 layers.max 0 with a fill", SPHERE_HYBRID.replace("max: 60", "max: 0") + "fill: {type: tetgen}\n", 1,
     "layers.max: 0 grows no layer"),
    ("8 a second YAML document", SPHERE + "---\nname: second\n", 1, "a second YAML document"),
    ("8 a name with a newline", SPHERE + "name: \"a\\nb\"\n", 1, "got 'a?b'"),
    ("8 a name with a leading dot", SPHERE + "name: ..msh\n", 1, "got '..msh'"),
    ("8 output.formats: []", SPHERE + "output: {formats: []}\n", 1, "output.formats: an empty list writes nothing"),
]


def run(plaf, config, out, env=None):
    """Runs plaf; returns (exit code, stderr, wall seconds, peak RSS in kB)."""
    start = time.monotonic()
    with open(os.devnull, "wb") as null, tempfile.TemporaryFile() as err:
        p = subprocess.Popen([plaf, "run", config, "--out", out], stdout=null, stderr=err, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.monotonic() - start
        err.seek(0)
        text = err.read().decode(errors="replace")
    code = os.waitstatus_to_exitcode(status)
    return code, text, seconds, usage.ru_maxrss


def files_under(folder):
    return sum(len(f) for _, _, f in os.walk(folder)) if os.path.isdir(folder) else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plaf", default=os.path.join(os.path.dirname(__file__), "..", "build", "apps", "plaf"))
    ap.add_argument("--keep", help="write the configs and outputs here (default: a temporary folder)")
    args = ap.parse_args()
    plaf = os.path.abspath(args.plaf)
    if not os.access(plaf, os.X_OK):
        sys.exit(f"probe_inputs: no plaf binary at {plaf} (build it, or give --plaf)")
    root = os.path.abspath(args.keep) if args.keep else tempfile.mkdtemp(prefix="plaf_probe_")
    os.makedirs(root, exist_ok=True)
    failures = 0
    for k, (name, yaml, want, message) in enumerate(CASES):
        folder = os.path.join(root, f"case{k:02d}")
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        config = os.path.join(folder, "case.yaml")
        with open(config, "w") as f:
            f.write(yaml)
        out = os.path.join(folder, "out")
        code, err, seconds, rss = run(plaf, config, out)
        why = []
        if code != want:
            why.append(f"exit {code}, expected {want}")
        last = err.strip().splitlines()[-1] if err.strip() else ""
        if message and message not in last:
            why.append(f"the last line does not say {message!r}: {last[:200]!r}")
        if want == 1 and files_under(out):
            why.append(f"{files_under(out)} files left in the output folder")
        if seconds > TIME_LIMIT_S:
            why.append(f"{seconds:.1f} s > {TIME_LIMIT_S:g} s")
        if rss > MEMORY_LIMIT_KB:
            why.append(f"{rss / 1024:.0f} MB > 1 GB")
        failures += 1 if why else 0
        print(f"{'FAIL' if why else 'ok  '} item {name}: exit {code}, {seconds:.2f} s, {rss / 1024:.0f} MB"
              + (f" -- {'; '.join(why)}" if why else ""), flush=True)
    # Item 4: a staging folder of a dead process is removed by the next run into the folder.
    folder = os.path.join(root, "stale")
    shutil.rmtree(folder, ignore_errors=True)
    dead = subprocess.Popen(["true"])
    dead.wait()
    stale = os.path.join(folder, "out", f".plaf-stage-{dead.pid}")
    os.makedirs(stale)
    with open(os.path.join(stale, "left.msh"), "w") as f:
        f.write("left by a killed run\n")
    config = os.path.join(folder, "case.yaml")
    with open(config, "w") as f:
        f.write(SPHERE)
    code, _, seconds, rss = run(plaf, config, os.path.join(folder, "out"))
    ok = code == 0 and not os.path.exists(stale)
    failures += 0 if ok else 1
    print(f"{'ok  ' if ok else 'FAIL'} item 4 a dead run's staging folder: exit {code}, "
          f"{'removed' if not os.path.exists(stale) else 'still there'}, {seconds:.2f} s", flush=True)
    # Item 4: SIGTERM while TetGen runs leaves no TetGen process behind.
    folder = os.path.join(root, "sigterm")
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    config = os.path.join(folder, "sigterm_probe.yaml")
    with open(config, "w") as f:
        f.write("order: 2\ngeometry: {type: sphere}\n"
                "metric: {type: wall_power_law, h0: 0.001, growth: 1.25, h_max: 5, h_wall_max: 0.3}\n"
                "layers: {max: 8}\nfill: {type: tetgen, optimize_passes: 0, farfield: {shape: sphere, radius: 20, h: 0.6}}\n"
                "output: {formats: [report]}\n")

    def running():
        found = []
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as f:
                    if config.encode() in f.read():
                        found.append(int(pid))
            except OSError:
                pass
        return found

    p = subprocess.Popen([plaf, "run", config, "--out", os.path.join(folder, "out")],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while len(running()) < 2 and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    forked = len(running()) >= 2
    p.send_signal(signal.SIGTERM)
    p.wait()
    deadline = time.monotonic() + 2
    while running() and time.monotonic() < deadline:
        time.sleep(0.1)
    left = running()
    ok = forked and not left
    failures += 0 if ok else 1
    print(f"{'ok  ' if ok else 'FAIL'} item 4 SIGTERM during TetGen: "
          + ("no TetGen child seen before the stop" if not forked else
             f"{len(left)} process(es) left 2 s after" if left else "nothing left 2 s after"), flush=True)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    total = len(CASES) + 2
    print(f"probe_inputs: {total - failures} of {total} cases as they should be" + ("" if args.keep else f" ({root} removed)"))
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
