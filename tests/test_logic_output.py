"""Output safety by injected faults (issue 33): a commit interrupted between two files leaves a
manifest that says "incomplete" and no staging folder; a refused commit leaves no staging folder;
and the ``..`` guard alone (a manifest naming only ``../x``) keeps a run from deleting a file
outside its directory."""
import json
import os
import textwrap
from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.output.directory import MARKER, STAGING_PREFIX

TINY = """
name: tiny
spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
maneuver:
  duration: 20.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9659258, 0.2588190, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 0.5}
"""


def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(yaml.safe_load(textwrap.dedent(TINY))))
    return path


def manifest(out: Path) -> dict:
    return json.loads((out / MARKER).read_text())


def staging_folders(out: Path) -> list[Path]:
    return list(out.glob(f"{STAGING_PREFIX}*"))


def test_the_manifest_says_complete_only_after_every_file_is_in_place(tmp_path, monkeypatch):
    """Every file moved into place is observed with the manifest still "incomplete"; a fault on
    the second file stops the commit with the manifest "incomplete" and the staging folder gone."""
    path, out = scenario(tmp_path), tmp_path / "out"
    real_replace = os.replace
    seen = []

    def observing(source, target, *args, **kwargs):
        if Path(target).name != MARKER and (Path(target).parent / MARKER).exists():
            seen.append((Path(target).name, manifest(Path(target).parent)["complete"]))
        return real_replace(source, target, *args, **kwargs)

    monkeypatch.setattr(os, "replace", observing)
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    assert len(seen) >= 3 and not any(complete for _, complete in seen), seen
    assert manifest(out)["complete"] is True and "results.json" in manifest(out)["files"]

    def failing(source, target, *args, **kwargs):
        if Path(target).name != MARKER:
            failing.count += 1
            if failing.count == 2:
                raise OSError(28, "No space left on device (injected)")
        return real_replace(source, target, *args, **kwargs)

    failing.count = 0
    monkeypatch.setattr(os, "replace", failing)
    try:
        code = main(["run", str(path), "--out", str(out), "--no-plots"])
    except OSError:
        code = None
    assert code != 0 and failing.count == 2
    assert manifest(out)["complete"] is False
    assert staging_folders(out) == []


def test_a_refused_commit_leaves_no_staging_folder(tmp_path, capsys):
    path, out = scenario(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    (out / "timeseries" / "smooth.csv").unlink()
    manifest_data = manifest(out)
    manifest_data["files"].remove("timeseries/smooth.csv")
    (out / MARKER).write_text(json.dumps(manifest_data))
    (out / "timeseries" / "smooth.csv").write_text("a user's file")  # now not slewbench's
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    assert "did not write" in capsys.readouterr().err
    assert (out / "timeseries" / "smooth.csv").read_text() == "a user's file"
    assert staging_folders(out) == []


@pytest.mark.parametrize("name", ["../precious.txt", "timeseries/../../precious.txt", "ABSOLUTE"])
def test_a_manifest_naming_one_path_outside_is_not_trusted(name, tmp_path, capsys):
    """One guard at a time: only ``..`` (no absolute path beside it), or only an absolute path;
    without its guard the run would delete the file as a stale result."""
    path, out = scenario(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    precious = tmp_path / "precious.txt"
    name = str(precious) if name == "ABSOLUTE" else name
    precious.write_text("keep")
    data = manifest(out)
    data["files"].append(name)
    (out / MARKER).write_text(json.dumps(data))
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    assert precious.read_text() == "keep"
    assert "did not create" in capsys.readouterr().err
