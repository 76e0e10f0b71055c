"""Compiled code against invariants (issue 33): the compiled-library cache keys on the generated
source (two functions of one name and different numbers get two libraries, each computing its
own), and ``interface.json`` describes the exported C functions' real inputs and outputs (their
sparsity, read back from the built library) and the control layout worked out by hand."""
import json
import shutil
import subprocess
from pathlib import Path

import casadi as ca
import pytest

from ocp.simulation import compile_function
from scenarios.cli.commands import main

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
needs_cc = pytest.mark.skipif(shutil.which("make") is None or shutil.which("cc") is None,
                              reason="needs make and a C compiler")


@needs_cc
def test_cache_key_changes_with_the_generated_source(tmp_path):
    x = ca.SX.sym("x")
    first = compile_function(ca.Function("law", [x], [2.0 * x]), tmp_path)
    second = compile_function(ca.Function("law", [x], [3.0 * x]), tmp_path)
    assert float(first(1.0)) == 2.0
    assert float(second(1.0)) == 3.0  # not the stale library of the first
    assert len(list(tmp_path.glob("law_*.so"))) == 2
    again = compile_function(ca.Function("law", [x], [2.0 * x]), tmp_path)
    assert float(again(1.0)) == 2.0 and len(list(tmp_path.glob("law_*.so"))) == 2  # the same source: reused


@needs_cc
@pytest.mark.parametrize("name, inputs, u_layout", [
    # nano_detumble: magnetorquers only (u = dipole, 3); y = [q 4, ω 3, h_w 0, b 3]; r = 2 rows of 13
    ("nano_detumble.yaml", {"t": 1, "y": 10, "r": 26}, {"dipole": [0, 3]}),
    # eigenaxis_demo: three reaction wheels (u = wheel torques, 3); y = [q, ω, h_w 3, b]
    ("eigenaxis_demo.yaml", {"t": 1, "y": 13, "r": 26}, {"wheels": [0, 3]}),
])
def test_interface_json_describes_the_real_c_functions(name, inputs, u_layout, tmp_path):
    out = tmp_path / "c"
    assert main(["codegen", str(SCENARIOS / name), "--out", str(out)]) == 0
    subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)
    interface = json.loads((out / "interface.json").read_text())
    library = str(out / interface["library"])
    assert interface["laws"]
    for function_name, description in interface["laws"].items():
        law = ca.external(function_name, library)
        assert [law.name_in(i) for i in range(law.n_in())] == list(description["inputs"])
        assert [law.name_out(i) for i in range(law.n_out())] == list(description["outputs"])
        for i, (key, size) in enumerate(description["inputs"].items()):
            assert law.sparsity_in(i).nnz() == law.sparsity_in(i).numel() == size, key
            if key in inputs:
                assert size == inputs[key], key
        assert description["inputs"]["z"] == len(description["z0"])
        for i, (key, size) in enumerate(description["outputs"].items()):
            assert law.sparsity_out(i).nnz() == law.sparsity_out(i).numel() == size, key
        assert description["outputs"]["z_next"] == description["inputs"]["z"]
        assert description["u_layout"] == u_layout
        assert max(stop for _, stop in description["u_layout"].values()) == description["outputs"]["u"]
    for reference in interface["references"].values():
        evaluate = ca.external(reference["function"], library)
        assert evaluate.n_in() == 1 and evaluate.sparsity_in(0).numel() == 1
        assert evaluate.sparsity_out(0).numel() == 13
