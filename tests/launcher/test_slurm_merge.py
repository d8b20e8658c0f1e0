"""launch/slurm/merge.py, the merge step of a Slurm job array, on hand-made task directories: the
runs in the experiment file's order, the first done result kept (copied byte for byte), a later
round filling what was missing, a failed run (a physics fault) kept failed and not listed for a
rerun, a run never run listed missing once (not again at each merge), quoted fields kept, and the
exit status."""
import csv
import os
import subprocess
import sys

import pytest

MERGE = os.path.join(os.environ.get("CALIPER_SOURCE_DIR", os.path.join(os.path.dirname(__file__),
                                                                       "..", "..")),
                     "launch", "slurm", "merge.py")
HEADER = ["name", "status", "model", "attempts", "duration [s]", "steps", "samples",
          "wall_time [s]", "load_wall_time [s]", "step_wall_time [s]", "retries", "reason"]


def task(out, name, rows):
    """A task's directory as caliper-ctl batch leaves it: summary.csv and runs/NAME.csv."""
    d = os.path.join(out, "tasks", name)
    os.makedirs(os.path.join(d, "runs"))
    with open(os.path.join(d, "summary.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(HEADER)
        for run, status, reason in rows:
            w.writerow([run, status, "model0@hostb", 1, 1, 1000, 51, 0.1, 0.01, 0.08,
                        "model1@hostc: TRANSIENT, then a retry" if run == "b" else "", reason])
            if status == "done":
                with open(os.path.join(d, "runs", run + ".csv"), "w") as r:
                    r.write(f"time [s],x [m]\n0,{name}-{run}\n")


def merge(out):
    p = subprocess.run([sys.executable, MERGE, out], capture_output=True, text=True)
    with open(os.path.join(out, "summary.csv"), newline="") as f:
        rows = list(csv.reader(f))
    with open(os.path.join(out, "array", "missing.txt")) as f:
        missing = f.read().split()
    return p, rows, missing


@pytest.fixture
def out(tmp_path):
    os.makedirs(tmp_path / "array")
    (tmp_path / "array" / "names.txt").write_text("a\nb\nc\nd\ne\n")
    return str(tmp_path)


def test_orders_keeps_failed_and_lists_missing_once(out):
    task(out, "0-1", [("d", "done", ""), ("b", "done", "")])
    task(out, "0-0", [("c", "failed", "NaN in the physics at step 12"), ("a", "done", "")])
    p, rows, missing = merge(out)
    assert p.returncode == 1, p.stdout
    assert rows[0] == HEADER
    assert [r[0] for r in rows[1:]] == ["a", "b", "c", "d", "e"], "the file's order"
    status = {r[0]: r[1] for r in rows[1:]}
    assert status == {"a": "done", "b": "done", "c": "failed", "d": "done", "e": "missing"}
    assert rows[2][10] == "model1@hostc: TRANSIENT, then a retry", "a quoted field kept whole"
    assert rows[3][11] == "NaN in the physics at step 12"
    assert rows[5][11] == "never run"
    assert missing == ["e"], "a failed run is not run again"
    assert "merged 3 of 5" in p.stdout and "failed 1" in p.stdout and "missing 1: e" in p.stdout
    with open(os.path.join(out, "runs", "d.csv")) as f:
        assert f.read() == "time [s],x [m]\n0,0-1-d\n"
    assert sorted(os.listdir(os.path.join(out, "runs"))) == ["a.csv", "b.csv", "d.csv"]

    # merged again with nothing new: the same summary, the reason not said twice
    p2, rows2, _ = merge(out)
    assert rows2 == rows

    # a rerun's round fills the gap; the first result of a run stays the one kept
    task(out, "1-0", [("e", "done", ""), ("a", "done", "")])
    p3, rows3, missing3 = merge(out)
    assert p3.returncode == 1, "c still failed"
    assert {r[0]: r[1] for r in rows3[1:]}["e"] == "done"
    assert missing3 == []
    with open(os.path.join(out, "runs", "a.csv")) as f:
        assert f.read().endswith("0-0-a\n"), "the first result kept, not the later round's"
    with open(os.path.join(out, "runs", "e.csv")) as f:
        assert f.read().endswith("1-0-e\n")


def test_every_run_done_exits_0(out):
    task(out, "0-0", [(n, "done", "") for n in "abcde"])
    p, rows, missing = merge(out)
    assert p.returncode == 0, p.stdout
    assert missing == [] and all(r[1] == "done" for r in rows[1:])
    assert "merged 5 of 5" in p.stdout
