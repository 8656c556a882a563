"""The example notebook runs as a script: its parameters cell (papermill's tag) swapped for a
smaller render, matplotlib without a display."""

import json
import os
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")

EXAMPLES = Path(os.environ.get("ENVGI_SOURCE_DIR", Path(__file__).resolve().parents[2])) / "examples"


def run_notebook(path, parameters):
    cells = json.loads(path.read_text())["cells"]
    code = [c for c in cells if c["cell_type"] == "code"]
    assert "parameters" in code[0]["metadata"].get("tags", []), "the first code cell holds the parameters"
    source = parameters + "\n" + "\n".join("".join(c["source"]) for c in code[1:])
    namespace = {}
    cwd = os.getcwd()
    os.chdir(path.parent)  # the notebook's paths are relative to examples/
    try:
        exec(compile(source, str(path), "exec"), namespace)
    finally:
        os.chdir(cwd)
    return namespace


def test_the_strategies_notebook_reproduces_figure_9s_order():
    ns = run_notebook(EXAMPLES / "strategies.ipynb",
                      'scene_file = "../scenes/buddha.xml"\nres, reference_spp = 32, 256\n'
                      'strategies = ["uniform", "importance"]\nspps = [1, 4, 16]')
    rmse = ns["rmse"]
    assert set(rmse) == {"uniform", "importance"}
    for s, e in rmse.items():
        assert len(e) == 3 and e[0] > e[-1], s  # the error falls with the samples
    assert all(i < u for i, u in zip(rmse["importance"], rmse["uniform"]))
    assert len(ns["fig"].axes) == 3
