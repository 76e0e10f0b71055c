"""The generated C law: code size and the time of one call, from a C harness (no Python in the
timing). Run: ``python -m pytest tests/benchmarks/test_bench_codegen.py -o addopts="" -s``"""
import json
import re
import subprocess
from pathlib import Path

import numpy as np

from scenarios.cli.commands import main

ROOT = Path(__file__).resolve().parents[2]

HARNESS = r"""
#include <stdio.h>
#include <time.h>
#include "STEM.h"
int main(void) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  slewbench_law_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  const casadi_real *arg[16]; casadi_real *res[16]; casadi_int iw[64]; casadi_real w[4096];
  casadi_real t = 3.0, y[64] = {0.9, 0.1, -0.2, 0.3, 0.01, -0.02, 0.03}, z[64] = {0}, r[26] = {1.0};
  casadi_real u[16], z_next[64], p[] = {PARAMETERS};
  arg[0] = &t; arg[1] = y; arg[2] = z; arg[3] = r; arg[4] = p; res[0] = u; res[1] = z_next;
  const long n = 2000000; struct timespec a, b; double sink = 0;
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < n; ++i) { y[4] = 1e-9 * i; slewbench_law(arg, res, iw, w, 0); sink += u[0]; }
  clock_gettime(CLOCK_MONOTONIC, &b);
  printf("%.2f ns per call (sink %g)\n", ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / n, sink);
  return 0;
}
"""


def test_c_law_call_time_and_code_size(tmp_path):
    out = tmp_path / "c"
    assert main(["codegen", str(ROOT / "scenarios" / "eigenaxis_demo.yaml"), "--out", str(out)]) == 0
    stem = Path(json.loads((out / "interface.json").read_text())["library"]).stem[3:]
    parameters = json.loads((out / "interface.json").read_text())["slewbench_law"]["parameters"]
    vector = np.concatenate([np.asarray(p["default"], dtype=float).ravel(order="F") for p in parameters])
    (tmp_path / "harness.c").write_text(HARNESS.replace("STEM", stem).replace(
        "PARAMETERS", ", ".join(repr(float(v)) for v in vector)))
    subprocess.run(["cc", "-O2", "-I", str(out), str(tmp_path / "harness.c"), str(out / f"{stem}.c"), "-o",
                    str(tmp_path / "harness"), "-lm"], check=True)
    timings = [float(re.match(r"([0-9.]+) ns", subprocess.run([str(tmp_path / "harness")], capture_output=True,
                                                               text=True, check=True).stdout).group(1))
               for _ in range(5)]
    subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)
    sizes = {p.name: p.stat().st_size for p in out.iterdir() if p.suffix in (".c", ".h", ".so")}
    print(f"\nC law call: median {sorted(timings)[2]:.1f} ns over 5 runs of 2e6 calls; files {sizes}")
