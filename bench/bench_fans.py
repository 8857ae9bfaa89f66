#!/usr/bin/env python3
"""Benchmark: the price of fans in plaf's 3D layers (issue 31), in one run.

The layer stage's rate (layer cells per second: the layers' prisms and tetrahedra, every one
certified as it is grown) on shipped 3D layer configs, beside the sphere's, which has no fans:
  - sphere_layers        a smooth body: prisms only;
  - box_layers           ridge and corner fans on every edge and corner (its first layer is
                         tetrahedra);
  - onera_m6_layers      the published ONERA M6 (needs the data root): its trailing edge keeps a
                         merged normal by default;
  - onera_m6_layers with layers.fan_fades: true: the trailing edge's fan, fading into the tip.
Each config runs as shipped but for its output (the report only). Printed per run: the layer
cells (prisms, tetrahedra), the layer stage's seconds (the report's timings_s.layers), the rate
and its ratio to the sphere's. Wall times on a shared machine are indicative: run by hand,
alone.

    PLAF_DATA=DATA_ROOT python3 bench/bench_fans.py [--plaf build/apps/plaf]   (DATA_ROOT: docs/data.md)
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent


def with_output_report(text, extra_layers=None):
    """The config text with its output section replaced by the report only, and extra keys
    appended to its layers section (a flow mapping per key)."""
    lines = text.splitlines()
    out, skip = [], False
    for line in lines:
        if line.startswith("output:"):
            skip = True
            continue
        if skip and (line.startswith(" ") or not line.strip()):
            continue
        skip = False
        out.append(line)
        if extra_layers and line.startswith("layers:"):
            for k, v in extra_layers.items():
                out.append(f"  {k}: {v}")
    out.append("output:\n  formats: [report]")
    return "\n".join(out) + "\n"


def run(plaf, config, work, extra_layers=None, label=None):
    text = with_output_report(config.read_text(), extra_layers)
    name = label or config.stem
    cfg = work / f"{name}.yaml"
    cfg.write_text(text)
    proc = subprocess.run([plaf, "run", str(cfg), "--out", str(work / name)], capture_output=True, text=True)
    reports = list((work / name).glob("*.report.json"))
    if proc.returncode != 0 or not reports:
        return {"name": name, "error": (proc.stderr.strip().splitlines() or ["no report"])[-1]}
    r = json.loads(reports[0].read_text())
    table = r["layers"]["table"]
    prisms = sum(row["cells"] for row in table)
    tets = sum(row["transition_cells"] for row in table)
    return {"name": name, "prisms": prisms, "tets": tets, "seconds": r["timings_s"]["layers"],
            "layers": r["layers"]["count"], "coverage": r["layers"]["coverage"]["complete"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plaf", default=str(ROOT / "build/apps/plaf"))
    args = ap.parse_args()
    runs = [(ROOT / "configs/sphere_layers.yaml", None, None), (ROOT / "configs/box_layers.yaml", None, None)]
    if os.environ.get("PLAF_DATA"):
        m6 = ROOT / "configs/onera_m6_layers.yaml"
        runs += [(m6, None, None), (m6, {"fan_fades": "true"}, "onera_m6_layers_fan_fades")]
    else:
        print("PLAF_DATA is not set: the ONERA M6 rows are skipped")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [run(args.plaf, c, pathlib.Path(tmp), extra, label) for c, extra, label in runs]
    base = next((r for r in rows if r["name"] == "sphere_layers" and "error" not in r), None)
    print(f"{'config':28} {'layers':>6} {'prisms':>9} {'tets':>9} {'seconds':>8} {'cells/s':>10} {'vs sphere':>9} {'coverage':>8}")
    for r in rows:
        if "error" in r:
            print(f"{r['name']:28} failed: {r['error']}")
            continue
        rate = (r["prisms"] + r["tets"]) / r["seconds"] if r["seconds"] > 0 else float("inf")
        ratio = rate / ((base["prisms"] + base["tets"]) / base["seconds"]) if base else float("nan")
        print(f"{r['name']:28} {r['layers']:6d} {r['prisms']:9d} {r['tets']:9d} {r['seconds']:8.2f} {rate:10.0f} "
              f"{ratio:9.2f} {100 * r['coverage']:7.1f}%")
    return 0 if all("error" not in r for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
