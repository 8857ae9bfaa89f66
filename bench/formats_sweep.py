#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every shipped config at orders 1-4 written as MSH 4.1, MSH 2.2 and CGNS, each file read back
by `plaf check` (the same certified cells: count, invalid, min scaled Jacobian as the run's
report) and the CGNS by `cgnscheck` (no error, no warning); meshio reads the MSH 2.2 when present.
Run by hand (about an hour on 2 cores); not a test.

    PLAF_DATA=<data root> python3 bench/formats_sweep.py --plaf build/apps/plaf --out /tmp/fs [--only NAME,...] [--orders 1,2,3,4]
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import time

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.join(os.path.dirname(HERE), "configs")


def check(plaf, path, out):
    rep = os.path.join(out, os.path.basename(path) + ".check.json")
    r = subprocess.run([plaf, "check", path, "--report", rep], capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(rep):
        return None, r.stderr.strip().splitlines()[-1:] if r.stderr else ["exit %d" % r.returncode]
    with open(rep) as f:
        return json.load(f), None


def absolute_files(node):
    """The config with its relative `file:` paths made absolute (they are relative to the config's
    folder, and the rewritten config lives elsewhere); data: paths are left to the data roots."""
    if isinstance(node, dict):
        return {k: (os.path.normpath(os.path.join(CONFIGS, v)) if k in ("file", "mesh", "sol") and isinstance(v, str)
                    and not v.startswith("data:") and not os.path.isabs(v) else absolute_files(v)) for k, v in node.items()}
    if isinstance(node, list):
        return [absolute_files(v) for v in node]
    return node


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plaf", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--only", default="")
    ap.add_argument("--orders", default="1,2,3,4")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    only = set(x for x in a.only.split(",") if x)
    cgnscheck = shutil.which("cgnscheck")
    try:
        import meshio
    except ImportError:
        meshio = None
    rows, bad = [], []
    for cfg in sorted(glob.glob(os.path.join(CONFIGS, "*.yaml"))):
        name = os.path.splitext(os.path.basename(cfg))[0]
        if (only and name not in only) or "study" in name:
            continue
        base = absolute_files(yaml.safe_load(open(cfg)))
        if "cases" in base:  # a study file
            continue
        for q in [int(x) for x in a.orders.split(",")]:
            d = dict(base)
            d["name"] = f"{name}_q{q}"
            d["order"] = q
            out = dict(d.get("output") or {})
            out["formats"] = ["msh", "msh22", "cgns", "report"]
            out.pop("cuts", None)
            out.pop("dir", None)
            d["output"] = out
            path = os.path.join(a.out, d["name"] + ".yaml")
            with open(path, "w") as f:
                yaml.safe_dump(d, f, sort_keys=False)
            t = time.time()
            r = subprocess.run([a.plaf, "run", path, "--out", a.out, "--quiet"], capture_output=True, text=True,
                               cwd=os.path.dirname(CONFIGS))
            wall = time.time() - t
            row = {"case": d["name"], "exit": r.returncode, "s": round(wall, 1)}
            if r.returncode != 0:
                row["why"] = (r.stderr.strip().splitlines() or [""])[-1][:160]
                rows.append(row)
                print(row, flush=True)  # a run that fails is not a format failure: listed, not checked
                continue
            with open(os.path.join(a.out, d["name"] + ".report.json")) as f:
                run_rep = json.load(f)
            ok = True
            for suffix in (".msh", "_msh22.msh", ".cgns"):
                rep, err = check(a.plaf, os.path.join(a.out, d["name"] + suffix), a.out)
                same = rep is not None and rep["cells"]["total"] == run_rep["cells"]["total"] and \
                    rep["cells"]["invalid"] == run_rep["cells"]["invalid"] == 0 and \
                    rep["scaled_jacobian"]["min"] == run_rep["scaled_jacobian"]["min"]
                row[suffix] = "same" if same else f"DIFFERS {err or (rep['cells'], rep['scaled_jacobian'])}"
                ok = ok and same
            if cgnscheck:
                c = subprocess.run([cgnscheck, os.path.join(a.out, d["name"] + ".cgns")], capture_output=True, text=True)
                text = c.stdout + c.stderr
                clean = c.returncode == 0 and "ERROR" not in text and "WARNING" not in text
                row["cgnscheck"] = "clean" if clean else "FINDINGS"
                ok = ok and clean
            if meshio is not None:
                try:
                    m = meshio.read(os.path.join(a.out, d["name"] + "_msh22.msh"))
                    row["meshio"] = sum(len(c.data) for c in m.cells)
                except Exception as e:  # noqa: BLE001 (report what meshio says, whatever it is)
                    row["meshio"] = f"FAILED {e}"[:120]
                    ok = False
            for f in glob.glob(os.path.join(a.out, d["name"] + "*")):
                if not f.endswith((".json", ".yaml")):
                    os.remove(f)
            rows.append(row)
            if not ok:
                bad.append(d["name"])
            print(row, flush=True)
    print(f"\n{len(rows)} runs, {sum(1 for r in rows if r['exit'] == 0)} exit 0, format failures: {bad or 'none'}")
    with open(os.path.join(a.out, "formats_sweep.json"), "w") as f:
        json.dump(rows, f, indent=1)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
