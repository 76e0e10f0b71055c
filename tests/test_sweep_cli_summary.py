"""``slewbench sweep --dry-run`` lists the cases and writes nothing; the summary of a resumed sweep
counts the cases it ran, not the study's."""
from __future__ import annotations

import copy
import re
import sqlite3

import yaml

from scenarios.cli.commands import main
from scenarios.study.spec import load_study
from tests.test_sweep import BASE


def _study(tmp_path, values=(0.2, 0.3, 0.4)):
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "summary-study", "scenario": copy.deepcopy(BASE),
                                    "grid": {"controller.options.kp": list(values)}}))
    return path


def test_dry_run_lists_every_case_and_writes_nothing(tmp_path, capsys):
    study = _study(tmp_path)
    out = tmp_path / "out"
    assert main(["sweep", str(study), "--out", str(out), "--dry-run"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith("summary-study: 3 cases, checked; nothing run, nothing written; varying "
                                 "controller.options.kp")
    cases = [line for line in printed if line.startswith("  case ")]
    assert [re.search(r"kp=([0-9.]+)", line).group(1) for line in cases] == ["0.2", "0.3", "0.4"]
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["study.yaml"]


def test_a_dry_run_of_a_bad_study_exits_2(tmp_path, capsys):
    study = _study(tmp_path, values=(0.2, "stiff"))
    assert main(["sweep", str(study), "--out", str(tmp_path / "out"), "--dry-run"]) == 2
    assert "controller.options.kp" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_a_resumed_sweep_counts_what_it_ran(tmp_path, capsys):
    out = tmp_path / "out"
    study = _study(tmp_path, values=(0.2, 0.3, 0.4))
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    assert re.search(r"^3 cases run in [0-9.]+ s; ", capsys.readouterr().out, re.M)
    with sqlite3.connect(out / "sweep.sqlite") as db:  # one case missing, as an interrupted sweep leaves it
        db.execute("DELETE FROM cases WHERE key = ?", (load_study(study).cases[2].key,))
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0
    said = capsys.readouterr().out
    assert re.search(r"^1 case run in [0-9.]+ s \(2 already stored, 3 in all\); ", said, re.M), said


def test_a_report_redrawn_without_plots_names_the_pictures_it_removed(tmp_path, capsys):
    """``sweep --report DIR --no-plots`` removes the earlier figures and report.html (they would no
    longer match the tables) and says which, as ``run --no-plots`` does."""
    out = tmp_path / "out"
    study = _study(tmp_path, values=(0.2, 0.3))
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1"]) == 0
    pictures = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.suffix in (".png", ".html"))
    assert pictures and "report.html" in pictures
    capsys.readouterr()
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    said = capsys.readouterr().out.splitlines()
    assert said[-1] == (f"removed {len(pictures)} file(s) of the earlier output in {out}/ that this one did not "
                        "write: " + ", ".join(pictures))
    assert not [p for p in out.rglob("*") if p.suffix in (".png", ".html")]
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0  # nothing more to remove: nothing said
    assert "removed" not in capsys.readouterr().out


def test_report_refuses_the_options_it_would_ignore(tmp_path, capsys):
    """``sweep --report DIR`` redraws DIR in place: beside it, --dry-run ('write nothing'), --out,
    a study file, --resume, --workers or --scheduler asked for what it does not do, and were
    ignored (the --dry-run and --out runs rewrote DIR's files): exit 2, DIR untouched."""
    out = tmp_path / "out"
    study = _study(tmp_path, values=(0.2, 0.3))
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    for extra, named in (([str(study)], "a study file"), (["--dry-run"], "--dry-run"),
                         (["--out", str(tmp_path / "other")], "--out"), (["--resume"], "--resume"),
                         (["--workers", "1"], "--workers"), (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler")):
        capsys.readouterr()
        assert main(["sweep", "--report", str(out), "--no-plots", *extra]) == 2, extra
        error = capsys.readouterr().err
        assert error.startswith("slewbench: error in option: --report: ") and f"does not take {named}" in error, error
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before and not (tmp_path / "other").exists()
