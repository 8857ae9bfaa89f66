# SPDX-License-Identifier: MIT
"""plaf from Python: curved high-order hybrid meshes (prismatic layers and advancing fronts).

    import plaf
    m = plaf.run({"order": 2, "geometry": {"type": "sphere", "radius": 1}, ...})  # or a YAML path
    m.points            # numpy (nodes x 3)
    m.cells             # {"prism_Q2": cells x 18 node numbers (0-based, Gmsh's node order), ...}
    m.boundary          # {"wall": {"triangle_Q2": ...}, "farfield": {...}}
    m.tags              # [("wall", "wall"), ("farfield", "farfield")]
    m.report            # the run's report (what NAME.report.json holds), a dict
    m.ok                # the report's verdict: exit code 0
    m.write("x.msh")    # .msh (MSH 4.1), .cgns, .vtu; format="msh22" for MSH 2.2; binary=True
    m.to_meshio()       # a meshio.Mesh, when meshio is installed
    plaf.check("x.msh") # certify a mesh file (MSH 4.1/2.2, CGNS) as `plaf check` does: its report

The configuration keys are the YAML files' (docs/config.md, `plaf keys`). Errors are raised as
plaf.Error (InputError, ConfigError, MesherError) with the command line's one-line message.
A run without `out` writes nothing but keeps the mesh in memory; with `out`, it writes the
configured outputs (output.formats) into that folder as `plaf run CONFIG --out DIR` does, except
that a run that fails before it has a mesh raises MesherError without writing NAME.failed/.
libcgns serves one thread at a time: CGNS reads and writes from several threads take turns.
"""
import json
import os
import tempfile

import numpy  # noqa: F401  (before any thread makes an array: pybind11 imports it once, under a lock)

from ._plaf import ConfigError, Error, InputError, Mesh, MesherError, _check, _run_file, _run_yaml

__all__ = ["run", "check", "Mesh", "Error", "InputError", "ConfigError", "MesherError"]


def _config_text(config):
    try:
        import yaml  # block style: messages name lines of this text

        return yaml.safe_dump(config, sort_keys=False)
    except ImportError:
        return json.dumps(config, indent=1)  # JSON is YAML too


def run(config, out=None, quiet=True, keep_invalid=False):
    """Mesh a configuration: a dict of the YAML keys, or the path of a YAML file.

    out: a folder for the configured outputs (None: nothing written). quiet: no progress on
    stderr. keep_invalid: with out, a failed run writes its mesh into out/NAME.failed/ too (the
    CLI's --keep-invalid). Returns a Mesh (also for a run that failed with a mesh: exit_code 2,
    ok False); raises plaf.Error subclasses for bad input and for a run that failed before it
    had a mesh.
    """
    out = None if out is None else os.fspath(out)
    if isinstance(config, dict):
        return _run_yaml(_config_text(config), "config", out, quiet, keep_invalid)
    return _run_file(os.fspath(config), out, quiet, keep_invalid)


def check(path):
    """Certify a mesh file's cells (MSH 4.1 or 2.2, ASCII or binary, or CGNS): its report, a dict
    with 'ok' and 'exit_code'."""
    code, text = _check(os.fspath(path))
    report = json.loads(text)
    report.setdefault("exit_code", code)
    return report


def _report(self):
    return json.loads(self.report_json)


def _to_meshio(self):
    """The mesh as a meshio.Mesh (read back by meshio from an MSH 4.1 file, so that meshio's own
    node-order conventions apply)."""
    import meshio

    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "mesh.msh")
        self.write(path)
        return meshio.read(path)


Mesh.report = property(_report, doc="the run's report (NAME.report.json) as a dict")
Mesh.ok = property(lambda self: self.exit_code == 0, doc="exit code 0: a valid mesh with its layers")
Mesh.to_meshio = _to_meshio
Mesh.__repr__ = lambda self: (f"<plaf.Mesh {self.name!r}: {self.dim}D, {len(self.points)} nodes, "
                              f"{sum(len(c) for c in self.cells.values())} cells, exit code {self.exit_code}>")
