"""The compiler of the native builds (the compiled closed loop, the sparse LDLᵀ): ``$CC`` when it is set and found, before ``cc``."""
import shutil

import pytest

from ocp.native import find_compiler


def test_cc_from_the_environment_comes_first(monkeypatch):
    gcc, cc = shutil.which("gcc"), shutil.which("cc")
    if gcc is None or cc is None or gcc == cc:
        pytest.skip("needs both gcc and cc on PATH, under different names")
    monkeypatch.setenv("CC", "gcc")
    assert find_compiler() == gcc
    monkeypatch.delenv("CC")
    assert find_compiler() == cc
    monkeypatch.setenv("CC", "no-such-compiler-s50")
    assert find_compiler() == cc
