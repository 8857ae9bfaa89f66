#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The Python module against the CLI (ctest: python:module): a run from a dict gives the cells
and nodes the CLI's report gives for the same YAML; a bad key raises with the CLI's message; the
mesh written from Python is certified by plaf.check and by the CLI; meshio reads it. Run as
    PYTHONPATH=BUILD/python python3 tests/python/test_module.py PLAF_EXE
"""
import json
import os
import subprocess
import sys
import tempfile

import plaf

PLAF = sys.argv[1]
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def cli(yaml_text, name, tmp, *extra):
    cfg = os.path.join(tmp, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(yaml_text)
    r = subprocess.run([PLAF, "run", cfg, "--out", os.path.join(tmp, "cli"), "--quiet", *extra],
                       capture_output=True, text=True)
    return r, cfg


annulus = {"name": "py_annulus", "order": 3,
           "geometry": {"type": "annulus", "r_inner": 1.0, "r_outer": 2.0, "angle_deg": 360, "cells": "quad"},
           "metric": {"type": "uniform", "h": 0.35},
           "output": {"formats": ["msh", "report"]}}
sphere = {"name": "py_sphere", "order": 2, "geometry": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
          "metric": {"type": "wall_power_law", "h0": 1e-4, "growth": 1.3, "h_max": 10.0, "h_wall_max": 0.4},
          "layers": {"type": "extrude", "max": 6, "f_atten": 0.2},
          "output": {"formats": ["msh", "report"]}}

with tempfile.TemporaryDirectory() as tmp:
    for cfg in (annulus, sphere):
        m = plaf.run(cfg)
        r, path = cli(json.dumps(cfg), cfg["name"], tmp)
        check(r.returncode == 0, f"{cfg['name']}: the CLI runs the same config (exit {r.returncode}: {r.stderr.strip()[:200]})")
        with open(os.path.join(tmp, "cli", cfg["name"] + ".report.json")) as f:
            rep = json.load(f)
        cells = sum(len(c) for c in m.cells.values())
        check(m.ok and m.exit_code == 0, f"{cfg['name']}: ok, exit code 0")
        check(cells == rep["cells"]["total"] == m.report["cells"]["total"],
              f"{cfg['name']}: {cells} cells = the CLI's report {rep['cells']['total']}")
        check(m.report["cells"]["by_type"] == rep["cells"]["by_type"], f"{cfg['name']}: the same cells by type")
        check(m.points.shape[1] == 3 and m.dim == (2 if cfg is annulus else 3), f"{cfg['name']}: points are n x 3, dim {m.dim}")
        # Gmsh's node order: a cell's first node is a vertex; every node number is a node.
        check(all(int(c.max()) < len(m.points) and int(c.min()) >= 0 for c in m.cells.values()),
              f"{cfg['name']}: node numbers within the {len(m.points)} points")
        check(len(m.tags) >= 1 and all(k in ("wall", "farfield", "symmetry", "named") for _, k in m.tags),
              f"{cfg['name']}: tags {m.tags}")
        check(set(m.boundary) == {t for t, _ in m.tags}, f"{cfg['name']}: boundary facets by tag")
        # Written from Python, certified by plaf.check and by the CLI; CGNS too.
        for suffix, kw in ((".msh", {}), (".cgns", {}), ("_22.msh", {"format": "msh22", "binary": True})):
            out = os.path.join(tmp, cfg["name"] + suffix)
            m.write(out, **kw)
            rc = plaf.check(out)
            check(rc["exit_code"] == 0 and rc["cells"]["total"] == cells, f"{cfg['name']}: plaf.check({suffix}) certifies {cells} cells")
            r = subprocess.run([PLAF, "check", out], capture_output=True, text=True)
            check(r.returncode == 0, f"{cfg['name']}: plaf check {suffix} exits 0")
        # A run with an output folder writes the configured files.
        m2 = plaf.run(cfg, out=os.path.join(tmp, "py"))
        check(os.path.exists(os.path.join(tmp, "py", cfg["name"] + ".msh")) and m2.ok, f"{cfg['name']}: out= writes NAME.msh")

    # A bad key: the same one-line message as the CLI (after its "plaf: error: " prefix).
    bad = dict(annulus, metric={"type": "uniform", "h": -1})
    try:
        plaf.run(bad)
        check(False, "a negative h raises")
    except plaf.ConfigError as e:
        r, path = cli(plaf._config_text(bad), "config", tmp)
        cli_line = r.stderr.strip().splitlines()[-1]
        msg = str(e)
        # The CLI names its file; the module's text is named "config": compare from the line number on.
        check(r.returncode == 1 and cli_line.startswith("plaf: error: "), f"the CLI refuses it: {cli_line}")
        check(msg.split(":", 1)[1] == cli_line[len("plaf: error: "):].split(":", 1)[1] and "metric.h" in msg,
              f"the same message: {msg!r}")
    try:
        plaf.run(dict(annulus, no_such_key=1))
        check(False, "an unknown key raises")
    except plaf.Error as e:
        check("no_such_key" in str(e) and isinstance(e, plaf.ConfigError), f"an unknown key: {e}")
    try:
        plaf.run(os.path.join(tmp, "missing.yaml"))
        check(False, "a missing file raises")
    except plaf.InputError as e:
        check("missing.yaml" in str(e), f"a missing file: {e}")
    try:
        plaf.check(os.path.join(tmp, "missing.msh"))
        check(False, "checking a missing mesh raises")
    except plaf.InputError as e:
        check("missing.msh" in str(e), f"a missing mesh: {e}")

    try:
        import meshio  # noqa: F401
        mm = plaf.run(sphere).to_meshio()
        check(sum(len(c.data) for c in mm.cells if c.type == "wedge18") > 0, "to_meshio: meshio reads the prisms")
    except ImportError:
        print("skip to_meshio: no meshio")

print(f"{len(failures)} failures")
sys.exit(1 if failures else 0)
